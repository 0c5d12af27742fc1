"""The grid-astar path planner: the paper's neighbour sets and grid, A* against an
exhaustive search, swept against grid-point collision tests, and its time budget."""

from __future__ import annotations

import functools
import heapq
import itertools
import math
import re
import time
from dataclasses import dataclass

import numpy as np
import pytest
from dcsim_plugins.path_planners.grid_astar import (
    FOOT,
    GridAStarParams,
    GridAStarPlanner,
    GridSearch,
    GridSettings,
    neighbour_moves,
)
from dcsim_plugins.path_planners.relative_motion import BurnPlan

from dcsim.api import (
    Bounds,
    CostWeights,
    GoalRegion,
    NoPath,
    PathProblem,
    RobotState,
    Shape,
    ShapeKind,
    Trajectory,
    path_clearance,
)
from dcsim.testing.problems import enclosed_goal_problem, obstacle_track


def move_set(*args, **kwargs) -> set[tuple[tuple[int, int, int], int]]:
    """``neighbour_moves`` as a set of (offset, steps)."""
    offsets, steps = neighbour_moves(*args, **kwargs)
    return {(tuple(int(c) for c in o), int(s)) for o, s in zip(offsets, steps, strict=True)}


# ---------------------------------------------------------------- neighbour sets (§4)


def test_paper_first_neighbour_example_speeds_from_0_4_to_2_5():
    # d = t = 1, speeds 0.4 to 2.5, delta-v limits ignored.
    moves = move_set(1.0, 1.0, 0.4, 2.5, 10)
    assert ((1, 0, 0), 1) in moves  # speed 1
    assert ((1, 0, 0), 2) in moves  # speed 0.5
    assert ((2, 0, 0), 1) in moves  # speed 2 (first set: one step, any distance)
    assert ((1, 0, 0), 3) not in moves  # speed 1/3 < 0.4
    assert ((3, 0, 0), 1) not in moves  # speed 3 > 2.5
    # (2, 0, 0) is two spacings away: only the one-step set reaches it
    assert ((2, 0, 0), 2) not in moves
    for offset, steps in moves:
        speed = np.linalg.norm(offset) / steps
        assert 0.4 - 1e-12 <= speed <= 2.5 + 1e-12
        assert steps == 1 or np.linalg.norm(offset) < 2


def test_paper_second_neighbour_example_speeds_from_1_to_1_9():
    moves = move_set(1.0, 1.0, 1.0, 1.9, 10)
    cube = {o for o in itertools.product((-1, 0, 1), repeat=3) if o != (0, 0, 0)}
    assert moves == {(o, 1) for o in cube}
    assert len(moves) == 26


def test_longest_duration_drops_the_longer_moves():
    everything = move_set(1.0, 1.0, 0.3, 1.9, 4)
    assert max(s for _, s in everything) == 4
    capped = move_set(1.0, 1.0, 0.3, 1.9, 4, longest_duration=2.5)
    assert capped == {m for m in everything if m[1] <= 2}


# ---------------------------------------------------------------- grid settings (Table 2)


def speed_limited(max_speed: float, max_acceleration: float) -> PathProblem:
    return PathProblem(
        start=RobotState(time=0.0, position=[0.0, 0.0, 0.0]),
        goal=GoalRegion(position=[10.0, 0.0, 0.0]),
        max_speed=max_speed,
        max_acceleration=max_acceleration,
    )


@pytest.mark.parametrize("acceleration", [1.0, math.inf])
def test_derived_grid_at_the_paper_speed_limit_is_table_2(acceleration):
    grid = GridSettings.derive(GridAStarParams(), speed_limited(0.19 * FOOT, acceleration))
    assert FOOT == 0.3048
    assert grid.distance_resolution == pytest.approx(6 * FOOT, rel=1e-12)
    assert grid.time_resolution == pytest.approx(60.0, rel=1e-12)
    assert grid.min_speed == pytest.approx(0.09 * FOOT, rel=1e-12)
    assert grid.max_speed == pytest.approx(0.19 * FOOT, rel=1e-12)
    assert grid.max_burn == pytest.approx(0.2 * FOOT, rel=1e-12)


def test_derived_grid_grows_the_step_where_a_burn_would_not_fit():
    # The burn from rest onto the slowest one-step move (0.1 ft/s) takes 120 s at this
    # acceleration when it may take 45 %: the step doubles to 120 s, the spacing to 12 ft.
    v = 0.19 * FOOT
    slowest = v / 1.9
    acceleration = slowest / (0.45 * 120.0)
    grid = GridSettings.derive(GridAStarParams(), speed_limited(v, acceleration))
    assert grid.time_resolution == pytest.approx(120.0, rel=1e-12)
    assert grid.distance_resolution == pytest.approx(12 * FOOT, rel=1e-12)
    assert grid.max_burn == pytest.approx(0.5 * acceleration * 120.0, rel=1e-12)
    assert grid.max_burn < 0.2 * FOOT


# ---------------------------------------------------------------- A* against exhaustive search

# Inertial problems small enough to search exhaustively: d = t = 1, speeds 0.3 to 1.9,
# moves of up to 3 steps, burns of at most 1.2345 m/s, a box of 6 x 4 x 2 grid points,
# a few spheres; start and goal velocities that are not zero.
D, T, MIN_SPEED, MAX_SPEED, MAX_BURN, LEGS = 1.0, 1.0, 0.3, 1.9, 1.2345, 3
ROBOT_RADIUS = 0.2
LOWER, UPPER = np.array([-1.5, -1.5, -0.5]), np.array([4.5, 2.5, 1.5])
GOAL, GOAL_VELOCITY = np.array([4.0, 0.0, 0.0]), np.array([0.2, 0.0, 0.0])
CHECK_SPACING = 0.02
"""Swept samples at most 2 cm apart: the planner's robot sphere grows by at most 1 cm."""


@dataclass(frozen=True)
class SmallCase:
    """Spheres of radius 0.3 m at ``centres``, the start velocity and the cost weights."""

    centres: tuple[tuple[float, float, float], ...]
    start_velocity: tuple[float, float, float]
    weights: CostWeights
    radius: float = 0.3

    def problem(self) -> PathProblem:
        return PathProblem(
            start=RobotState(time=0.0, position=[0.0, 0.0, 0.0], velocity=self.start_velocity),
            goal=GoalRegion(position=GOAL, tolerance=0.1, velocity=GOAL_VELOCITY),
            obstacles=tuple(
                obstacle_track(i + 1, centre, radius=self.radius)
                for i, centre in enumerate(self.centres)
            ),
            robot_radius=ROBOT_RADIUS,
            max_speed=MAX_SPEED,
            bounds=Bounds(lower=LOWER, upper=UPPER),
            weights=self.weights,
            time_budget=20.0,
        )


CASES = {
    # a sphere on the direct line and two beside it: the plan climbs over or goes round
    "blocked-line": SmallCase(
        ((1.0, 0.0, 0.0), (2.0, 1.0, 0.0), (2.0, -1.0, 0.0), (3.0, 0.0, 1.0)),
        (0.0, 0.5, 0.0),
        CostWeights(delta_v=1.0, length=0.1, time=0.05),
    ),
    # drifting back and sideways at the start, two spheres in the goal's row
    "drifting-start": SmallCase(
        ((3.0, 2.0, 0.0), (2.0, -1.0, 0.0), (3.0, -1.0, 1.0), (2.0, 0.0, 0.0)),
        (0.55, 0.54, 0.0),
        CostWeights(delta_v=1.0, length=0.1, time=0.2),
    ),
}


def small_params(heuristic: str) -> GridAStarParams:
    return GridAStarParams(
        distance_resolution=D,
        time_resolution=T,
        min_speed=MIN_SPEED,
        max_burn=MAX_BURN,
        max_leg_steps=LEGS,
        heuristic=heuristic,
        check_spacing=CHECK_SPACING,
    )


def segment_gaps(case: SmallCase, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """Least distance between the robot's surface and a sphere's along each straight
    segment (m,) m: the exact distance from the segment to each centre, less both radii."""
    starts, ends = np.atleast_2d(starts), np.atleast_2d(ends)
    along = ends - starts
    lengths = np.maximum(np.einsum("ij,ij->i", along, along), 1e-300)
    gaps = np.full(len(starts), np.inf)
    for centre in case.centres:
        share = np.clip(np.einsum("ij,ij->i", np.asarray(centre) - starts, along) / lengths, 0, 1)
        nearest = starts + share[:, None] * along
        gap = np.linalg.norm(nearest - centre, axis=1) - case.radius - ROBOT_RADIUS
        gaps = np.minimum(gaps, gap)
    return gaps


def exhaustive_optimum(case: SmallCase) -> tuple[float, list[float], list[float]]:
    """The cheapest path of the grid by Dijkstra's algorithm over (grid point, incoming
    velocity), written from the planner's rules but not its code.

    In an inertial frame an arc is the straight segment flown at ``offset d / Δt``; a
    move is allowed when its end lies in the box, its segment clears every sphere and
    the burn onto it is within the limit; it costs ``w_dv |burn| + w_L |offset| d +
    w_T Δt``. From every state the goal's centre is tried after 1 to ``LEGS`` steps
    when it is nearer than 2 d (else after one step) at no more than the speed limit,
    with a burn onto that segment and one onto the goal's velocity, both within the
    limit. Obstacles rest and the goal has no time, so time is no part of a state.

    Returns
    -------
    cost : float
        The optimum.
    gaps : list of float
        Clearance of every segment tried, m (to check none grazes a sphere).
    burns : list of float
        Every burn compared with the limit, m/s (to check none sits on it).
    """
    offsets, steps = neighbour_moves(D, T, MIN_SPEED, MAX_SPEED, LEGS)
    velocities = offsets * D / (steps[:, None] * T)
    w = case.weights
    move_costs = w.length * np.linalg.norm(offsets, axis=1) * D + w.time * steps * T
    gaps: list[float] = []
    burns_seen: list[float] = []
    allowed: dict[tuple[int, ...], np.ndarray] = {}

    def moves_from(cell: tuple[int, ...]) -> np.ndarray:
        if cell not in allowed:
            here = np.array(cell, dtype=float) * D
            ends = here + offsets * D
            inside = np.all((ends > LOWER) & (ends < UPPER), axis=1)
            clearance = segment_gaps(case, np.broadcast_to(here, ends.shape), ends)
            gaps.extend(clearance[inside])
            allowed[cell] = inside & (clearance > 0)
        return allowed[cell]

    settled = set()
    queue = [(0.0, 0, ((0, 0, 0), -1))]
    counter = itertools.count(1)
    best: dict[tuple, float] = {}
    while queue:
        cost, _, node = heapq.heappop(queue)
        if node == "goal":
            return cost, gaps, burns_seen
        if node in settled:
            continue
        settled.add(node)
        cell, move = node
        velocity = np.asarray(case.start_velocity) if move < 0 else velocities[move]
        burns = np.linalg.norm(velocities - velocity, axis=1)
        usable = moves_from(cell)
        burns_seen.extend(burns[usable])
        for k in np.flatnonzero(usable & (burns <= MAX_BURN)):
            child = (tuple(int(c) for c in np.add(cell, offsets[k])), int(k))
            total = cost + w.delta_v * burns[k] + move_costs[k]
            if total < best.get(child, math.inf):
                best[child] = total
                heapq.heappush(queue, (total, next(counter), child))
        here = np.array(cell, dtype=float) * D
        distance = float(np.linalg.norm(GOAL - here))
        spans = T * np.arange(1, LEGS + 1) if distance < 2 * D else [T]
        for span in spans:
            if distance > MAX_SPEED * span * (1 + 1e-9):
                continue
            onto = (GOAL - here) / span
            first = float(np.linalg.norm(onto - velocity))
            last = float(np.linalg.norm(GOAL_VELOCITY - onto))
            burns_seen += [first, last]
            gap = float(segment_gaps(case, here, GOAL)[0])
            gaps.append(gap)
            if first <= MAX_BURN and last <= MAX_BURN and gap > 0:
                total = cost + w.delta_v * (first + last) + w.length * distance + w.time * span
                heapq.heappush(queue, (total, next(counter), "goal"))
    return math.inf, gaps, burns_seen


@functools.cache
def optimum(name: str) -> float:
    cost, gaps, burns = exhaustive_optimum(CASES[name])
    # The comparison is fair only if no segment grazes a sphere within the planner's
    # swept margin (half the 2 cm sample spacing) and no burn sits on the limit.
    assert np.min(np.abs(gaps)) > CHECK_SPACING
    assert np.min(np.abs(np.array(burns) - MAX_BURN)) > 1e-6
    assert math.isfinite(cost)
    return cost


@functools.cache
def search(name: str, heuristic: str) -> tuple[GridSearch, BurnPlan, float]:
    """The planner's search of a small problem, its plan, and the plan's cost recomputed
    from its burns, chords and duration."""
    grid = GridSearch(CASES[name].problem(), small_params(heuristic))
    plan = grid.run(time.monotonic() + 20.0)
    assert not isinstance(plan, NoPath), plan
    np.testing.assert_allclose(plan.positions[0], [0.0, 0.0, 0.0])
    np.testing.assert_allclose(plan.positions[-1], GOAL)
    np.testing.assert_allclose(plan.start_velocity, CASES[name].start_velocity)
    np.testing.assert_allclose(plan.goal_velocity, GOAL_VELOCITY)
    w = CASES[name].weights
    chords = np.linalg.norm(np.diff(plan.positions, axis=0), axis=1).sum()
    cost = w.delta_v * plan.delta_v + w.length * chords + w.time * (plan.times[-1] - plan.times[0])
    return grid, plan, float(cost)


@pytest.mark.parametrize("name", CASES)
def test_lower_bound_heuristic_finds_the_exhaustive_optimum(name):
    grid, plan, cost = search(name, "lower-bound")
    assert cost == pytest.approx(optimum(name), rel=1e-9)
    # the search's own account (the cheapest arrival it made) agrees with the plan
    arrived = min(s.cost for s in grid.states if s.goal)
    assert arrived == pytest.approx(cost, rel=1e-9)
    # not a trivial problem: the spheres force a plan of several legs
    assert len(plan.times) >= 4


@pytest.mark.parametrize("name", CASES)
def test_two_burn_heuristic_is_never_cheaper_than_the_optimum(name):
    _, _, cost = search(name, "two-burn")
    assert cost >= optimum(name) * (1 - 1e-9)
    print(f"{name}: two-burn plan cost / optimum = {cost / optimum(name):.6f}")


def test_planner_answer_follows_the_search():
    case = CASES["blocked-line"]
    answer = GridAStarPlanner(small_params("lower-bound")).plan(case.problem())
    assert isinstance(answer, Trajectory)
    grid, _, _ = search("blocked-line", "lower-bound")
    assert answer.statistics["points_searched"] == grid.statistics.points_searched
    np.testing.assert_allclose(answer.positions[0], [0.0, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(answer.velocities[0], case.start_velocity, atol=1e-12)
    np.testing.assert_allclose(answer.positions[-1], GOAL, atol=1e-9)
    np.testing.assert_allclose(answer.velocities[-1], GOAL_VELOCITY, atol=1e-12)
    assert not path_clearance(answer, case.problem()).collides


# ---------------------------------------------------------------- swept against grid points


def walled_problem() -> PathProblem:
    """A 10 cm wall across x = 0.5 m, 3 m wide and tall, between the grid points (0, 0, 0)
    and (1, 0, 0), both 35 cm clear of it; the goal two points on. The box keeps the
    robot in the plane z = 0 and lets it round the wall at y = ±2 m."""
    wall = Shape(ShapeKind.BOX, half_extents=(0.05, 1.5, 1.5))
    return PathProblem(
        start=RobotState(time=0.0, position=[0.0, 0.0, 0.0]),
        goal=GoalRegion(position=[2.0, 0.0, 0.0], tolerance=0.1),
        obstacles=(obstacle_track(1, (0.5, 0.0, 0.0), shape=wall),),
        robot_radius=0.1,
        max_speed=1.9,
        bounds=Bounds(lower=[-1.5, -2.5, -0.5], upper=[3.5, 2.5, 0.5]),
        time_budget=10.0,
    )


def walled_params(collision: str) -> GridAStarParams:
    return GridAStarParams(
        distance_resolution=1.0,
        time_resolution=1.0,
        min_speed=0.3,
        max_burn=1.5,
        max_leg_steps=3,
        collision=collision,
    )


def test_grid_point_checks_let_an_arc_cross_a_thin_wall():
    problem = walled_problem()
    answer = GridAStarPlanner(walled_params("grid-points")).plan(problem)
    assert isinstance(answer, Trajectory)
    clearance = path_clearance(answer, problem)
    assert clearance.collides and clearance.obstacle_id == 1
    assert abs(clearance.position[0] - 0.5) < 0.2  # it hits the wall, between the points


def test_swept_checks_go_round_the_thin_wall():
    problem = walled_problem()
    answer = GridAStarPlanner(walled_params("swept")).plan(problem)
    assert isinstance(answer, Trajectory)
    assert not path_clearance(answer, problem).collides
    assert np.abs(answer.positions[:, 1]).max() >= 2.0 - 1e-9  # round the wall's end
    np.testing.assert_allclose(answer.positions[-1], [2.0, 0.0, 0.0], atol=1e-9)


# ---------------------------------------------------------------- time budget


def test_short_time_budget_ends_the_search_with_no_path():
    budget = 0.2
    problem = enclosed_goal_problem(time_budget=budget)
    began = time.monotonic()
    answer = GridAStarPlanner().plan(problem)
    elapsed = time.monotonic() - began
    assert isinstance(answer, NoPath)
    found = re.fullmatch(
        r"no path within the time budget \((\d+) points searched, (\d+) open\)", answer.reason
    )
    assert found, answer.reason
    assert int(found[1]) >= 1 and int(found[2]) >= 1
    # one expansion (about 20 ms here) may run past the deadline, not half a second
    assert elapsed < budget + 0.5
