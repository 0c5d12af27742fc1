"""fixture-intercept: the end effector onto a tumbling body's grapple bar, moving with it.

The body's motion is checked against the closed form of an axisymmetric body's
torque-free rotation, written here, not against the planner's own propagator.
"""

from __future__ import annotations

import numpy as np
import pytest
from dcsim_plugins.path_planners.fixture_intercept import FixtureInterceptPlanner
from scipy.spatial.transform import Rotation

from dcsim.api import (
    GoalRegion,
    GraspGoal,
    NoPath,
    ObjectKind,
    ObjectTrack,
    PathProblem,
    PosePath,
    RobotState,
    Trajectory,
    load_robot_model,
)
from tests.conftest import REPO

READY = np.radians([3.474921, 0.0, 90.0, 90.0, -149.725932, -123.748989])
MASS, RADIUS, LENGTH = 1400.0, 1.2, 6.5
ACROSS = MASS * (3 * RADIUS**2 + LENGTH**2) / 12
ALONG = MASS * RADIUS**2 / 2
TOOL = 0.15
FIXTURE = np.array([1.28, 0.0, 0.0])


@pytest.fixture(scope="module")
def model():
    return load_robot_model(REPO / "scenarios" / "debris_capture.yaml")


def start_state(track: ObjectTrack, standoff: float = 3.9) -> RobotState:
    """The base at ``standoff`` from the body's centre on its angular momentum axis (the
    fixture's side) and 0.4 m below it, its arm side (+x) facing the body, the arm in its
    ready pose (as the capture mission's approach leaves it)."""
    rotation = Rotation.from_quat(np.array(track.attitude)).as_matrix()
    momentum = rotation @ track.inertia @ rotation.T @ track.angular_velocity
    axis = momentum if np.linalg.norm(momentum) > 0 else rotation @ FIXTURE
    axis = axis / np.linalg.norm(axis)
    axis = axis if axis @ (rotation @ FIXTURE) > 0 else -axis
    facing, _ = Rotation.align_vectors([-axis], [[1.0, 0.0, 0.0]])
    return RobotState(
        time=track.time,
        position=track.position + standoff * axis - 0.4 * facing.apply([0.0, 0.0, 1.0]),
        attitude=facing.as_quat(),
        joint_positions=READY,
        joint_velocities=np.zeros(6),
    )


def tumbling_track(body_rates_deg: tuple[float, float, float]) -> ObjectTrack:
    """The scenario's cylinder at the origin, its body x towards -X, tumbling."""
    attitude = np.array([0.0, 0.0, 1.0, 0.0])
    rotation = Rotation.from_quat(attitude).as_matrix()
    return ObjectTrack(
        id=1,
        kind=ObjectKind.TARGET,
        time=10.0,
        position=np.zeros(3),
        velocity=np.zeros(3),
        mass=MASS,
        radius=float(np.hypot(RADIUS, LENGTH / 2)),
        attitude=attitude,
        angular_velocity=rotation @ np.radians(body_rates_deg),
        inertia=np.diag([ACROSS, ACROSS, ALONG]),
    )


def problem(model, track: ObjectTrack, standoff: float = 3.9) -> PathProblem:
    return PathProblem(
        start=start_state(track, standoff),
        goal=GoalRegion(position=track.position, tolerance=0.005),
        max_speed=0.2,
        max_acceleration=0.05,
        time_budget=20.0,
        model=model,
        grasp=GraspGoal(
            target=track,
            fixture=FIXTURE,
            approach_axis=np.array([1.0, 0.0, 0.0]),
            bar_axis=np.array([0.0, 0.0, 1.0]),
            tool_offset=TOOL,
        ),
    )


def closed_form_rotation(track: ObjectTrack, t: float) -> np.ndarray:
    """Body-to-world rotation of an axisymmetric body (moments I1 = I2, I3 about body z)
    tumbling torque-free: R(t) = Rot(h, W_p t) R0 Rot(e3, W_r t), with h the angular
    momentum's direction, W_p = |H| / I1 the precession rate and W_r = w3 (I1 - I3) / I1
    the body's spin relative to the precessing frame."""
    r0 = Rotation.from_quat(np.array(track.attitude))
    body_rates = r0.inv().apply(np.array(track.angular_velocity))
    momentum = r0.apply(np.diag([ACROSS, ACROSS, ALONG]) @ body_rates)
    precession = np.linalg.norm(momentum) / ACROSS
    spin = body_rates[2] * (ACROSS - ALONG) / ACROSS
    dt = t - track.time
    turned = Rotation.from_rotvec(momentum / np.linalg.norm(momentum) * precession * dt)
    return (turned * r0 * Rotation.from_rotvec([0.0, 0.0, spin * dt])).as_matrix()


def grasp_frame(track: ObjectTrack, t: float) -> tuple[np.ndarray, np.ndarray]:
    """Where DH frame n must be at ``t`` to hold the bar: its origin and its x axis."""
    rotation = closed_form_rotation(track, t)
    approach = rotation @ np.array([1.0, 0.0, 0.0])
    return rotation @ FIXTURE + TOOL * approach, -approach


def end_effector(model, path: PosePath, t: float, start: RobotState) -> tuple[np.ndarray, ...]:
    q = np.concatenate([start.position, start.attitude, path.at(t).angles])
    frame = model.forward_kinematics(q)
    return frame.end_effector, frame.end_effector_rotation


@pytest.mark.parametrize("rates", [(3.0, 0.3, 0.0), (5.0, 0.0, 0.4), (1.0, -0.2, 0.0)])
def test_the_end_effector_meets_the_bar_with_matched_velocity(model, rates):
    track = tumbling_track(rates)
    planner = FixtureInterceptPlanner(FixtureInterceptPlanner.Params(), np.random.default_rng(0))
    posed = problem(model, track)
    trajectory = planner.plan(posed)
    assert isinstance(trajectory, Trajectory), trajectory
    grasp_time = trajectory.statistics["grasp_time"]
    following = trajectory.times[trajectory.times >= grasp_time]
    assert following[-1] - grasp_time >= planner.params.follow_time - 1e-9
    for t in following[::10]:
        origin, x_axis = grasp_frame(track, t)
        state = trajectory.state_at(float(t))
        assert np.linalg.norm(state.position - origin) < 1e-6
        later, _ = grasp_frame(track, t + 1e-4)
        earlier, _ = grasp_frame(track, t - 1e-4)
        assert np.linalg.norm(state.velocity - (later - earlier) / 2e-4) < 1e-5
        assert Rotation.from_quat(state.attitude).as_matrix()[:, 0] @ x_axis > 1 - 1e-9
    # the arm flies it: joints follow the whole path within the goal's tolerance
    path = PosePath(model, posed.start.configuration, trajectory, step=0.02)
    assert path.tracking.max_error < posed.goal.tolerance
    reached, _ = end_effector(model, path, following[-1], posed.start)
    assert np.linalg.norm(reached - grasp_frame(track, following[-1])[0]) < 1e-3


def test_the_path_starts_where_the_end_effector_is_at_rest(model):
    track = tumbling_track((3.0, 0.3, 0.0))
    posed = problem(model, track)
    trajectory = FixtureInterceptPlanner(
        FixtureInterceptPlanner.Params(), np.random.default_rng(0)
    ).plan(posed)
    assert isinstance(trajectory, Trajectory)
    frame = model.forward_kinematics(posed.start.configuration)
    assert trajectory.times[0] == posed.start.time
    assert np.linalg.norm(trajectory.positions[0] - frame.end_effector) < 1e-12
    assert np.linalg.norm(trajectory.velocities[0]) < 1e-3


def test_a_bar_out_of_reach_gives_no_path_with_the_reason(model):
    track = tumbling_track((3.0, 0.3, 0.0))
    posed = problem(model, track, standoff=8.0)
    params = FixtureInterceptPlanner.Params(horizon=80.0)
    answer = FixtureInterceptPlanner(params, np.random.default_rng(0)).plan(posed)
    assert isinstance(answer, NoPath)
    assert "out of the arm's reach" in answer.reason


def test_a_bar_too_far_for_the_horizon_says_so(model):
    track = tumbling_track((3.0, 0.3, 0.0))
    params = FixtureInterceptPlanner.Params(horizon=5.0)
    answer = FixtureInterceptPlanner(params, np.random.default_rng(0)).plan(problem(model, track))
    assert isinstance(answer, NoPath)
    assert "too far to reach by the horizon of 5 s" in answer.reason


def test_a_bar_that_faces_away_gives_no_path(model):
    """The body turned half a turn and moved back by twice the fixture's offset: the bar
    stands where it stood, within reach, but its approach axis points away from the
    arm."""
    still = tumbling_track((0.0, 0.0, 0.0))  # the bar towards -X, where the base stands
    posed = problem(model, still)
    turned = ObjectTrack(
        **{
            **still.__dict__,
            "attitude": np.array([0.0, 0.0, 0.0, 1.0]),
            "position": still.position - 2.0 * FIXTURE,
        }
    )
    away = PathProblem(
        **{**posed.__dict__, "grasp": GraspGoal(**{**posed.grasp.__dict__, "target": turned})}
    )
    params = FixtureInterceptPlanner.Params(horizon=40.0)
    answer = FixtureInterceptPlanner(params, np.random.default_rng(0)).plan(away)
    assert isinstance(answer, NoPath)
    assert "the fixture faces away" in answer.reason
    assert "out of the arm's reach" not in answer.reason
