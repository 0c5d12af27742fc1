"""The straight-line baseline path planner."""

from __future__ import annotations

import numpy as np
import pytest
from dcsim_plugins.path_planners.straight_line import StraightLinePlanner

from dcsim.api import (
    Bounds,
    GoalRegion,
    LinearMotion,
    NoPath,
    ObjectKind,
    ObjectTrack,
    PathProblem,
    RobotState,
    Trajectory,
)


def obstacle(obstacle_id, position, velocity=(0, 0, 0), radius=1.0):
    return ObjectTrack(
        obstacle_id,
        ObjectKind.OBSTACLE,
        0.0,
        position,
        velocity,
        radius=radius,
        motion=LinearMotion(position, velocity),
    )


def problem(goal=(20, 0, 0), obstacles=(), goal_time=None, **kwargs):
    return PathProblem(
        start=RobotState(time=0.0, position=[0, 0, 0]),
        goal=GoalRegion(position=goal, tolerance=0.5, time=goal_time),
        obstacles=tuple(obstacles),
        robot_radius=0.5,
        max_speed=1.0,
        **kwargs,
    )


def test_free_segment_at_the_planning_speed():
    result = StraightLinePlanner().plan(problem())
    assert isinstance(result, Trajectory)
    np.testing.assert_allclose(result.positions[0], [0, 0, 0])
    np.testing.assert_allclose(result.positions[-1], [20, 0, 0])
    assert result.duration == pytest.approx(20 / 0.8)
    assert result.length == pytest.approx(20.0)
    assert result.delta_v == pytest.approx(2 * 0.8)  # accelerate, then stop at the goal


def test_required_arrival_time_sets_the_speed_or_is_refused():
    timed = StraightLinePlanner().plan(problem(goal_time=40.0))
    assert isinstance(timed, Trajectory) and timed.times[-1] == pytest.approx(40.0)
    rushed = StraightLinePlanner().plan(problem(goal_time=10.0))
    assert isinstance(rushed, NoPath)
    assert "needs 20 s at the speed and acceleration limits, only 10 s are left" in rushed.reason


def test_trapezoid_respects_the_acceleration_limit_and_ends_at_rest():
    result = StraightLinePlanner().plan(problem(max_acceleration=0.05))
    assert isinstance(result, Trajectory)
    speeds = np.linalg.norm(result.velocities, axis=1)
    accelerations = np.abs(np.diff(speeds)) / np.diff(result.times)
    assert accelerations.max() <= 0.05 * (1 + 1e-9)
    assert speeds[0] == pytest.approx(0.0) and speeds[-1] == pytest.approx(0.0)
    assert speeds.max() == pytest.approx(0.8)
    # 20 m at 0.8 m/s with 16 s ramps at each end: 25 s cruising-equivalent + 16 s.
    assert result.duration == pytest.approx(20 / 0.8 + 0.8 / 0.05)


def test_moving_goal_is_met_at_its_time_with_its_velocity():
    moving = PathProblem(
        start=RobotState(time=5.0, position=[0, 0, 0]),
        goal=GoalRegion(position=[30, 10, 0], tolerance=0.5, velocity=[0, 0.2, 0], time=65.0),
        robot_radius=0.5,
        max_speed=1.0,
        max_acceleration=0.05,
    )
    result = StraightLinePlanner().plan(moving)
    assert isinstance(result, Trajectory)
    position, velocity = result.sample(65.0)
    np.testing.assert_allclose(position, [30, 10, 0], atol=1e-9)
    np.testing.assert_allclose(velocity, [0, 0.2, 0], atol=1e-9)
    assert result.times[0] == pytest.approx(5.0)


def test_static_obstacle_on_the_segment_blocks_it():
    result = StraightLinePlanner().plan(problem(obstacles=[obstacle(42, (10, 0.5, 0))]))
    assert isinstance(result, NoPath)
    assert "obstacle 42" in result.reason


def test_moving_obstacle_blocks_only_if_it_is_there_when_the_collector_passes():
    # The collector passes x = 10 at t = 12.5 s. An obstacle crossing the line then blocks;
    # the same obstacle crossing 20 s earlier does not.
    crossing_now = obstacle(1, (10, -12.5, 0), velocity=(0, 1.0, 0))
    crossing_early = obstacle(2, (10, 7.5, 0), velocity=(0, 1.0, 0))
    assert isinstance(StraightLinePlanner().plan(problem(obstacles=[crossing_now])), NoPath)
    assert isinstance(StraightLinePlanner().plan(problem(obstacles=[crossing_early])), Trajectory)


def test_goal_inside_an_obstacle_has_no_path():
    result = StraightLinePlanner().plan(problem(obstacles=[obstacle(3, (20, 0, 0), radius=2.0)]))
    assert isinstance(result, NoPath) and "obstacle 3" in result.reason


def test_bounds_and_delta_v_limits():
    box = Bounds(lower=[-1, -1, -1], upper=[10, 1, 1])
    assert "leaves the bounds" in StraightLinePlanner().plan(problem(bounds=box)).reason
    assert "delta-v" in StraightLinePlanner().plan(problem(max_delta_v=1.0)).reason
