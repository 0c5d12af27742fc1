"""The capture scenario (scenarios/debris_capture.yaml) cut short: the base starts at its
standoff and the target is turned as it is when the shipped run asks its planner, so
the whole capture (observe, intercept, grasp, latch, detumble) flies in 16.5 s of
simulated time instead of 113; then the approach, and the capture's refusals and
aborts."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest
import yaml
from dcsim_plugins.path_planners.ant_colony.planner import AntColonyPlanner

from dcsim.api import (
    NoPath,
    PathProblem,
    RunResult,
    ScenarioError,
    ShapeKind,
    Trajectory,
    close_run,
    load_scenario,
    manipulator_model,
    open_run,
    run,
    shortest_duration,
)
from dcsim.errors import PlanOutlastsRunWarning
from tests.conftest import CAPTURE, capture_approach_line, short_capture
from tests.test_runner import registry_with

OBSERVATION = 0.5
"""Observation time (s) of the short run."""
DURATION = 22.0
"""Duration (s) of the short run: it is detumbled at 16.5 s."""
MODES = ("ACQUIRE", "APPROACH", "OBSERVE", "INTERCEPT", "GRASP", "DETUMBLE", "CAPTURED")
GRIP_DISTANCE = 0.005
"""Largest distance (m) of the bar from the pads' centre at latch time."""
GRIP_SPEED = 0.005
"""Largest speed (m/s) of the bar relative to the pads at latch time."""


@pytest.fixture(scope="module")
def capture(tmp_path_factory) -> RunResult:
    """The short capture, run into a run directory."""
    out = tmp_path_factory.mktemp("capture") / "run"
    return run(CAPTURE, short_capture(OBSERVATION, DURATION), out=out)


def named(result: RunResult, event: str) -> list[dict]:
    return [e for e in result.events if e["event"] == event]


def test_the_capture_passes_every_mode_in_order(capture):
    modes = [e["mode"] for e in named(capture, "mode")]
    assert [named(capture, "mode")[0]["previous"], *modes] == list(MODES)
    order = [e["event"] for e in capture.events if e["event"] != "mode"]
    # the short run starts at its standoff, inside the approach planner's keep-out
    expected = ["approach_within_keep_out", "path", "gripper_closing", "contact", "latched"]
    assert order == [*expected, "detumbled"]
    assert capture.status == "completed"
    assert capture.summary["reason"] == "target captured and detumbled"
    assert capture.summary["sim_time_s"] < DURATION


def test_the_summary_says_captured_within_the_limits(capture):
    summary = capture.summary
    gripper = load_scenario(CAPTURE).robot.gripper
    assert summary["goal_met"] and summary["captured"] and summary["detumbled"]
    assert 0.0 < summary["peak_contact_force_N"] < gripper.force_limit
    assert summary["force_limit_exceeded"] is False
    assert summary["max_base_turn_deg"] <= 5.0
    assert np.isfinite(summary["detumble_time_s"]) and summary["detumble_time_s"] > 0.0
    assert summary["contact_time_s"] < summary["latch_time_s"]


def test_the_bar_sits_between_the_pads_and_moves_with_them_at_latch_time(capture):
    telemetry = capture.telemetry
    units = telemetry.attrs["units"]
    offset = [f"fixture_d{a}_m" for a in "xyz"]
    velocity = [f"fixture_dv{a}_mps" for a in "xyz"]
    assert {units[c] for c in offset} == {"m"} and {units[c] for c in velocity} == {"m/s"}
    latched = named(capture, "latched")[0]["t"]
    row = telemetry[np.isclose(telemetry["time_s"], latched, rtol=0.0, atol=1e-9)]
    assert len(row) == 1
    assert np.linalg.norm(row[offset].to_numpy()) < GRIP_DISTANCE
    assert np.linalg.norm(row[velocity].to_numpy()) < GRIP_SPEED


def test_the_capture_plot_is_written(capture):
    assert capture.run_dir is not None
    plot = Path(capture.run_dir) / "plots" / "capture.png"
    assert plot.stat().st_size > 10_000  # bytes: a drawn figure, not an empty file


def test_a_planner_that_finds_nothing_aborts_the_capture_with_its_reason():
    overrides = {**short_capture(OBSERVATION, DURATION), "path_planner.params.horizon": 0.01}
    result = run(CAPTURE, overrides)
    refusal = named(result, "no_path")[0]["reason"]
    assert refusal.startswith("the fixture is too far to reach by the horizon of 0.01 s")
    assert [refusal in e["reason"] for e in named(result, "abort")] == [True]
    assert named(result, "mode")[-1]["mode"] == "ABORT"
    assert result.status == "stopped" and refusal in result.summary["reason"]
    assert result.summary["captured"] is False and result.summary["goal_met"] is False


def test_a_capture_without_a_gripper_is_refused_naming_the_key():
    data = yaml.safe_load(CAPTURE.read_text(encoding="utf-8"))
    del data["robot"]["gripper"]
    with pytest.raises(ScenarioError) as refused:
        load_scenario(data)
    assert "robot.gripper: a capture needs a gripper: add `gripper: {}`" in str(refused.value)


def test_a_capture_in_the_lvlh_frame_is_refused_by_the_cli(dcsim_cli):
    done = dcsim_cli("run", str(CAPTURE), "--set", "world.frame=lvlh")
    assert done.returncode == 2
    assert "world.frame: a capture's tumbling body moves in free space" in done.stderr
    assert "use `geocentric`" in done.stderr and "Traceback" not in done.stderr


def test_a_body_striking_the_base_is_named_in_an_event_and_counted():
    """The target drifting into the back of the base (the shipped start, on the x axis,
    a 1 m cube; the cylinder's side 5 cm off it) while the robot watches it (ACQUIRE):
    the mission names the base once in an ``arm_contact`` event and the summary counts
    one link struck."""
    base = load_scenario(CAPTURE).robot.initial.position[0]
    start = [base - 0.5 - 1.2 - 0.05, 0.0, 0.0]
    overrides = {
        "mission.target.position": start,
        "mission.target.velocity": [0.1, 0.0, 0.0],
        "world.duration": 1.0,
    }
    result = run(CAPTURE, overrides, plots=False)
    assert [e["links"] for e in named(result, "arm_contact")] == [["base"]]
    assert result.summary["arm_links_struck"] == 1


@pytest.mark.filterwarnings("ignore::dcsim.errors.PlanOutlastsRunWarning")  # cut short
def test_the_standoff_waits_for_the_tracker_and_an_exact_track_does_not():
    """Under the shipped object sensor the robot holds at its start for the acquisition
    time while the tracker learns the tumble; with the truth as the track it leaves at
    once."""
    acquisition = {"mission.acquisition_time": 2.0, "world.duration": 2.5}
    tracked = run(CAPTURE, acquisition, plots=False)
    exact = run(CAPTURE, {**acquisition, "sensors.objects": None}, plots=False)
    for result, leaves in ((tracked, 2.0), (exact, 0.0)):
        (approach,) = named(result, "mode")
        assert (approach["previous"], approach["mode"]) == ("ACQUIRE", "APPROACH")
        assert approach["t"] == pytest.approx(leaves, abs=1e-9)
    held = tracked.telemetry[tracked.telemetry["time_s"] < 2.0 - 1e-9]
    start = load_scenario(CAPTURE).robot.initial.position
    drift = held[["x_m", "y_m", "z_m"]].to_numpy() - np.asarray(start)
    assert np.abs(drift).max() < 1e-3  # m: held at the start while it watches


def test_a_target_the_sensor_cannot_see_aborts_the_capture_before_the_approach():
    """An object sensor of 1 m range never detects the body 8 m away: the capture aborts
    at the end of the acquisition, naming why, and the base never leaves its start."""
    overrides = {
        "robot.sensor_range": 1.0,
        "mission.acquisition_time": 1.0,
        "world.duration": 3.0,
    }
    result = run(CAPTURE, overrides, plots=False)
    ((abort,),) = [named(result, "abort")]
    assert abort["t"] == pytest.approx(1.0, abs=1e-9)
    assert abort["reason"].startswith("the target is not tracked")
    assert [e["mode"] for e in named(result, "mode")] == ["ABORT"]
    assert result.status == "stopped"


def test_the_sensed_detumble_is_the_world_s(capture):
    """The mission judges the detumble by the rates the robot senses (the base's gyros,
    the palm's rate through the arm's Jacobian); over the second before it says so,
    the world's own rates of the base and the target are within the limit too, and
    just before it the target's was not."""
    limit = np.radians(load_scenario(CAPTURE).mission.detumbled_rate_deg_s)
    (detumbled,) = named(capture, "detumbled")
    telemetry = capture.telemetry
    times = telemetry["time_s"].to_numpy()
    last_second = (times > detumbled["t"] - 1.0 + 1e-9) & (times <= detumbled["t"] + 1e-9)
    assert last_second.sum() >= 90  # control periods of 0.01 s
    for column in ("target_rate_radps", "base_rate_radps"):
        assert telemetry.loc[last_second, column].max() <= limit
    # and the world's target crosses the limit when the sensed rates do, within 0.05 s
    before = (times > detumbled["t"] - 1.05) & (times <= detumbled["t"] - 1.0 + 1e-9)
    assert telemetry.loc[before, "target_rate_radps"].max() > limit


FAR_SIDE = [9.0, 0.0, 0.0]
"""A start on the far side of the target from its standoff (m): the shipped target's
angular momentum, and so the standoff, points along -x."""


def test_an_approach_through_the_tumble_is_refused_before_the_base_moves():
    """From the far side the straight approach would fly through the tumbling body (it
    struck the base at 110 s when the approach was a straight move); the approach
    planner refuses it and the capture aborts, naming why, before the base moves."""
    overrides = {"robot.initial.position": FAR_SIDE, "sensors.objects": None}
    result = run(CAPTURE, {**overrides, "world.duration": 0.5}, plots=False)
    (refusal,) = named(result, "no_path")
    assert (refusal["t"], refusal["role"]) == (0.0, "approach_planner")
    assert refusal["reason"].startswith("the straight path passes")
    (abort,) = named(result, "abort")
    assert abort["reason"] == f"no approach path: {refusal['reason']}"
    moved = result.telemetry[["x_m", "y_m", "z_m"]].to_numpy() - np.asarray(FAR_SIDE)
    assert np.abs(moved).max() < 1e-6
    assert result.status == "stopped"


class RecordingAntColony(AntColonyPlanner):
    """ant-colony, keeping the problems it is given and its answers (test)."""

    name = "recording-ant-colony"
    summary = "ant-colony, keeping its problems and answers (test)"
    answers: ClassVar[list[tuple[PathProblem, Trajectory | NoPath]]] = []

    def plan(self, problem: PathProblem) -> Trajectory | NoPath:
        answer = super().plan(problem)
        self.answers.append((problem, answer))
        return answer


@pytest.mark.filterwarnings("ignore::dcsim.errors.PlanOutlastsRunWarning")  # cut short
def test_a_planned_approach_keeps_the_arm_clear_of_the_tumble_s_sweep():
    """An approach planner that goes round obstacles (ant-colony) takes the base from
    the far side to the gate with the robot's sphere clear of the sphere the tumbling
    body sweeps by the approach clearance; the straight line it replaces passes within a
    metre of the body's centre."""
    RecordingAntColony.answers.clear()
    overrides = {
        "robot.initial.position": FAR_SIDE,
        "sensors.objects": None,
        "approach_planner.plugin": "recording-ant-colony",
        "world.duration": 0.5,
    }
    result = run(CAPTURE, overrides, plots=False, registry=registry_with(RecordingAntColony))
    ((problem, path),) = RecordingAntColony.answers
    (flight,) = named(result, "approach_path")
    assert isinstance(path, Trajectory)
    (obstacle,) = problem.obstacles
    keep_out = obstacle.radius + problem.robot_radius + problem.safety_margin
    times = np.linspace(path.times[0], path.times[-1], 20_001)
    positions, _ = path.sample(times)
    assert np.linalg.norm(positions - obstacle.position, axis=1).min() >= keep_out
    assert np.linalg.norm(positions[-1] - problem.goal.position) < 1e-6
    # the case needs a way round: the straight line passes within a metre of the centre
    gate = problem.goal.position
    line = np.linspace(0.0, 1.0, 1001)[:, None] * (gate - FAR_SIDE) + FAR_SIDE
    assert np.linalg.norm(line - obstacle.position, axis=1).min() < 1.0
    assert flight["length"] == pytest.approx(path.length)


def test_the_approach_planner_plans_a_free_flyer_and_must_be_named():
    """The approach planner plans the base as a free flyer: a manipulator-only planner
    is refused there, naming the role; a capture without one is refused too."""
    data = yaml.safe_load(CAPTURE.read_text(encoding="utf-8"))
    with pytest.raises(ScenarioError) as wrong:
        load_scenario({**data, "approach_planner": {"plugin": "fixture-intercept"}})
    assert (
        "approach_planner.plugin: approach_planner plugin 'fixture-intercept' does not support "
        "robot type 'free-flyer', which the approach_planner plans for (it supports: "
        "manipulator)"
    ) in str(wrong.value)
    with pytest.raises(ScenarioError) as missing:
        load_scenario({**data, "approach_planner": None})
    assert "approach_planner: a capture needs an approach planner" in str(missing.value)


def test_the_approach_problem_keeps_the_held_arm_clear_of_the_tumble():
    """The approach planner is asked for the base's flight to the gate with the target as
    a sphere of its bounding radius (all it sweeps while it tumbles) at rest where its
    track puts it (as the standoff and the gate take it), the robot as a
    sphere holding its base and its held arm with the gripper, and the approach
    clearance as the safety margin; the gate lies on the standoff's line, twice the
    clearance beyond touching, and as far below the target's centre as the standoff."""
    RecordingAntColony.answers.clear()
    overrides = {"approach_planner.plugin": "recording-ant-colony", "sensors.objects": None}
    registry = registry_with(RecordingAntColony)
    with pytest.warns(PlanOutlastsRunWarning):  # cut short
        run(CAPTURE, {**overrides, "world.duration": 0.5}, plots=False, registry=registry)
    ((problem, _),) = RecordingAntColony.answers
    scenario = load_scenario(CAPTURE)
    target, robot, mission = scenario.mission.target, scenario.robot, scenario.mission
    (obstacle,) = problem.obstacles
    radius = target.shape.build().bounding_radius
    assert obstacle.shape.kind is ShapeKind.SPHERE and obstacle.radius == pytest.approx(radius)
    assert np.allclose(obstacle.position, target.position)
    assert not np.any(obstacle.velocity) and obstacle.motion is None  # at rest, as the gate
    start = np.concatenate(
        [robot.initial.position, [0.0, 0.0, 0.0, 1.0], np.radians(robot.initial.joint_angles_deg)]
    )
    kinematics = manipulator_model(robot.dh_robot()).kinematics(start)
    arm = np.linalg.norm(kinematics.end_effector - kinematics.base_position)
    pads = robot.gripper.reach + 0.5 * robot.gripper.opening  # the open pads' far edge
    assert arm + pads < problem.robot_radius < robot.radius  # the arm as held, not stretched
    assert problem.robot_radius == pytest.approx(2.43, abs=0.005)  # the scenario's comment
    assert problem.safety_margin == mission.approach_clearance
    assert problem.model is None  # the base, as a free flyer
    line = capture_approach_line(CAPTURE)
    out = radius + problem.robot_radius + 2.0 * mission.approach_clearance  # along the axis
    assert np.allclose(problem.goal.position, line.point(out), rtol=0.0, atol=1e-9)
    assert abs(problem.goal.attitude @ line.facing) == pytest.approx(1.0, abs=1e-12)


def test_the_base_flies_its_path_to_the_gate_then_straight_in_to_the_standoff():
    """From just beyond the gate on the approach line (faster limits, so that it takes
    about 24 s): the references follow the planned flight, hand over to the move in
    without a jump and end at rest at the standoff, where the base arrives and OBSERVE
    holds it."""
    scenario = load_scenario(CAPTURE)
    line, mission = capture_approach_line(CAPTURE), scenario.mission
    speed = 0.3  # m/s
    overrides = {
        "robot.initial.position": line.point(7.2).tolist(),
        "robot.initial.attitude": line.facing.tolist(),
        "sensors.objects": None,
        "mission.approach_speed": speed,
        "mission.approach_acceleration": 0.05,  # the base's 100 N give it 0.09 m/s^2
        "world.duration": 30.0,
    }
    runner = open_run(CAPTURE, overrides, plots=False)
    try:
        references = []
        while runner.mode in ("ACQUIRE", "APPROACH"):
            references.append(runner.reference)
            runner.advance()
        references.append(runner.reference)  # the first of OBSERVE: held at the standoff
        arrived = runner.world.robot_state().position
        path, standoff = runner.mission.approach_path, runner.mission.standoff
    finally:
        close_run(runner)
    positions = np.array([r.position for r in references])
    steps = np.linalg.norm(np.diff(positions, axis=0), axis=1)
    period = scenario.world.control_period
    assert steps.max() <= speed * period * (1 + 1e-9)  # no jump, the hand-over included
    handed = np.searchsorted([r.time for r in references], path.times[-1])
    assert 0 < handed < len(references) - 1  # both legs were flown
    assert np.allclose(positions[-1], standoff.point, rtol=0.0, atol=1e-9)
    assert references[-1].velocity is not None and not np.any(references[-1].velocity)
    assert np.allclose(standoff.point, line.point(mission.standoff), rtol=0.0, atol=1e-9)
    assert np.linalg.norm(arrived - standoff.point) < 0.02  # m


def test_a_start_inside_the_keep_out_off_the_approach_line_is_refused():
    """Inside the keep-out but beside the approach line a straight move in could cross
    the tumble: the capture aborts, saying where the robot is and what to change."""
    line = capture_approach_line(CAPTURE)
    side = np.cross(line.axis, [0.0, 0.0, 1.0])
    start = line.point(4.5) + 1.5 * side / np.linalg.norm(side)
    overrides = {"robot.initial.position": start.tolist(), "sensors.objects": None}
    result = run(CAPTURE, {**overrides, "world.duration": 0.5}, plots=False)
    (abort,) = named(result, "abort")
    assert abort["t"] == 0.0
    assert "inside the approach planner's keep-out of 6.39 m" in abort["reason"]
    assert "off the approach line between the standoff and the gate" in abort["reason"]
    assert not named(result, "no_path") and result.status == "stopped"


def test_a_run_cut_short_of_the_approach_says_when_the_approach_would_end():
    """The warning of a plan outlasting the run names the whole approach's end: the
    planned flight's end and the move in from where it ends to the standoff."""
    overrides = {"sensors.objects": None, "world.duration": 1.0}
    with pytest.warns(PlanOutlastsRunWarning, match=r"ends at t = \d+\.\d s, after"):
        runner = open_run(CAPTURE, overrides, plots=False)
    try:
        path, standoff = runner.mission.approach_path, runner.mission.standoff
        while not runner.ended:
            runner.advance()
    finally:
        result = close_run(runner)
    settings = load_scenario(CAPTURE).mission
    length = np.linalg.norm(standoff.point - path.positions[-1])
    move_in = shortest_duration(length, settings.approach_speed, settings.approach_acceleration)
    (outlasts,) = named(result, "plan_outlasts_run")
    assert outlasts["plan_end"] == pytest.approx(path.times[-1] + move_in, rel=1e-12)
    assert outlasts["plan_end"] > path.times[-1] + 30.0  # s: the move in is most of it


def test_the_detumble_is_judged_by_the_sensed_rates_not_the_world_s():
    """Once the stack is still in the world, an estimate that says the base still turns
    at 1 deg/s keeps the detumble from being declared, however long it lasts; the
    estimate as it is declares it after a second."""
    runner = open_run(CAPTURE, short_capture(OBSERVATION, DURATION), plots=False)
    try:
        while not runner.ended:
            runner.advance()
        assert runner.mode == "CAPTURED"
        mission, estimate, now = runner.mission, runner.estimate, runner.world.time
        turning = dataclasses.replace(
            estimate, angular_velocity=estimate.angular_velocity + [0.0, 0.0, np.radians(1.0)]
        )
        for sensed, declared in ((estimate, True), (turning, False)):
            mission.still_since = None
            for k in range(150):  # 1.5 s of control periods
                mission._check_still(now + 0.01 * k, sensed)
            assert (mission.still_since is not None) is declared
    finally:
        close_run(runner)
