"""The shipped debris mission flies exactly as it did: byte-identical records.

The hashes are those of the first 130 s (a plan, a path, a grab, the controller's
reset for the new mass) of ``dcsim run scenarios/default.yaml``. The events are as
recorded at commit c063456, before the robot and mission contracts were generalised.
The telemetry's header line is checked on its own (it gained its units, ``x_m``,
``vx_mps``..., at a commit that moved no row); its rows are those of c063456 with the
columns ``wx wy wz est_sigma_x est_sigma_y est_sigma_z`` appended, every earlier
column unchanged. A change that moves any number of the debris mission's telemetry or
events fails here; if such a change is meant, its commit says why and replaces the
hashes.
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
    "nearest_obstacle_m,fx_N,fy_N,fz_N,wx_radps,wy_radps,wz_radps,est_sigma_x_m,est_sigma_y_m,"
    "est_sigma_z_m"
)
TELEMETRY_ROWS_SHA256 = "255db4a44caa31be595e91b9cdadf9d404a39cc1503ec0e94281116e181241d2"
ORIGINAL_COLUMNS = 27  # the columns recorded at c063456, before wx ... est_sigma_z
ORIGINAL_ROWS_SHA256 = "97007c0936e73859b2cb32156f644d9aa9113313e732dad127ce4e3a2687beaf"
EVENTS_SHA256 = "002f4b6204e2c8c146bb05876a76b6856c584fdd38ef97a3c532f38b35ab8e14"


def sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def fly(out, scenario: str, seconds: float) -> None:
    """Fly the first ``seconds`` of a shipped scenario into the run directory ``out``."""
    setup = prepare_run(
        REPO / "scenarios" / f"{scenario}.yaml",
        [f"world.duration={seconds}"],
        registry=PluginRegistry.discover(),
    )
    Runner(setup, out).run()


def test_default_scenario_records_are_byte_identical_to_the_reference(tmp_path):
    fly(tmp_path, "default", 130)
    assert sha256((tmp_path / "events.jsonl").read_bytes()) == EVENTS_SHA256
    header, newline, rows = (tmp_path / "telemetry.csv").read_bytes().partition(b"\n")
    assert header.decode() == TELEMETRY_HEADER and newline
    assert sha256(rows) == TELEMETRY_ROWS_SHA256
    original = b"\n".join(
        b",".join(line.split(b",")[:ORIGINAL_COLUMNS]) for line in rows.split(b"\n")
    )
    assert sha256(original) == ORIGINAL_ROWS_SHA256


CROWDED_TELEMETRY_SHA256 = "93d069eb68b590ef7d4238134ecd4606909b4a704d1fcd577a8cad63daf2e959"
CROWDED_EVENTS_SHA256 = "126e2500f5196cdf74aaa83d2f856020a9fc9847e58d516b807454a361087721"


def test_crowded_field_records_are_byte_identical_to_the_reference(tmp_path):
    """The elastic controller's numbers: the first 120 s of ``dcsim run
    scenarios/crowded_field.yaml`` (the collector dodges and brakes to within 1.3 m of
    an obstacle), as recorded at commit 8f80d82, before its norms and cross products
    were computed without numpy's per-call overhead."""
    fly(tmp_path, "crowded_field", 120)
    assert sha256((tmp_path / "telemetry.csv").read_bytes()) == CROWDED_TELEMETRY_SHA256
    assert sha256((tmp_path / "events.jsonl").read_bytes()) == CROWDED_EVENTS_SHA256
