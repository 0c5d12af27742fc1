"""The hold mission: a position and an attitude kept for the whole run."""

from __future__ import annotations

import textwrap

import numpy as np
import pytest

from dcsim.api import ScenarioError
from dcsim.geometry import (
    attitude_error,
    quaternion_conjugate,
    quaternion_from_rotation_vector,
    quaternion_multiply,
    rotation_vector,
)
from dcsim.missions.hold import HoldMission
from dcsim.registry.discovery import PluginRegistry
from dcsim.run.loop import Runner
from dcsim.run.setup import setup_run

GOAL = [0.0, 0.0, 0.38268343236508984, 0.9238795325112867]  # 45° about +z

SLEW = """\
    name: slew
    world: {{frame: geocentric, duration: {duration}}}
    robot:
      max_torque: 50
      initial:
        position: [1, 2, 3]
        velocity: [0.05, -0.03, 0.02]
        attitude: [0.5, 0.5, 0.5, 0.5]
        angular_velocity: [0.02, -0.01, 0.03]
    mission: {{type: hold, attitude: {goal}, hold_position: {hold}}}
"""


@pytest.fixture(scope="module")
def registry():
    return PluginRegistry.discover()


def fly(tmp_path, registry, hold: bool, duration: float = 40.0, extra: str = ""):
    path = tmp_path / "slew.yaml"
    text = SLEW.format(duration=duration, goal=GOAL, hold=str(hold).lower())
    path.write_text(textwrap.dedent(text) + extra)
    runner = Runner(setup_run(path, registry=registry))
    return runner, runner.run()


def test_the_attitude_and_the_start_position_are_held(tmp_path, registry):
    runner, summary = fly(tmp_path, registry, hold=True)
    assert summary["status"] == "completed" and summary["reason"] == "duration reached"
    assert set(runner.plugins) == {"controller"}
    assert summary["localiser"] == "none: the mission was fed the true state"
    assert set(HoldMission.summary_names) <= set(summary)
    rows = runner.recorder.rows
    assert np.degrees(rows[0]["attitude_error"]) == pytest.approx(98.42, abs=0.01)  # a real slew
    assert summary["final_attitude_error_deg"] < 1e-3
    # the start drift (0.06 m/s) is taken out and the collector comes back to the start
    assert 0.05 < summary["max_position_error_m"] < 0.5
    assert summary["final_position_error_m"] < 1e-3
    assert summary["fuel_used_kg"] > 0
    assert {row["mode"] for row in rows} == {"HOLD"}


def test_translation_free_asks_for_no_force_and_drifts(tmp_path, registry):
    runner, summary = fly(tmp_path, registry, hold=False, duration=20.0)
    rows = runner.recorder.rows
    assert all(row[k] == 0.0 for row in rows for k in ("fx", "fy", "fz"))
    assert summary["fuel_used_kg"] == 0.0
    drift = np.linalg.norm([0.05, -0.03, 0.02]) * 20.0
    assert summary["final_position_error_m"] == pytest.approx(drift, rel=1e-6)
    assert summary["final_attitude_error_deg"] < 0.1
    torques = np.array([[row[k] for k in ("tx", "ty", "tz")] for row in rows])
    assert np.linalg.norm(torques[0]) > 1.0  # the slew is flown by torque alone


def test_a_given_position_is_held_and_the_initial_attitude_by_default(tmp_path, registry):
    path = tmp_path / "hold.yaml"
    path.write_text(
        "world: {frame: geocentric, duration: 60}\n"
        "robot: {initial: {position: [0, 0, 0], attitude: [0, 0, 1, 0]}}\n"
        "mission: {type: hold, position: [2, 0, 0]}\n"
    )
    runner = Runner(setup_run(path, registry=registry))
    summary = runner.run()
    assert runner.recorder.rows[0]["position_error"] == pytest.approx(2.0)
    assert summary["final_position_error_m"] < 0.05
    assert summary["final_attitude_error_deg"] < 1e-9
    assert all(row["attitude_error"] < 1e-9 for row in runner.recorder.rows)


def test_a_zero_attitude_is_refused_with_its_key(tmp_path, registry):
    path = tmp_path / "hold.yaml"
    path.write_text("mission: {type: hold, attitude: [0, 0, 0, 0], speed: 1}\n")
    with pytest.raises(ScenarioError) as error:
        setup_run(path, registry=registry)
    text = str(error.value)
    assert "mission.attitude" in text and "the quaternion must not be zero" in text
    assert "mission.speed: unknown key" in text


def test_attitude_error_is_the_rotation_angle_for_either_sign():
    rng = np.random.default_rng(3)
    for _ in range(50):
        a, b = (q / np.linalg.norm(q) for q in rng.normal(size=(2, 4)))
        expected = np.linalg.norm(rotation_vector(quaternion_multiply(b, quaternion_conjugate(a))))
        assert attitude_error(a, b) == pytest.approx(expected, abs=1e-12)
        assert attitude_error(-a, b) == pytest.approx(expected, abs=1e-12)
    tiny = quaternion_from_rotation_vector([1e-10, 0.0, 0.0])
    assert attitude_error(tiny, [0.0, 0.0, 0.0, 1.0]) == pytest.approx(1e-10, rel=1e-6)


def test_a_hold_run_draws_its_timeline_the_pictures_every_run_has_and_no_debris_ones(
    tmp_path, registry
):
    path = tmp_path / "slew.yaml"
    path.write_text(textwrap.dedent(SLEW.format(duration=2.0, goal=GOAL, hold="true")))
    out = tmp_path / "run"
    Runner(setup_run(path, registry=registry), out).run()
    names = sorted(p.name for p in (out / "plots").iterdir())
    assert names == ["estimation.png", "motion.png", "timeline.png"]
