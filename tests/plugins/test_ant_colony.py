"""The ant-colony path planner: the paper's equations on a small instance, blocked
segments, convergence, the effect of δ, moving obstacles and the conformance suite."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from dcsim_plugins.path_planners.ant_colony.colony import (
    descend,
    lay_pheromone,
    solve_colony,
    transition_probabilities,
    transition_weights,
    visibility,
    walk,
)
from dcsim_plugins.path_planners.ant_colony.layered_graph import (
    LayeredGraph,
    build_graph,
    segment_gaps,
)
from dcsim_plugins.path_planners.ant_colony.planner import AntColonyParams, AntColonyPlanner

from dcsim.api import (
    GoalRegion,
    NoPath,
    PathProblem,
    PluginRegistry,
    RobotState,
    Shape,
    ShapeKind,
    Trajectory,
    path_clearance,
    surface_distance,
)
from dcsim.bench.layered_optimum import layered_optimum
from dcsim.testing import checks_for
from dcsim.testing.problems import held_still, obstacle_track

PAPER = {"visibility": "length", "local_search": False, "deposit_by": "all", "pheromone_floor": 0}
"""The settings that make the colony the paper's."""


def problem(*obstacles, goal=(4.0, 0.0, 0.0), **changes) -> PathProblem:
    """A transfer along +x from the origin (the line cross-sections then lie along y),
    with a safety margin of 0.05 m."""
    base = PathProblem(
        start=RobotState(time=0.0, position=[0.0, 0.0, 0.0]),
        goal=GoalRegion(position=goal, tolerance=0.2),
        obstacles=obstacles,
        robot_radius=0.5,
        max_speed=0.5,
        max_acceleration=0.05,
        time_budget=2.0,
        safety_margin=0.05,
    )
    return dataclasses.replace(base, **changes)


# A 4 m transfer cut into 4 parts: three cross-sections (x = 1, 2, 3) of three points
# (y = -1, 0, 1), and a sphere of radius 1 at (2, 5, 0), clear of every segment; no margin.
SMALL = {"parts": 4, "points": 1, "half_width": 1.0, "delta": 2.0}
FAR_SPHERE = obstacle_track(1, (2.0, 5.0, 0.0), radius=1.0)


@pytest.fixture(scope="module")
def small() -> tuple[LayeredGraph, AntColonyParams]:
    params = AntColonyParams(**SMALL, **PAPER)
    return build_graph(problem(FAR_SPHERE, safety_margin=0.0), params), params


def hand_clearance(x: float, y: float) -> float:
    """Eq. 7 less the robot radius: from (x, y, 0) to the sphere at (2, 5, 0), m."""
    return math.hypot(x - 2.0, y - 5.0) - 1.0 - 0.5


def test_the_cross_sections_and_eq_7_clearances(small):
    graph, _ = small
    assert graph.points.shape == (5, 3, 3)
    assert graph.step == pytest.approx(1.0) and graph.spacing == pytest.approx(1.0)
    for i in (1, 2, 3):
        np.testing.assert_allclose(graph.points[i], [[i, -1, 0], [i, 0, 0], [i, 1, 0]])
        expected = [hand_clearance(i, y) for y in (-1, 0, 1)]
        np.testing.assert_allclose(graph.clearance[i], expected)
        np.testing.assert_allclose(graph.node_cost[i], [2.0 / d for d in expected])
    assert np.isinf(graph.node_cost[0, 1:]).all() and graph.node_cost[0, 0] == 0.0


def test_eq_6_length_and_eq_8_objective(small):
    graph, _ = small
    path = np.array([[0, 2, 1, 0, 0]])  # start, y = 1, 0, -1, goal
    length = math.sqrt(1 + 1**2) + math.sqrt(1 + 1**2) + math.sqrt(1 + 1**2) + math.sqrt(1 + 1)
    assert graph.path_lengths(path)[0] == pytest.approx(length)
    safety = 1 / hand_clearance(1, 1) + 1 / hand_clearance(2, 0) + 1 / hand_clearance(3, -1)
    assert graph.costs(path)[0] == pytest.approx(length + 2.0 * safety)
    straight = np.array([[0, 1, 1, 1, 0]])
    assert graph.path_lengths(straight)[0] == pytest.approx(4.0)


def test_eq_11_transition_probabilities(small):
    graph, _ = small
    tau = np.full(graph.lengths.shape, 1.0)
    tau[1, 1, 2] = 3.0  # more pheromone from (x=1, y=0) to (x=2, y=1)
    weights = transition_weights(tau, visibility(graph, 5.0, "length"), 1.0)
    p = transition_probabilities(weights)
    diagonal = math.sqrt(2.0) ** -5
    row = np.array([diagonal, 1.0, 3.0 * diagonal])
    np.testing.assert_allclose(p[1, 1], row / row.sum())
    # the visibility that sees the objective: 1 / (d_pq + δ / d_min of q)
    steps = np.array([math.sqrt(2.0), 1.0, math.sqrt(2.0)])
    steps += [2.0 / hand_clearance(2, y) for y in (-1, 0, 1)]
    row = steps**-5 * [1.0, 1.0, 3.0]
    weights = transition_weights(tau, visibility(graph, 5.0, "objective"), 1.0)
    np.testing.assert_allclose(transition_probabilities(weights)[1, 1], row / row.sum())
    # α weighs the pheromone
    weights = transition_weights(tau, visibility(graph, 5.0, "length"), 2.0)
    row = np.array([diagonal, 1.0, 9.0 * diagonal])
    np.testing.assert_allclose(transition_probabilities(weights)[1, 1], row / row.sum())
    # padding nodes of the start and the goal layers are never reached
    assert (p[0, 0, 1:] > 0).all() and p[0, 0, 0] > 0 and (p[0, 1:] == 0).all()
    assert (p[3, :, 1:] == 0).all()


def test_eqs_12_13_pheromone_update_by_hand():
    tau = np.full((2, 2, 2), 4.0)
    paths = np.array([[0, 1, 0], [0, 1, 0], [0, 0, 0]])
    costs = np.array([10.0, 20.0, 40.0])
    updated = lay_pheromone(tau, paths, costs, persistence=0.5, deposit=8.0)
    expected = np.full((2, 2, 2), 2.0)
    expected[0, 0, 1] += 8 / 10 + 8 / 20  # ants 1 and 2 went 0 -> 1
    expected[1, 1, 0] += 8 / 10 + 8 / 20  # then 1 -> 0
    expected[0, 0, 0] += 8 / 40  # ant 3 stayed on node 0
    expected[1, 0, 0] += 8 / 40
    np.testing.assert_allclose(updated, expected)


def test_one_cycle_of_the_paper_colony(small):
    graph, params = small
    params = params.model_copy(update={"max_cycles": 1, "initial_pheromone": 2.0, "ants": 7})
    result = solve_colony(graph, params, np.random.default_rng(5))
    # the same draws give the same ants' paths (Steps 2-3)
    weights = transition_weights(
        np.full(graph.lengths.shape, 2.0), visibility(graph, 5.0, "length"), 1
    )
    paths = walk(weights, np.random.default_rng(5).random((4, 7)))
    expected = np.full(graph.lengths.shape, 0.526 * 2.0)
    for path in paths:
        f = graph.costs(path[None])[0]
        for i in range(4):
            expected[i, path[i], path[i + 1]] += 320.0 / f
    np.testing.assert_allclose(result.pheromone, expected)
    assert result.cycles == 1 and result.cost == pytest.approx(graph.costs(paths).min())
    assert len(result.history) == 1 and result.stop in ("max cycles", "one path")


def test_the_roulette_follows_eq_11(small):
    graph, _ = small
    weights = transition_weights(np.ones(graph.lengths.shape), visibility(graph, 1.0, "length"), 1)
    draws = np.random.default_rng(0).random((4, 40_000))
    paths = walk(weights, draws)
    first = np.bincount(paths[:, 1], minlength=3) / len(paths)
    np.testing.assert_allclose(first, transition_probabilities(weights)[0, 0], atol=0.01)


def blocked_problem() -> PathProblem:
    """The small transfer with a sphere of 0.3 m between the cross-sections x = 1 and 2,
    for a robot of 0.1 m: every point is clear, some segments are not."""
    return problem(
        obstacle_track(1, (1.5, 0.0, 0.0), radius=0.3), robot_radius=0.1, safety_margin=0.0
    )


def test_blocked_segments_have_infinite_length_and_are_never_chosen():
    params = AntColonyParams(**SMALL, **PAPER)
    graph = build_graph(blocked_problem(), params)
    assert np.isfinite(graph.node_cost[1:4]).all()
    # (1, 0) -> (2, 0) runs through the centre; (1, -1) -> (2, 0) passes 0.354 m from it,
    # within 0.3 + 0.1; (1, -1) -> (2, -1) passes 1 m away
    assert np.isinf(graph.lengths[1, 1, 1]) and np.isinf(graph.lengths[1, 0, 1])
    assert graph.lengths[1, 0, 0] == pytest.approx(1.0)
    weights = transition_weights(
        np.ones(graph.lengths.shape), visibility(graph, 5.0, "length"), 1.0
    )
    paths = walk(weights, np.random.default_rng(1).random((4, 20_000)))
    assert np.isfinite(graph.path_lengths(paths)).all()
    result = solve_colony(graph, params, np.random.default_rng(2))
    assert math.isfinite(result.cost)


def test_segment_gaps_of_a_turned_box_are_a_close_lower_bound():
    box = Shape(
        ShapeKind.BOX, half_extents=(1.0, 0.5, 0.3), orientation=(0, 0, 0.3826834, 0.9238795)
    )
    track = obstacle_track(1, (0.0, 0.0, 0.0), shape=box)
    rng = np.random.default_rng(3)
    first, last = rng.uniform(-3, 3, (200, 3)), rng.uniform(-3, 3, (200, 3))
    gaps = segment_gaps(track, first, last, reach=10.0, spacing=0.02)
    fractions = np.linspace(0, 1, 2001)[:, None, None]
    points = (first + fractions * (last - first)).reshape(-1, 3)
    true = surface_distance(box, np.zeros_like(points), points).reshape(2001, 200).min(axis=0)
    assert (gaps <= true + 1e-9).all()
    assert (gaps >= true - 0.02).all()


def small_graph(lengths: np.ndarray) -> LayeredGraph:
    """A graph of the given segment lengths, no node terms (m layers of P nodes)."""
    m, count, _ = lengths.shape
    node_cost = np.zeros((m + 1, count))
    node_cost[0, 1:] = node_cost[m, 1:] = np.inf
    return LayeredGraph(
        points=np.zeros((m + 1, count, 3)),
        times=np.zeros(m + 1),
        clearance=np.full((m + 1, count), np.inf),
        node_cost=node_cost,
        lengths=lengths,
        step=1.0,
        spacing=1.0,
    )


def test_the_colony_stops_when_every_ant_takes_one_path():
    lengths = np.full((3, 2, 2), np.inf)
    lengths[0, 0, 1] = lengths[1, 1, 0] = lengths[2, 0, 0] = 1.0  # a single path
    params = AntColonyParams(**PAPER)
    result = solve_colony(small_graph(lengths), params, np.random.default_rng(0))
    assert result.stop == "one path" and result.converged and result.cycles == 1
    np.testing.assert_array_equal(result.path, [0, 1, 0, 0])
    assert result.cost == pytest.approx(3.0)


def test_the_colony_stops_when_its_best_stalls():
    lengths = np.ones((3, 2, 2))  # every path is as short as any other
    lengths[0, 1] = lengths[2, :, 1] = np.inf
    params = AntColonyParams(stall_cycles=4, pheromone_floor=1.0)
    result = solve_colony(small_graph(lengths), params, np.random.default_rng(0))
    assert result.stop == "stalled" and result.converged
    assert result.cycles == 5  # the best of cycle 1 is never beaten
    np.testing.assert_allclose(result.history, 3.0)


def test_the_local_search_never_raises_the_objective(small):
    graph, _ = small
    rng = np.random.default_rng(4)
    paths = np.zeros((50, 5), dtype=int)
    paths[:, 1:4] = rng.integers(0, 3, (50, 3))
    improved = descend(graph, paths)
    assert (graph.costs(improved) <= graph.costs(paths) + 1e-12).all()
    optimum = layered_optimum(graph.lengths, graph.node_cost).cost
    assert graph.costs(improved).min() == pytest.approx(optimum)


def test_a_larger_delta_keeps_further_from_an_obstacle():
    layout = problem(obstacle_track(1, (5.0, 0.4, 0.0), radius=1.0), goal=(10.0, 0.0, 0.0))
    layout = dataclasses.replace(layout, robot_radius=0.3)
    closest = []
    for delta in (0.01, 0.1, 1.0):
        planner = AntColonyPlanner({"delta": delta, "half_width": 3.0}, np.random.default_rng(0))
        trajectory = planner.plan(layout)
        assert isinstance(trajectory, Trajectory), trajectory
        closest.append(path_clearance(trajectory, layout).distance)
    assert closest[0] < closest[1] < closest[2]
    assert closest[0] > 0


def crossing_layout() -> PathProblem:
    """A 20 m transfer across the way of a sphere that reaches the straight line when
    the robot would."""
    crossing = obstacle_track(1, (10.0, -2.9, 0.0), velocity=(0.0, 0.1, 0.0), radius=1.0)
    return dataclasses.replace(problem(crossing, goal=(20.0, 0.0, 0.0)), robot_radius=0.3)


def test_points_are_judged_where_obstacles_are_when_their_layer_is_crossed():
    layout = crossing_layout()
    params = AntColonyParams(delta=0.05)
    graph = build_graph(layout, params)
    # nominal flight: 0.4 m/s after an 8 s ramp at 0.05 m/s^2; layer 20 is at x = 10 m
    assert graph.times[20] == pytest.approx(8.0 + (10.0 - 1.6) / 0.4)
    centre = np.array([10.0, -2.9 + 0.1 * graph.times[20], 0.0])
    expected = np.linalg.norm(graph.points[20] - centre, axis=1) - 1.0 - 0.3 - 0.05
    np.testing.assert_allclose(graph.clearance[20], expected)


def test_a_moving_obstacle_is_avoided_where_it_will_be():
    layout = crossing_layout()
    planner = AntColonyPlanner({"delta": 0.05}, np.random.default_rng(0))
    trajectory = planner.plan(layout)
    assert isinstance(trajectory, Trajectory), trajectory
    assert path_clearance(trajectory, layout).distance > 0
    # planned as if the obstacle stood still, the straight path would meet it
    still = planner.plan(held_still(layout))
    assert isinstance(still, Trajectory)
    assert path_clearance(still, layout).collides


def test_a_goal_time_is_met_exactly_or_refused():
    layout = problem(FAR_SPHERE, goal=(10.0, 0.0, 0.0))
    timed = dataclasses.replace(layout.goal, time=60.0, time_tolerance=0.5, velocity_tolerance=0.01)
    trajectory = AntColonyPlanner(None, np.random.default_rng(0)).plan(
        dataclasses.replace(layout, goal=timed)
    )
    assert isinstance(trajectory, Trajectory), trajectory
    assert trajectory.times[-1] == pytest.approx(60.0, abs=0.5)
    assert np.abs(trajectory.velocities[-1]).max() < 1e-9
    rushed = dataclasses.replace(timed, time=15.0)
    answer = AntColonyPlanner(None, np.random.default_rng(0)).plan(
        dataclasses.replace(layout, goal=rushed)
    )
    assert isinstance(answer, NoPath) and "goal's time" in answer.reason


def test_the_trajectory_keeps_the_limits():
    layout = problem(obstacle_track(1, (5.0, 0.2, 0.0), radius=1.0), goal=(10.0, 0.0, 0.0))
    trajectory = AntColonyPlanner(None, np.random.default_rng(0)).plan(layout)
    assert isinstance(trajectory, Trajectory), trajectory
    speeds = np.linalg.norm(trajectory.velocities, axis=1)
    assert speeds.max() <= layout.max_speed * (1 + 1e-9)
    rates = np.linalg.norm(np.diff(trajectory.velocities, axis=0), axis=1) / np.diff(
        trajectory.times
    )
    assert rates.max() <= layout.max_acceleration * (1 + 1e-6)
    assert set(trajectory.statistics) >= {"cycles", "ants", "best_cost", "converged"}


def test_the_bench_scores_the_planner_through_its_own_graph_and_colony():
    planner_class = PluginRegistry.discover().get("path_planner", "ant-colony").cls
    layout = blocked_problem()
    planner = planner_class(SMALL, np.random.default_rng(7))
    graph = planner.candidate_graph(layout)
    expected = build_graph(layout, AntColonyParams(**SMALL))
    np.testing.assert_array_equal(graph.lengths, expected.lengths)
    np.testing.assert_array_equal(graph.node_cost, expected.node_cost)
    result = planner.colony(graph)
    again = solve_colony(graph, AntColonyParams(**SMALL), np.random.default_rng(7))
    np.testing.assert_array_equal(result.history, again.history)
    assert result.cost >= layered_optimum(graph.lengths, graph.node_cost).cost - 1e-9
    assert np.all(np.diff(result.history) <= 0)


def test_it_is_a_registered_path_planner_with_checks():
    assert AntColonyPlanner.name == "ant-colony"
    assert {c.name for c in checks_for("path_planner")} >= {"reaches_the_goal", "collision_free"}
