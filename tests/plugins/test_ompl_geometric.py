"""The ompl-geometric path planner: static fields, timing, refusals."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from dcsim_plugins.path_planners.ompl.geometric import MOVING_REFUSAL, OmplGeometricPlanner

from dcsim.api import (
    Bounds,
    GoalRegion,
    NoPath,
    PathProblem,
    RobotState,
    Shape,
    ShapeKind,
    Trajectory,
    path_clearance,
)
from dcsim.testing.problems import obstacle_track


def track(obstacle_id, position, **properties):
    """An obstacle track, a sphere of radius 2 m unless ``properties`` say otherwise."""
    return obstacle_track(obstacle_id, position, **{"radius": 2.0, **properties})


WALL = Shape(ShapeKind.BOX, half_extents=(0.5, 6.0, 6.0))


def problem(**changes):
    """A 20 m transfer behind a wall with a sphere beside it."""
    base = PathProblem(
        start=RobotState(time=0.0, position=[0.0, 0.0, 0.0]),
        goal=GoalRegion(position=[20.0, 0.0, 0.0], tolerance=1.0),
        obstacles=(track(1, (10.0, 0.0, 0.0), shape=WALL), track(2, (10.0, 8.0, 0.0))),
        robot_radius=0.5,
        max_speed=1.0,
        max_acceleration=0.1,
        bounds=Bounds(lower=[-5.0, -15.0, -15.0], upper=[25.0, 15.0, 15.0]),
        time_budget=2.0,
    )
    return dataclasses.replace(base, **changes)


def plan(p, seed=1, **params):
    return OmplGeometricPlanner(params or None, np.random.default_rng(seed)).plan(p)


@pytest.fixture(scope="module")
def default_plan():
    return plan(problem())


def test_the_path_goes_round_the_wall_simplified_and_rest_to_rest(default_plan):
    p = problem()
    assert isinstance(default_plan, Trajectory), default_plan
    assert p.goal.contains(default_plan.end_state(p.goal))
    assert not path_clearance(default_plan, p).collides
    stats = default_plan.statistics
    assert 3 <= stats["waypoints"] <= stats["raw_waypoints"]
    # at rest at every waypoint, never faster or harder than allowed, attitude held
    at_rest = np.linalg.norm(default_plan.velocities, axis=1) < 1e-12
    assert at_rest.sum() >= stats["waypoints"]
    assert np.linalg.norm(default_plan.velocities, axis=1).max() <= 0.8 + 1e-9
    rates = np.linalg.norm(np.diff(default_plan.velocities, axis=0), axis=1)
    assert (rates / np.diff(default_plan.times)).max() <= 0.1 * (1 + 1e-9)
    assert default_plan.attitudes is None


def test_same_seed_same_path(default_plan):
    again = plan(problem())
    np.testing.assert_array_equal(default_plan.positions, again.positions)


@pytest.mark.parametrize("planner", ["rrt", "rrtstar", "informed-rrtstar", "sorrtstar"])
def test_every_planner_constructs_and_solves(planner):
    p = problem()
    trajectory = plan(p, planner=planner, optimise_for=0.05)
    assert isinstance(trajectory, Trajectory), trajectory
    np.testing.assert_array_equal(trajectory.positions[0], p.start.position)
    assert trajectory.length > 20.0
    assert not path_clearance(trajectory, p).collides
    assert p.goal.contains(trajectory.end_state(p.goal))


def test_moving_obstacles_are_refused_with_the_reason():
    p = problem(obstacles=(*problem().obstacles, track(3, (5.0, -9.0, 0.0), velocity=(0, 0.1, 0))))
    assert plan(p) == NoPath(MOVING_REFUSAL)


def test_a_moving_start_brakes_first_and_a_later_goal_time_is_waited_for():
    start = RobotState(time=5.0, position=[0.0, 0.0, 0.0], velocity=[0.0, 0.3, 0.0])
    goal = GoalRegion(position=[20.0, 0.0, 0.0], tolerance=1.0, time=400.0, time_tolerance=1.0)
    p = problem(start=start, goal=goal)
    trajectory = plan(p)
    assert isinstance(trajectory, Trajectory), trajectory
    np.testing.assert_array_equal(trajectory.velocities[0], [0.0, 0.3, 0.0])
    assert trajectory.times[0] == 5.0 and trajectory.times[-1] == 400.0
    assert goal.contains(trajectory.end_state(goal))
    assert not path_clearance(trajectory, p).collides
    too_soon = dataclasses.replace(goal, time=20.0)
    answer = plan(problem(goal=too_soon))
    assert isinstance(answer, NoPath) and "after the goal's time 20 s" in answer.reason


def test_a_goal_inside_an_obstacle_is_no_path():
    p = problem(obstacles=(*problem().obstacles, track(9, (20.0, 0.0, 0.0), radius=2.0)))
    assert plan(p) == NoPath("the goal region is inside obstacle 9")
