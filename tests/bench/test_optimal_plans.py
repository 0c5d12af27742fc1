"""Exact task-plan solvers against exhaustive search on tiny instances."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from dcsim.api import (
    DropPoint,
    DropVisit,
    LinearMotion,
    ObjectKind,
    ObjectTrack,
    Plan,
    PlanTask,
    StateEstimate,
    StaticMotion,
    TaskRequest,
    leg_delta_v,
    plan_cost,
)
from dcsim.bench.optimal_plans import LegRules, optimal_grid_plan, optimal_static_plan

RULES = LegRules(time_weight=0.005, min_time_step=1.0, speed_fraction=0.8, max_leg_time=600.0)


def make_request(positions, velocities=None, capacity=2, drop=(-3.0, 1.0, 0.0), accel=0.02):
    velocities = np.zeros_like(positions) if velocities is None else velocities
    tracks = tuple(
        ObjectTrack(i + 1, ObjectKind.TARGET, 0.0, p, v, radius=0.3, motion=LinearMotion(p, v))
        for i, (p, v) in enumerate(zip(positions, velocities, strict=True))
    )
    return TaskRequest(
        time=0.0,
        robot=StateEstimate(time=0.0, position=[0.0, 0.0, 0.0], converged=True),
        targets=tracks,
        drop_point=DropPoint(StaticMotion(drop), tolerance=1.0),
        capacity=capacity,
        max_speed=0.5,
        max_acceleration=accel,
    )


def layouts(n, capacity):
    """Every drop-flag pattern whose runs fit the capacity (always a drop after the last)."""
    for flags in itertools.product([False, True], repeat=n - 1):
        flags = (*flags, True)
        run, ok = 0, True
        for f in flags:
            run += 1
            ok &= run <= capacity
            run = 0 if f else run
        if ok:
            yield flags


def node_sequence(order, flags):
    """Per node after the start: the target's index, or None for a drop visit."""
    nodes = []
    for target, drop_after in zip(order, flags, strict=True):
        nodes.append(target)
        if drop_after:
            nodes.append(None)
    return nodes


def as_plan(request, order, flags, times):
    tasks, visits, k = [], [], 0
    for index, (target, drop_after) in enumerate(zip(order, flags, strict=True)):
        track = request.targets[target]
        point, velocity = track.predict(times[k])
        tasks.append(PlanTask(track.id, float(times[k]), point, velocity))
        k += 1
        if drop_after:
            visits.append(
                DropVisit(index, float(times[k]), request.drop_point.state_at(times[k])[0])
            )
            k += 1
    return Plan(tuple(tasks), tuple(visits))


def test_static_optimum_equals_exhaustive_search_with_scanned_leg_times():
    rng = np.random.default_rng(0)
    request = make_request(rng.uniform(-30, 30, (4, 3)))
    durations = np.geomspace(1.0, 600.0, 20_000)
    points = [t.position for t in request.targets] + [request.drop_point.state_at(0.0)[0]]

    def best_leg(a, b):
        d = np.linalg.norm(b - a)
        ok = durations >= RULES.min_duration(request, d)
        cost = leg_delta_v(a, np.zeros(3), b, np.zeros(3), durations) + 0.005 * durations
        return np.min(cost[ok])

    best = np.inf
    for order in itertools.permutations(range(4)):
        for flags in layouts(4, 2):
            here, total = np.zeros(3), 0.0
            for node in node_sequence(order, flags):
                there = points[4] if node is None else points[node]
                total += best_leg(here, there)
                here = there
            best = min(best, total)
    assert optimal_static_plan(request, RULES).cost == pytest.approx(best, rel=1e-4)


def test_grid_optimum_equals_exhaustive_search_over_the_grid():
    rng = np.random.default_rng(1)
    request = make_request(rng.uniform(-4, 4, (3, 3)), rng.normal(0, 0.02, (3, 3)), accel=0.1)
    step, horizon = 12.5, 150.0
    grid = step * np.arange(1, int(horizon / step) + 1)
    best = np.inf
    for order in itertools.permutations(range(3)):
        for flags in layouts(3, 2):
            count = len(node_sequence(order, flags))
            for times in itertools.combinations(grid, count):
                plan = as_plan(request, order, flags, np.array(times))
                if _feasible(request, plan):
                    best = min(best, plan_cost(request, plan, RULES.time_weight))
    assert np.isfinite(best)
    assert optimal_grid_plan(request, RULES, step, horizon).cost == pytest.approx(best, rel=1e-12)


def _feasible(request, plan):
    from dcsim.yardsticks.plan_cost import plan_nodes

    times, positions, _ = plan_nodes(request, plan)
    distance = np.linalg.norm(np.diff(positions, axis=0), axis=1)
    duration = np.diff(times)
    return bool(
        np.all(duration >= RULES.min_duration(request, distance))
        and np.all(duration <= RULES.max_leg_time)
    )


def test_static_solver_refuses_moving_targets():
    request = make_request(np.ones((2, 3)), np.full((2, 3), 0.01))
    with pytest.raises(ValueError, match="stationary"):
        optimal_static_plan(request, RULES)
