"""The shipped debris missions fly as they did, on this machine and on any other.

The reference is recorded data: ``tests/data/behaviour/default-130s/`` holds the
telemetry (gzipped) and events of the first 130 s of ``dcsim run
scenarios/default.yaml`` (a plan, a path, a grab, the controller's reset for the new
mass), ``crowded_field-120s/`` those of the first 120 s of
``scenarios/crowded_field.yaml`` (the elastic controller dodges and brakes to within
1.3 m of an obstacle). Their bytes are pinned by SHA-256 (below), as recorded when the
debris mission began to hold the collector's attitude (``mission.attitude: hold``) and
every run to record ``attitude_error``; the events are those recorded before (the
default's since its targets and obstacles took ``bounded: true`` starts, the crowded
field's since 8f80d82).

Bytes are a property of one machine and library build, not of the code: numpy's
OpenBLAS picks its kernels by CPU, and each kernel family rounds its sums in its own
order. So the suite checks

- determinism: a scenario flown twice here gives identical bytes;
- behaviour kept: today's records against the reference, discrete columns (``mode``,
  ``converged``, ``carried``, ``delivered``) and every event's name, ids, modes and
  other non-float fields exact, float values within ``|a - b| <= ATOL + RTOL * |b|``;
- across kernels: one short flight under two ``OPENBLAS_CORETYPE`` values agrees
  within that tolerance, and a real change does not.

The tolerance, from measured differences. Flown with ``OPENBLAS_CORETYPE=Prescott``,
``Sandybridge`` and ``SkylakeX`` against ``Haswell`` (the reference's kernels), the
reference windows differ by at most 2.2e-13 in any value (the force columns; positions
8e-14, event fields 6e-14), with the same events; the whole default mission (724.2 s)
by at most 3.8e-12 (Prescott), 3.2e-11 (Sandybridge) and 1.1e-10 (SkylakeX), in
``nearest_obstacle_m`` (attitude 7e-11), with the same 29 events (the commands are in
docs/architecture.md, "What is reproducible"). ``RTOL = ATOL = 1e-9`` is nine times the
largest over the whole mission and four thousand times the largest within the
reference windows. A change of the pd controller's damping ratio by 1e-7 moves the
forces by 2.4e-7 N within 20 s, far outside it
(``test_the_tolerance_catches_a_changed_controller_gain``). To see where this
machine stands, run this file with another kernel:
``OPENBLAS_CORETYPE=Prescott .venv/bin/pytest tests/test_behaviour_kept.py``. Bit for bit
against the reference, on the machine that recorded it (Haswell kernels)::

    .venv/bin/dcsim run scenarios/default.yaml --set world.duration=130 --out /tmp/d
    zcat tests/data/behaviour/default-130s/telemetry.csv.gz | cmp - /tmp/d/telemetry.csv

A change that moves the missions' records beyond the tolerance fails here; if such a
change is meant, its commit says why and records the reference again (the run
directory's ``events.jsonl`` as it is, its ``telemetry.csv`` through ``gzip -9 -n``).
"""

from __future__ import annotations

import gzip
import hashlib
import json
import math
import os
import platform
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from dcsim.registry.discovery import PluginRegistry
from dcsim.run.loop import Runner
from dcsim.run.setup import setup_run
from tests.conftest import REPO

pytestmark = pytest.mark.xdist_group("behaviour-kept")  # one worker flies the flights once

REFERENCE = REPO / "tests" / "data" / "behaviour"
FLIGHTS = {"default": 130, "crowded_field": 120}
"""Each reference flight: scenario name → seconds flown."""

RTOL = 1e-9
ATOL = 1e-9
"""Relative and absolute tolerance of every float value (in its column's unit)."""

CORETYPES = ("Prescott", "Nehalem")
"""Two of OpenBLAS's SSE kernel families, which every x86-64 CPU runs; they give the
default scenario different bytes from its first telemetry row on."""

SHORT = 20
"""Seconds of the short flights that compare kernels and a changed gain."""


def sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def reference(scenario: str) -> Path:
    """The directory of a scenario's reference records."""
    return REFERENCE / f"{scenario}-{FLIGHTS[scenario]}s"


def read_bytes(directory: Path, name: str) -> bytes:
    """A record file's bytes, from ``name`` or its gzipped ``name.gz``."""
    packed = directory / f"{name}.gz"
    if packed.exists():
        return gzip.decompress(packed.read_bytes())
    return (directory / name).read_bytes()


def read_events(directory: Path) -> list[dict[str, Any]]:
    """A run directory's events, one dict each."""
    return [json.loads(line) for line in read_bytes(directory, "events.jsonl").splitlines()]


def fly(out: Path, scenario: str, seconds: float, overrides: tuple[str, ...] = ()) -> Path:
    """Fly the first ``seconds`` of a shipped scenario into the run directory ``out``."""
    setup = setup_run(
        REPO / "scenarios" / f"{scenario}.yaml",
        [f"world.duration={seconds}", *overrides],
        registry=PluginRegistry.discover(),
    )
    Runner(setup, out).run()
    return out


def fly_with_blas_kernel(out: Path, coretype: str) -> Path:
    """Fly the default scenario's first :data:`SHORT` seconds in a new process whose
    OpenBLAS uses the kernels of ``coretype``."""
    code = (
        "import sys; from dcsim.api import run; "
        f"run('scenarios/default.yaml', ['world.duration={SHORT}'], out=sys.argv[1], plots=False)"
    )
    env = {**os.environ, "OPENBLAS_CORETYPE": coretype}
    subprocess.run([sys.executable, "-c", code, str(out)], cwd=REPO, env=env, check=True)
    return out


def close(value: Any, expected: Any) -> bool:
    """Whether a recorded value matches the reference's: floats within the tolerance,
    lists and mappings item by item, anything else exactly."""
    if isinstance(expected, float) and isinstance(value, float):
        both_nan = math.isnan(value) and math.isnan(expected)
        return both_nan or abs(value - expected) <= ATOL + RTOL * abs(expected)
    if isinstance(expected, list) and isinstance(value, list):
        return len(value) == len(expected) and all(map(close, value, expected))
    if isinstance(expected, dict) and isinstance(value, dict):
        same_keys = list(value) == list(expected)
        return same_keys and all(close(value[key], expected[key]) for key in expected)
    return type(value) is type(expected) and value == expected


def cell(text: str) -> Any:
    """A telemetry cell as a value: a float when written as one (``repr`` of a float
    has a point, an exponent, ``inf`` or ``nan``), else its text (modes, integers)."""
    try:
        int(text)
    except ValueError:
        try:
            return float(text)
        except ValueError:
            return text
    return text


def differences(recorded: Path, expected: Path, limit: int = 5) -> list[str]:
    """How the records in ``recorded`` differ from those in ``expected``.

    Parameters
    ----------
    recorded, expected : Path
        Run directories (``expected``'s telemetry may be gzipped).
    limit : int
        Telemetry values described at most.

    Returns
    -------
    list of str
        One line per difference (empty when the records match within the tolerance).
    """
    found = []
    mine = read_bytes(recorded, "telemetry.csv").decode().splitlines()
    theirs = read_bytes(expected, "telemetry.csv").decode().splitlines()
    if mine[0] != theirs[0] or len(mine) != len(theirs):
        found.append(f"telemetry: header or row count differs ({len(mine)} against {len(theirs)})")
    header = theirs[0].split(",")
    for row, (line, line_expected) in enumerate(zip(mine[1:], theirs[1:], strict=False), 1):
        pairs = zip(header, line.split(","), line_expected.split(","), strict=False)
        for name, text, text_expected in pairs:
            if len(found) < limit and not close(cell(text), cell(text_expected)):
                found.append(f"telemetry row {row}, {name}: {text} against {text_expected}")
    events, events_expected = read_events(recorded), read_events(expected)
    if not close(events, events_expected):
        found.append(f"events differ: {events} against {events_expected}")
    return found


@pytest.fixture(scope="module")
def flown(tmp_path_factory) -> dict[str, Path]:
    """Each reference flight flown today, scenario name → run directory."""
    return {
        scenario: fly(tmp_path_factory.mktemp(scenario), scenario, seconds)
        for scenario, seconds in FLIGHTS.items()
    }


def test_the_reference_is_the_recording_the_suite_hashed_before():
    default, crowded = reference("default"), reference("crowded_field")
    header, _, rows = read_bytes(default, "telemetry.csv").partition(b"\n")
    assert header.startswith(b"time_s,x_m,y_m,z_m,vx_mps,") and header.endswith(
        b",est_sigma_z_m,attitude_error_rad"
    )
    assert sha256(rows) == "df27e1c373c0bdef73e95815c3f05f30a40f2635e5fc15206bc02ba606e2e356"
    assert sha256(read_bytes(default, "events.jsonl")) == (
        "79f290a2089ad32be7398df1b655411fde04b5e77933a10a3db4492312342909"
    )
    assert sha256(read_bytes(crowded, "telemetry.csv")) == (
        "ad3c5419b55400af870fd6ede76a4b779e1c009b6764210ef8e4d3de3fbebc27"
    )
    assert sha256(read_bytes(crowded, "events.jsonl")) == (
        "126e2500f5196cdf74aaa83d2f856020a9fc9847e58d516b807454a361087721"
    )


@pytest.mark.parametrize("scenario", FLIGHTS)
def test_the_records_match_the_reference_within_the_tolerance(flown, scenario):
    assert differences(flown[scenario], reference(scenario)) == []


@pytest.mark.parametrize("scenario", FLIGHTS)
def test_a_scenario_flown_twice_gives_identical_bytes(flown, scenario, tmp_path):
    again = fly(tmp_path, scenario, FLIGHTS[scenario])
    for name in ("telemetry.csv", "events.jsonl"):
        assert (again / name).read_bytes() == (flown[scenario] / name).read_bytes(), name


@pytest.mark.skipif(
    platform.machine().lower() not in {"x86_64", "amd64"},
    reason="OPENBLAS_CORETYPE names x86-64 kernels",
)
def test_a_flight_under_two_blas_kernels_agrees_within_the_tolerance(tmp_path):
    first, second = (fly_with_blas_kernel(tmp_path / name, name) for name in CORETYPES)
    assert differences(first, second) == []


def test_the_tolerance_catches_a_changed_controller_gain(tmp_path):
    base = fly(tmp_path / "base", "default", SHORT)
    changed = fly(tmp_path / "changed", "default", SHORT, ("controller.params.damping=0.9000001",))
    found = differences(changed, base)
    assert found and found[0].startswith("telemetry row ")
