"""The reach mission on the thesis's manipulator: both controllers to the thesis's figures,
the joint references, and the ways a reach is refused."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from dcsim_plugins.path_planners.end_effector_line import EndEffectorLinePlanner

from dcsim.api import Trajectory, manipulator_model, thesis_manipulator
from dcsim.robots.joint_path import JointPath, SingularPath
from dcsim.run.loop import Runner
from dcsim.run.recording import read_telemetry
from dcsim.run.setup import setup_run
from dcsim.testing.problems import reach_problem

SCENARIO = Path(__file__).parents[2] / "scenarios" / "space_manipulator_reach.yaml"
START = np.array([1.4, 0.9, -0.8])
TARGET = np.array([1.5, 0.7, -1.0])


def read_run(out: Path) -> tuple[dict, dict[str, np.ndarray]]:
    """A run directory's summary and telemetry columns (by their row names)."""
    summary = json.loads((out / "summary.json").read_text())
    return summary, read_telemetry(out / "telemetry.csv")


def fly(out: Path, *overrides: str) -> tuple[dict, dict[str, np.ndarray]]:
    """Run the shipped reach scenario; return its summary and telemetry columns."""
    Runner(setup_run(SCENARIO, list(overrides)), out).run()
    return read_run(out)


@pytest.fixture(scope="module")
def full_control_run(tmp_path_factory) -> Path:
    """The run directory of the shipped scenario (full control)."""
    out = tmp_path_factory.mktemp("computed-torque") / "run"
    fly(out)
    return out


@pytest.fixture(scope="module")
def full_control(full_control_run):
    return read_run(full_control_run)


@pytest.fixture(scope="module")
def partial_control(tmp_path_factory):
    return fly(tmp_path_factory.mktemp("underactuated"), "controller.plugin=underactuated")


def test_full_control_tracks_the_end_effector_path_within_the_thesis_figure(full_control):
    summary, telemetry = full_control
    assert summary["status"] == "completed" and summary["reason"] == "target reached"
    assert summary["max_ee_tracking_error_m"] <= 1e-4  # thesis §7.5.1: order 1e-4 m
    assert summary["final_target_distance_m"] <= 1e-3
    assert np.allclose(telemetry["ee_x"][0], START[0], atol=1e-9)
    assert np.allclose(
        [telemetry["ee_x"][-1], telemetry["ee_y"][-1], telemetry["ee_z"][-1]], TARGET, atol=1e-3
    )
    assert summary["max_base_displacement_m"] < 1e-5  # the base is held by its thrusters
    assert telemetry["mode"][-1] == "ARRIVED"


def test_partial_control_tracks_the_joints_without_thrust(partial_control):
    summary, telemetry = partial_control
    assert summary["max_joint_tracking_error_deg"] <= 1e-3  # thesis §7.5.2: order 1e-3 deg
    thrust = np.abs(np.column_stack([telemetry[k] for k in ("fx", "fy", "fz")]))
    assert thrust.max() == 0.0 and summary["fuel_used_kg"] == 0.0
    # no external force: the base drifts as the arm moves, the total momentum stays put
    assert summary["max_base_displacement_m"] > 0.01
    momentum = np.column_stack([telemetry[k] for k in ("px", "py", "pz")])
    assert np.abs(momentum).max() < 1e-3
    # so the end effector misses the target by about the base's drift (thesis Fig. 7.17)
    assert not summary["reached"]
    assert summary["final_target_distance_m"] == pytest.approx(
        summary["max_base_displacement_m"], rel=0.2
    )


def test_q_learning_and_full_control_reach_the_target_within_every_constraint(tmp_path):
    summary, telemetry = fly(
        tmp_path / "run",
        "path_planner.plugin=q-learning",
        "world.duration=15",
        "world.physics_step=0.001",
    )
    assert summary["reached"] and summary["final_target_distance_m"] <= 1e-3
    joints = np.column_stack([telemetry[f"joint_{i}"] for i in range(1, 7)])
    assert np.degrees(np.abs(joints)).max() < 90.0  # the thesis's joint limits
    assert telemetry["det_jjt"].min() > 1e-3  # no singularity
    assert np.degrees(telemetry["target_angle"]).max() < 60.0  # the target in sight
    moved = telemetry["ee_displacement"] > 0.0
    ratio = telemetry["base_displacement"][moved] / telemetry["ee_displacement"][moved]
    assert ratio.max() <= 0.5  # the base moves less than half the end effector


def test_reach_writes_one_column_per_joint_and_its_plots(full_control, tmp_path):
    _, telemetry = full_control
    for i in range(1, 7):
        for prefix in ("joint_", "ref_joint_", "joint_torque_"):
            assert f"{prefix}{i}" in telemetry
    assert "joint_7" not in telemetry
    assert telemetry["det_jjt"].min() > 1.0
    assert np.degrees(telemetry["target_angle"]).max() < 60.0


def test_reach_run_directory_has_the_plots(full_control_run):
    out = full_control_run
    assert {p.name for p in (out / "plots").iterdir()} == {"path.png", "timeline.png", "joints.png"}
    events = [json.loads(line) for line in (out / "events.jsonl").read_text().splitlines()]
    assert events[0]["event"] == "path" and events[0]["length"] == pytest.approx(0.3)


def test_an_unreachable_target_stops_the_run_with_the_planner_reason(tmp_path):
    summary, telemetry = fly(tmp_path / "run", "mission.target=[6, 0, 0]", "world.duration=0.2")
    assert summary["status"] == "stopped"
    assert "beyond the arm's reach" in summary["reason"]
    assert set(telemetry["mode"]) == {"HOLD"}


def test_a_free_flyer_controller_is_refused_for_the_manipulator(dcsim_cli):
    result = dcsim_cli("run", str(SCENARIO), "--set", "controller.plugin=pd")
    assert result.returncode == 2
    assert "pd" in result.stderr and "manipulator" in result.stderr
    assert "Traceback" not in result.stderr


# ----------------------------------------------------------------- joint references


@pytest.fixture(scope="module")
def joint_path():
    problem = reach_problem()
    trajectory = EndEffectorLinePlanner(None, np.random.default_rng(0)).plan(problem)
    start = problem.start.configuration
    return problem.model, start, trajectory, JointPath(problem.model, start, trajectory)


def test_joint_references_follow_the_end_effector_path(joint_path):
    model, start, trajectory, path = joint_path
    for t in np.linspace(0.0, trajectory.duration, 13):
        sample = path.at(t)
        q = np.concatenate([start[:7], sample.angles])
        assert np.linalg.norm(model.forward_kinematics(q).end_effector - sample.end_effector) < 1e-8
        # the joint rates give the path's velocity through the arm's Jacobian
        jacobian = model.jacobian(q)[:3, 6:]
        assert np.allclose(jacobian @ sample.rates, sample.end_effector_velocity, atol=1e-8)


def test_joint_rates_and_accelerations_are_the_derivatives_of_the_angles(joint_path):
    _, _, trajectory, path = joint_path
    h = 1e-3
    for t in np.linspace(0.5, trajectory.duration - 0.5, 5):
        rate = (path.angles_at(t + h) - path.angles_at(t - h)) / (2 * h)
        acceleration = (path.at(t + h).rates - path.at(t - h).rates) / (2 * h)
        sample = path.at(t)
        assert np.allclose(sample.rates, rate, atol=1e-7)
        assert np.allclose(sample.accelerations, acceleration, atol=1e-6)


def test_references_rest_at_the_ends_of_the_path(joint_path):
    _, _, trajectory, path = joint_path
    for t in (-1.0, trajectory.duration + 1.0):
        sample = path.at(t)
        assert not sample.rates.any() and not sample.accelerations.any()
    assert np.array_equal(path.at(-1.0).angles, path.at(0.0).angles)


def test_a_path_through_a_singularity_is_refused():
    model = manipulator_model(thesis_manipulator())
    problem = reach_problem()
    start = problem.start.configuration
    shoulder = model.forward_kinematics(start).origins[0]
    # straight out to the full reach: the arm must stretch to a line, where J Jᵀ is singular
    direction = TARGET - shoulder
    edge = shoulder + model.robot.reach * direction / np.linalg.norm(direction)
    edge_problem = reach_problem(target=tuple(edge))
    trajectory = EndEffectorLinePlanner(None, np.random.default_rng(0)).plan(edge_problem)
    with pytest.raises(SingularPath, match="singularity"):
        JointPath(model, start, trajectory)


TWO_LINKS = """\
name: two-links
world: {frame: geocentric, physics_step: 0.001, control_period: 0.01, duration: 0.1}
robot:
  type: manipulator
  mass: 1000
  propellant_mass: 50
  inertia: [166.67, 166.67, 166.67]
  mount: [0.5, 0, 0]
  links:
    - {a: 0.7, alpha_deg: 90, mass: 20, inertia: [0.2, 1.87, 1.87]}
    - {a: 0.4, alpha_deg: 0, mass: 15, inertia: [0.1, 1.25, 1.25]}
  initial: {joint_angles_deg: [30, 40]}
mission: {type: reach, target: [1.2, 0.3, 0.2]}
"""


def test_an_arm_of_two_joints_is_refused_with_a_reason(tmp_path):
    scenario = tmp_path / "two_links.yaml"
    scenario.write_text(TWO_LINKS)
    summary = Runner(setup_run(scenario), None).run()
    assert summary["status"] == "stopped"
    assert "at least three links" in summary["reason"]


def test_an_unusable_trajectory_is_refused():
    problem = reach_problem()
    start = problem.start.configuration
    one_sample = Trajectory(times=[0.0], positions=[[1.4, 0.9, -0.8]], velocities=[[0, 0, 0]])
    with pytest.raises(ValueError, match="two samples"):
        JointPath(problem.model, start, one_sample)
    stretched = np.concatenate([start[:7], np.zeros(6)])  # the arm straight: singular
    line = EndEffectorLinePlanner(None, np.random.default_rng(0)).plan(problem)
    with pytest.raises(SingularPath, match="starts in a singularity"):
        JointPath(problem.model, stretched, line)
