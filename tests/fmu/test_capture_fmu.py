"""The capture scenario (scenarios/debris_capture.yaml) as a closed-loop FMU in fmpy: valid,
and flown by ``simulate_fmu`` as ``dcsim run`` flies it, at every control period."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.validation import validate_fmu

from dcsim.api import close_run, open_run
from dcsim.fmu.export import export_fmu
from dcsim.fmu.instance import FmuInstance
from dcsim.fmu.variables import JOINT_ANGLE, JOINT_RATE, closed_loop_variables
from dcsim.missions.capture import CaptureMission
from dcsim.run.loop import Runner
from dcsim.scenario import read_scenario
from tests.conftest import CAPTURE, short_capture

PERIOD = 0.01  # s, the capture scenario's control period
JOINTS = 6
TYPES = {float: "Real", int: "Integer", bool: "Boolean"}


ACQUIRED = "mission.acquisition_time=1.0"
"""The FMU's and the native run's watch of the target before the approach: 1 s, so that
a short flight sees the tracker's acquisition end and the approach begin."""


@pytest.fixture(scope="module")
def capture_fmu(tmp_path_factory) -> Path:
    """The shipped capture scenario as a closed-loop FMU, its target tracked for 1 s
    before the approach (:data:`ACQUIRED`)."""
    out = tmp_path_factory.mktemp("capture") / "capture.fmu"
    return export_fmu(CAPTURE, out, overrides=[ACQUIRED])


def simulate(fmu: Path, stop_time: float) -> np.ndarray:
    """fmpy's run of ``fmu`` to ``stop_time`` (s), stepped and recorded every period."""
    return simulate_fmu(str(fmu), stop_time=stop_time, step_size=PERIOD, output_interval=PERIOD)


def world_outputs(runner: Runner) -> dict[str, float]:
    """The closed-loop FMU's outputs from an open run's world and mission now."""
    world = runner.world
    assert world is not None
    state, out = world.robot_state(), runner.outputs
    values = {
        f"{name}.{axis}": float(vector[k])
        for name, vector in (
            ("position", state.position),
            ("velocity", state.velocity),
            ("angular_velocity", state.angular_velocity),
            ("end_effector", world.end_effector()),
        )
        for k, axis in enumerate("xyz")
    }
    values.update({f"attitude.{a}": float(state.attitude[k]) for k, a in enumerate("xyzw")})
    for i in range(JOINTS):
        values[JOINT_ANGLE.format(i + 1)] = float(state.joint_positions[i])
        values[JOINT_RATE.format(i + 1)] = float(state.joint_velocities[i])
    values.update(
        fuel_used=float(out["fuel_used"]),
        delta_v=float(out["delta_v"]),
        collisions=int(out["collisions"]),
        mode=CaptureMission.modes.index(runner.mode),
    )
    return values


def native(overrides: list[str] | dict[str, object]) -> list[dict[str, float]]:
    """The outputs of ``dcsim run`` of the capture scenario at every period boundary."""
    runner = open_run(CAPTURE, overrides)
    rows = [world_outputs(runner)]
    while not runner.ended:
        runner.advance()
        rows.append(world_outputs(runner))
    close_run(runner)
    return rows


def assert_flown_alike(result: np.ndarray, rows: list[dict[str, float]]) -> None:
    """Every output equal to the bit at every period boundary both runs reached."""
    for tick, row in enumerate(rows):
        assert result["time"][tick] == pytest.approx(tick * PERIOD, abs=1e-9)
        for name, value in row.items():
            assert result[name][tick] == value, f"{name} at t = {tick * PERIOD:.2f} s"


def test_the_capture_fmu_is_valid_and_declares_the_arm_and_the_capture_modes(capture_fmu):
    assert validate_fmu(str(capture_fmu)) == []
    table = closed_loop_variables(read_scenario(CAPTURE))
    with FmuInstance(capture_fmu) as fmu:
        described = {n: (v.causality, v.type) for n, v in fmu.description.variables.items()}
        mode = fmu.description.variables["mode"].description
    assert described == {v.name: (v.causality, TYPES[v.type]) for v in table}
    assert described[JOINT_ANGLE.format(JOINTS)] == ("output", "Real")
    assert "captured" not in described  # the arm carries no targets
    assert "capture: 0 ACQUIRE, 1 APPROACH, 2 OBSERVE, 3 INTERCEPT, 4 GRASP, 5 DETUMBLE" in mode


def test_simulate_fmu_flies_the_capture_as_dcsim_run_does(capture_fmu):
    stop = 3.0  # s: 1 s of acquisition, then the approach
    result = simulate(capture_fmu, stop)
    rows = native([f"world.duration={stop}", ACQUIRED])
    assert len(rows) == len(result) == 301
    assert_flown_alike(result, rows)
    assert result["velocity.x"][-1] > 0.0  # the base is on its way to the standoff


@pytest.mark.slow
def test_the_fmu_grasps_latches_and_detumbles_as_dcsim_run_does(tmp_path):
    overrides = short_capture(observation=0.5, duration=26.0)
    texts = [f"{key}={json.dumps(value)}" for key, value in overrides.items()]
    fmu = export_fmu(CAPTURE, tmp_path / "short.fmu", overrides=texts)
    result = simulate(fmu, 24.0)
    rows = native(overrides)
    assert_flown_alike(result, rows)
    captured = CaptureMission.modes.index("CAPTURED")
    assert rows[-1]["mode"] == captured and result["mode"][-1] == captured
    assert result["run_status"][len(rows) - 1] == 1  # completed: captured and detumbled


def test_the_shipped_capture_exports_as_it_is(tmp_path):
    """The scenario exactly as shipped (no overrides) exports to a valid FMU."""
    fmu = export_fmu(CAPTURE, tmp_path / "shipped.fmu")
    assert validate_fmu(str(fmu)) == []
