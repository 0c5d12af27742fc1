"""The ompl-control path planner: eq. 2's propagation, the control sets, and its plans."""

from __future__ import annotations

import dataclasses
import math
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from dcsim_plugins.path_planners.ompl.control import OmplControlParams, OmplControlPlanner
from dcsim_plugins.path_planners.ompl.rigid_body import Model, discrete_control
from dcsim_plugins.path_planners.ompl.support import in_worker, seed_ompl

from dcsim.api import (
    Bounds,
    GoalRegion,
    NoPath,
    PathProblem,
    PluginParameterError,
    RobotState,
    Trajectory,
    path_clearance,
    rotate,
)
from dcsim.bench.path_problems import load_problem
from dcsim.testing.problems import obstacle_track

ESCAPE = Path(__file__).resolve().parents[2] / "scenarios" / "asteroid_escape.yaml"


def model(discrete=False, rk4=False, inertia=(0.1, 0.2, 0.3)):
    return Model(0.5, 0.01, 1.0, inertia, discrete, rk4, 0.0)


def fly(m, x, u, dt, steps):
    for _ in range(steps):
        x = m.step(x, u, dt)
    return np.array(x)


REST = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]


@pytest.mark.parametrize("rk4", [False, True])
def test_constant_thrust_follows_the_closed_form(rk4):
    start = list(REST)
    start[7:10] = [0.2, -0.1, 0.0]  # m/s
    a, dt, n = np.array([0.3, 0.0, -0.4]), 0.3, 40  # m/s², s, steps
    end = fly(model(rk4=rk4), start, (*a, 0.0, 0.0, 0.0), dt, n)
    t = n * dt
    exact = np.array(start[7:10]) * t + 0.5 * a * t**2
    np.testing.assert_allclose(end[7:10], np.array(start[7:10]) + a * t, atol=1e-12)
    # Euler moves with the velocity at the start of each step: half a step behind
    lag = 0.0 if rk4 else 0.5 * t * dt
    np.testing.assert_allclose(end[0:3], exact - lag * a, atol=1e-9)
    assert end[13] == pytest.approx(t) and end[14] == pytest.approx(0.5 * t)  # time, Δv


@pytest.mark.parametrize(("rk4", "tolerance"), [(False, 2e-2), (True, 1e-8)])
def test_constant_torque_about_a_principal_axis_follows_the_closed_form(rk4, tolerance):
    tau, inertia, dt, n = 0.01, (0.1, 0.2, 0.3), 0.01, 1000  # N·m, kg·m², s, steps
    end = fly(model(rk4=rk4, inertia=inertia), list(REST), (0, 0, 0, 0, 0, tau), dt, n)
    t, alpha = n * dt, tau / inertia[2]
    np.testing.assert_allclose(end[10:13], [0.0, 0.0, alpha * t], atol=1e-12)
    angle = 0.5 * alpha * t**2
    expected = [0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2)]
    assert np.abs(end[3:7] - expected).max() < tolerance


def test_quaternion_stays_unit_while_tumbling():
    start = list(REST)
    start[10:13] = [1.5, -0.7, 2.0]  # rad/s
    x = start
    for _ in range(2000):
        x = model().step(x, (0.1, 0.2, 0.3, 0.01, -0.01, 0.005), 0.3)
        assert abs(math.fsum(q * q for q in x[3:7]) - 1.0) < 1e-12


def test_discrete_controls_floor_onto_the_sources_sets_evenly():
    rng = np.random.default_rng(0)
    pairs = [discrete_control(*u) for u in rng.uniform([0, 0], [3, 7], (21_000, 2))]
    counts = np.bincount([3 * j + i for i, j in pairs], minlength=21)
    assert counts.min() > 850 and counts.max() < 1150  # 1000 each
    assert discrete_control(3.0, 7.0) == (2, 6) and discrete_control(-0.1, 0.0) == (0, 0)


def test_discrete_force_pushes_along_the_body_z_axis():
    m = model(discrete=True)
    turned = np.array([math.sin(math.pi / 4), 0.0, 0.0, math.cos(math.pi / 4)])  # 90° about x
    ax, ay, az, tx, ty, tz = m.wrench((0.5, 4.5), tuple(turned))  # +f, +τ about z
    np.testing.assert_allclose([ax, ay, az], 0.5 * rotate(turned, [0, 0, 1]), atol=1e-15)
    assert (tx, ty, tz) == (0.0, 0.0, 0.01)
    assert m.wrench((2.5, 6.5), tuple(turned)) == (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


def small_problem(time_budget=5.0, obstacles=None):
    """A 12 m hop past a sphere in a tight box (fast dynamics: a few thousand steps)."""
    sphere = obstacle_track(1, (6.0, 0.0, 0.0), radius=2.0)
    return PathProblem(
        start=RobotState(time=0.0, position=[0.0, 0.0, 0.0]),
        goal=GoalRegion(position=[12.0, 0.0, 0.0], tolerance=1.5),
        obstacles=(sphere,) if obstacles is None else obstacles,
        robot_radius=0.5,
        max_speed=2.0,
        max_acceleration=0.5,
        bounds=Bounds(lower=[-2.0, -4.0, -4.0], upper=[14.0, 4.0, 4.0]),
        time_budget=time_budget,
    )


def upward_problem():
    """A 12 m climb along z beside a sphere: the source's thrust along the body z axis
    reaches it without turning."""
    sphere = obstacle_track(1, (3.0, 0.0, 6.0), radius=2.0)
    return dataclasses.replace(
        small_problem(obstacles=(sphere,)),
        goal=GoalRegion(position=[0.0, 0.0, 12.0], tolerance=1.5),
        bounds=Bounds(lower=[-4.0, -4.0, -2.0], upper=[4.0, 4.0, 14.0]),
    )


def plan(problem, seed=1, **params):
    return OmplControlPlanner(params or None, np.random.default_rng(seed)).plan(problem)


@pytest.mark.parametrize("planner", ["rrt", "est", "kpiece"])
def test_each_planner_flies_past_the_obstacle_by_propagation(planner):
    problem = small_problem()
    trajectory = plan(problem, planner=planner, connect_radius=0.0)
    assert isinstance(trajectory, Trajectory), trajectory
    assert problem.goal.contains(trajectory.end_state(problem.goal))
    assert not path_clearance(trajectory, problem).collides
    stats = trajectory.statistics
    assert stats["closing_attempts"] == 0 and stats["exact"] == 1
    assert stats["nodes_in_tree"] == stats["nodes_added"] + 1 >= stats["nodes_expanded"] >= 1
    if planner == "rrt":  # one node at most per RRT iteration
        assert stats["iterations"] >= stats["nodes_added"]
    # a step of the source's 0.3 s between samples, each with its force and torque
    np.testing.assert_allclose(np.diff(trajectory.times), 0.3, atol=1e-9)
    assert len(trajectory.forces) == len(trajectory.times) - 1


def test_same_seed_same_trajectory_within_one_process():
    problem = upward_problem()
    first = plan(problem, seed=3, connect_radius=0.0, controls="discrete")
    other = plan(problem, seed=4, connect_radius=0.0, controls="discrete")
    again = plan(problem, seed=3, connect_radius=0.0, controls="discrete")
    assert isinstance(first, Trajectory) and isinstance(other, Trajectory)
    assert problem.goal.contains(first.end_state(problem.goal))
    assert not path_clearance(first, problem).collides
    np.testing.assert_array_equal(first.positions, again.positions)
    assert first.statistics == again.statistics
    assert first.positions.shape != other.positions.shape or np.any(
        first.positions != other.positions
    )


def test_rk4_and_euler_plans_are_both_consistent_with_their_samples():
    problem = small_problem()
    for integrator in ("euler", "rk4"):
        trajectory = plan(problem, integrator=integrator, connect_radius=0.0)
        accelerations = np.diff(trajectory.velocities, axis=0) / np.diff(trajectory.times)[:, None]
        assert np.linalg.norm(accelerations, axis=1).max() <= 0.5 * (1 + 1e-9)


def test_the_closing_manoeuvre_arrives_at_rest_turned_on_time():
    goal = GoalRegion(
        position=[12.0, 0.0, 0.0],
        tolerance=1.5,
        time=40.0,
        attitude=[0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4)],
        attitude_tolerance=math.radians(1.0),
        velocity_tolerance=0.01,
        time_tolerance=0.5,
    )
    problem = dataclasses.replace(small_problem(), goal=goal, max_angular_acceleration=0.05)
    trajectory = plan(problem)
    assert isinstance(trajectory, Trajectory), trajectory
    assert goal.contains(trajectory.end_state(goal))
    assert not path_clearance(trajectory, problem).collides
    assert trajectory.statistics["closing_attempts"] >= 1


def test_the_budget_is_honoured_and_an_unreachable_goal_is_no_path():
    wall = tuple(
        obstacle_track(10 + i, c, radius=2.0)
        for i, c in enumerate(
            [(12 + dx, dy, dz) for dx, dy, dz in np.vstack([np.eye(3), -np.eye(3)]) * 3.2]
        )
    )
    problem = small_problem(time_budget=0.3, obstacles=wall)
    began = time.perf_counter()
    answer = plan(problem, controls="discrete")
    assert time.perf_counter() - began < 0.3 * 1.2 + 0.2
    assert isinstance(answer, NoPath) and "within the 0.3 s budget" in answer.reason


@pytest.fixture(scope="module")
def escape():
    return load_problem(str(ESCAPE)).problem


def test_the_asteroid_escape_is_solved_clear_of_every_asteroid(escape):
    trajectory = plan(dataclasses.replace(escape, time_budget=10.0), seed=0)
    assert isinstance(trajectory, Trajectory), trajectory
    assert escape.goal.contains(trajectory.end_state(escape.goal))
    assert not path_clearance(trajectory, escape).collides


def test_a_start_inside_an_asteroid_is_no_path(escape):
    inside = dataclasses.replace(escape.start, position=[1.22, -1.02, 8.09])  # asteroid 13
    answer = plan(dataclasses.replace(escape, start=inside))
    assert answer == NoPath(
        "the start is inside obstacle 13 (robot radius and safety margin included)"
    )


def test_parameters_hold_the_sources_values_by_default():
    params = OmplControlParams.parse("ompl-control", None)
    assert (params.step, params.integrator, params.planner) == (0.3, "euler", "rrt")
    weights = (params.position_weight, params.attitude_weight)
    assert weights + (params.velocity_weight, params.rate_weight) == (0.05, 5.0, 0.3, 0.5)


def test_moving_obstacles_are_checked_where_they_are_at_each_states_time():
    # a sphere crossing the way at 0.5 m/s, at the middle about when a direct flight passes
    crossing = obstacle_track(2, (6.0, -4.0, 0.0), velocity=(0.0, 0.5, 0.0), radius=1.0)
    problem = small_problem(obstacles=(crossing,))
    for connect_radius in (0.0, 50.0):
        trajectory = plan(problem, connect_radius=connect_radius)
        assert isinstance(trajectory, Trajectory), trajectory
        assert not path_clearance(trajectory, problem).collides


def draw(seed):
    """A number from OMPL's generator, seeded with ``seed`` (in a worker process)."""
    from ompl import util as ou

    seed_ompl(seed)
    return ou.RNG().uniform01()


FALLBACK = """
import time

from ompl import base as ob
from ompl import util as ou

from dcsim_plugins.path_planners.ompl.support import in_worker, seed_ompl


def draw(seed):
    seed_ompl(seed)
    return ou.RNG().uniform01()


if __name__ == "__main__":
    ob.RealVectorStateSpace(1).allocDefaultStateSampler()  # OMPL's generator now runs here
    print(*(in_worker(draw, (7,), time.monotonic() + 30) for _ in range(2)))
"""


def test_seeds_take_in_workers_even_when_ompl_already_runs_in_the_planning_process(tmp_path):
    script = tmp_path / "fallback.py"
    script.write_text(FALLBACK)
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert "Random number generation already started" in done.stderr  # the fork's seed failed
    first, second = map(float, done.stdout.split())
    assert first == second == in_worker(draw, (7,), time.monotonic() + 30)


def test_a_moment_of_inertia_must_be_positive():
    with pytest.raises(PluginParameterError, match="every principal moment must be positive"):
        OmplControlPlanner({"inertia": [0.1, 0.0, 0.1]}, np.random.default_rng(0))


def test_a_deadline_sooner_than_the_budget_is_the_budget_the_answer_quotes():
    wall = tuple(
        obstacle_track(10 + i, c, radius=2.0)
        for i, c in enumerate(
            [(12 + dx, dy, dz) for dx, dy, dz in np.vstack([np.eye(3), -np.eye(3)]) * 3.2]
        )
    )
    problem = dataclasses.replace(
        small_problem(time_budget=5.0, obstacles=wall), deadline=time.monotonic() + 0.3
    )
    answer = plan(problem, controls="discrete")
    assert isinstance(answer, NoPath)
    # The time left when the planner starts, a little under 0.3 s (less on a busy
    # machine), not the problem's 5 s time_budget.
    quoted = re.search(r"within the ([0-9.]+) s budget", answer.reason)
    assert quoted is not None and 0.2 < float(quoted.group(1)) <= 0.3, answer.reason
