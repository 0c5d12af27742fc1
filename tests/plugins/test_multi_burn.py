"""The multi-burn path planner: direct two-burn transfers, burns added around a wall."""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import pytest
from dcsim_plugins.path_planners.multi_burn import BurnSearch, MultiBurnParams, MultiBurnPlanner
from dcsim_plugins.path_planners.obstacle_field import ObstacleField
from dcsim_plugins.path_planners.relative_motion import FreeMotion

from dcsim.api import (
    FrameDynamics,
    FrameKind,
    GoalRegion,
    NoPath,
    ObjectKind,
    ObjectTrack,
    PathProblem,
    RobotState,
    Shape,
    ShapeKind,
    StaticMotion,
    Trajectory,
    mean_motion,
    path_clearance,
)
from dcsim.testing import problems

LEAST_SPEED_SHARE = 0.09 / 0.19
"""The paper's least speed over its speed limit (Table 2)."""


def open_problem(**changes) -> PathProblem:
    """From rest at the origin to rest 32 m away, nothing in the way, inertial frame."""
    base = dict(
        start=RobotState(time=0.0, position=[0.0, 0.0, 0.0]),
        goal=GoalRegion(position=[30.0, 10.0, -5.0], tolerance=0.5),
        robot_radius=0.5,
        max_speed=0.5,
        max_acceleration=0.025,
        time_budget=5.0,
    )
    return PathProblem(**(base | changes))


def wall_problem(time_budget: float = 20.0, goal_time: float | None = None) -> PathProblem:
    """A 12 m square wall, 1 m thick, square across the straight line to the goal."""
    wall = ObjectTrack(
        1,
        ObjectKind.OBSTACLE,
        0.0,
        (20.0, 0.0, 0.0),
        (0.0, 0.0, 0.0),
        mass=100.0,
        motion=StaticMotion((20.0, 0.0, 0.0)),
        shape=Shape(ShapeKind.BOX, half_extents=(0.5, 6.0, 6.0)),
    )
    return PathProblem(
        start=RobotState(time=0.0, position=[0.0, 0.0, 0.0]),
        goal=GoalRegion(position=[40.0, 0.0, 0.0], tolerance=0.5, time=goal_time),
        obstacles=(wall,),
        robot_radius=0.5,
        max_speed=0.5,
        max_acceleration=0.025,
        max_delta_v=5.0,
        time_budget=time_budget,
    )


@pytest.mark.parametrize("min_speed", [None, 0.3])
def test_unobstructed_rest_to_rest_is_the_slowest_direct_transfer(min_speed):
    # In a force-free frame the two burns cost 2 chord / T, least at the least mean speed.
    problem = open_problem()
    params = MultiBurnParams(min_speed=min_speed)
    least = min_speed if min_speed is not None else LEAST_SPEED_SHARE * problem.max_speed
    offset = problem.goal.position - problem.start.position
    duration = np.linalg.norm(offset) / least

    search = BurnSearch(problem, params)
    direct = search.two_burn()
    plan = search.plan(direct)
    assert direct.clear
    assert direct.durations == pytest.approx([duration], rel=1e-9)
    assert plan.delta_v == pytest.approx(2 * least, rel=1e-9)
    assert plan.burns()[0] == pytest.approx(offset / duration, rel=1e-9)

    trajectory = MultiBurnPlanner(params).plan(problem)
    assert isinstance(trajectory, Trajectory)
    assert trajectory.statistics["burns"] == 2
    assert trajectory.times[-1] == pytest.approx(duration, rel=1e-9)
    assert trajectory.positions[-1] == pytest.approx(problem.goal.position, abs=1e-9)
    assert problem.goal.contains(trajectory.end_state(problem.goal))


def test_two_burn_time_about_an_orbit_is_the_best_of_a_dense_scan():
    # About an orbit the delta-v has a minimum inside the allowed transfer times here,
    # with both burns within the largest burn.
    n = mean_motion(6_778_137.0)
    problem = open_problem(
        goal=GoalRegion(position=[5.0, -30.0, 20.0], tolerance=0.5),
        frame=FrameDynamics(kind=FrameKind.CLOHESSY_WILTSHIRE, mean_motion=n),
        max_speed=0.03,
    )
    motion = FreeMotion(n)
    chord = float(np.linalg.norm(problem.goal.position))
    times = np.linspace(
        chord / problem.max_speed,
        min(chord / (LEAST_SPEED_SHARE * problem.max_speed), motion.longest_duration),
        20_001,
    )
    goal = np.broadcast_to(problem.goal.position, (len(times), 3))
    departure, arrival = motion.single_burn(np.zeros((len(times), 3)), goal, times)
    burns = np.stack([np.linalg.norm(departure, axis=1), np.linalg.norm(arrival, axis=1)])
    largest = 0.2 / 0.19 * problem.max_speed
    scan = np.where((burns <= largest).all(axis=0), burns.sum(axis=0), np.inf)
    best = int(np.argmin(scan))
    assert 0 < best < len(times) - 1 and burns[:, best].max() < 0.95 * largest  # inside

    direct = BurnSearch(problem, MultiBurnParams()).two_burn()
    assert direct.violation == 0
    assert direct.cost <= scan[best] + 1e-12
    assert direct.cost == pytest.approx(scan[best], rel=1e-6)
    assert direct.durations[0] == pytest.approx(times[best], rel=1e-3)


@pytest.mark.parametrize("goal_time", [None, 250.0])
def test_a_wall_in_the_way_gets_more_burns_and_a_clear_plan(goal_time):
    problem = wall_problem(goal_time=goal_time)
    params = MultiBurnParams(refine=2)
    direct = BurnSearch(problem, params).two_burn()
    assert not direct.clear  # the straight line runs through the wall

    trajectory = MultiBurnPlanner(params).plan(problem)
    assert isinstance(trajectory, Trajectory)
    assert trajectory.statistics["burns"] >= 3
    assert not path_clearance(trajectory, problem).collides
    assert problem.goal.contains(trajectory.end_state(problem.goal))
    if goal_time is not None:
        assert trajectory.times[-1] == pytest.approx(goal_time, abs=1e-9)


def test_a_plan_comes_within_the_budget():
    problem = wall_problem(time_budget=0.5)
    start = time.perf_counter()
    trajectory = MultiBurnPlanner().plan(problem)
    elapsed = time.perf_counter() - start
    assert elapsed < 1.2 * problem.time_budget + 0.2
    assert isinstance(trajectory, Trajectory)
    assert not path_clearance(trajectory, problem).collides


def test_the_same_problem_gives_the_same_plan():
    problem = wall_problem()
    params = MultiBurnParams(refine=2)
    first = MultiBurnPlanner(params, rng=np.random.default_rng(1)).plan(problem)
    second = MultiBurnPlanner(params, rng=np.random.default_rng(2)).plan(problem)
    assert isinstance(first, Trajectory)
    np.testing.assert_array_equal(first.times, second.times)
    np.testing.assert_array_equal(first.positions, second.positions)
    assert first.statistics == second.statistics


def test_too_few_burns_or_a_goal_time_passed_is_no_path():
    answer = MultiBurnPlanner(MultiBurnParams(max_burns=2)).plan(wall_problem())
    assert isinstance(answer, NoPath)
    assert "2 burns" in answer.reason
    late = wall_problem()
    late = dataclasses.replace(late, start=dataclasses.replace(late.start, time=300.0))
    answer = MultiBurnPlanner().plan(
        dataclasses.replace(late, goal=wall_problem(goal_time=250.0).goal)
    )
    assert isinstance(answer, NoPath)
    assert "goal's time" in answer.reason


def test_arc_overlaps_are_zero_exactly_where_arcs_are_clear():
    problem = problems.path_problem()
    field = ObstacleField(dataclasses.replace(problem, safety_margin=0.2))
    rng = np.random.default_rng(3)
    centres = np.array([track.position for track in problem.obstacles])
    starts = centres[rng.integers(len(centres), size=200)] + rng.uniform(-5, 5, (200, 3))
    steps = rng.normal(0.0, 0.2, (200, 1, 3))
    points = starts[:, None, :] + steps * np.arange(40)[:, None]
    times = np.broadcast_to(np.arange(40.0) * 3, (200, 40))
    margins = rng.uniform(0.0, 0.3, 200)
    which = np.arange(field.count)
    depth = field.arc_overlaps(points, times, margins, which)
    clear = field.clear_arcs(points, times, margins, which)
    assert 20 < clear.sum() < 180  # both kinds are present
    np.testing.assert_array_equal(depth == 0, clear)
    assert np.all(depth >= 0)
