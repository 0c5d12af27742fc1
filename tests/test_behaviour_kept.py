"""The shipped debris mission flies exactly as it did: byte-identical records.

The hashes are those of the first 130 s (a plan, a path, a grab, the controller's
reset for the new mass) of ``dcsim run scenarios/default.yaml``. The events are as
recorded at commit c063456, before the robot and mission contracts were generalised;
the telemetry is that record with the columns ``wx wy wz est_sigma_x est_sigma_y
est_sigma_z`` appended (every earlier column unchanged). A change that moves any number
of the debris mission's telemetry or events fails here; if such a change is meant, its
commit says why and replaces the hashes.
"""

from __future__ import annotations

import hashlib

from dcsim.registry import PluginRegistry
from dcsim.runner import Runner
from dcsim.runsetup import prepare_run
from tests.conftest import REPO

TELEMETRY_SHA256 = "2b41842e42e7e638664a9d5a556b23bf183f6117466818e0f0ccbdaa5d6ba814"
EVENTS_SHA256 = "002f4b6204e2c8c146bb05876a76b6856c584fdd38ef97a3c532f38b35ab8e14"


def sha256(path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_default_scenario_records_are_byte_identical_to_the_reference(tmp_path):
    setup = prepare_run(
        REPO / "scenarios" / "default.yaml",
        ["world.duration=130"],
        registry=PluginRegistry.discover(),
    )
    Runner(setup, tmp_path).run()
    assert sha256(tmp_path / "events.jsonl") == EVENTS_SHA256
    assert sha256(tmp_path / "telemetry.csv") == TELEMETRY_SHA256
