"""The shipped debris mission flies exactly as it did: byte-identical records.

The hashes are those of the first 130 s (a plan, a path, a grab, the controller's
reset for the new mass) of ``dcsim run scenarios/default.yaml``. The events and the
telemetry's rows are as recorded at commit c063456, before the robot and mission
contracts were generalised; the telemetry's header line is checked on its own, since
it gained its units (``x_m``, ``vx_mps``...) at a commit that moved no row: the hash of
the rows below the header was taken on the commit before (c4bccb2). A change that moves
any number of the debris mission's telemetry or events fails here; if such a change is
meant, its commit says why and replaces the hashes.
"""

from __future__ import annotations

import hashlib

from dcsim.registry import PluginRegistry
from dcsim.runner import Runner
from dcsim.runsetup import prepare_run
from tests.conftest import REPO

TELEMETRY_HEADER = (
    "time_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps,est_x_m,est_y_m,est_z_m,est_vx_mps,est_vy_mps,"
    "est_vz_mps,qx,qy,qz,qw,mode,converged,carried,delivered,fuel_used_kg,delta_v_mps,"
    "nearest_obstacle_m,fx_N,fy_N,fz_N"
)
TELEMETRY_ROWS_SHA256 = "97007c0936e73859b2cb32156f644d9aa9113313e732dad127ce4e3a2687beaf"
EVENTS_SHA256 = "002f4b6204e2c8c146bb05876a76b6856c584fdd38ef97a3c532f38b35ab8e14"


def sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def test_default_scenario_records_are_byte_identical_to_the_reference(tmp_path):
    setup = prepare_run(
        REPO / "scenarios" / "default.yaml",
        ["world.duration=130"],
        registry=PluginRegistry.discover(),
    )
    Runner(setup, tmp_path).run()
    assert sha256((tmp_path / "events.jsonl").read_bytes()) == EVENTS_SHA256
    header, newline, rows = (tmp_path / "telemetry.csv").read_bytes().partition(b"\n")
    assert header.decode() == TELEMETRY_HEADER and newline
    assert sha256(rows) == TELEMETRY_ROWS_SHA256
