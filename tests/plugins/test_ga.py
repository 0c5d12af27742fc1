"""The genetic task planner: operators, search control, capacity, and plans."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from dcsim_plugins.task_planners.ga.planner import GeneticTaskPlanner
from dcsim_plugins.task_planners.ga.population import (
    Population,
    evaluate,
    greedy_crossover,
    min_distance_times,
    random_population,
    repair_runs,
    swap_mutation,
)
from dcsim_plugins.task_planners.ga.problem import PlanModel, TaskProblem

from dcsim.api import (
    DropPoint,
    LinearMotion,
    ObjectKind,
    ObjectTrack,
    StateEstimate,
    StaticMotion,
    TaskRequest,
    plan_cost,
)
from dcsim.bench.optimal_plans import LegRules, optimal_static_plan
from dcsim.bench.task_planners import random_request

MODEL = PlanModel(
    time_weight=0.005,
    min_time_step=1.0,
    speed_fraction=0.8,
    max_leg_time=600.0,
    horizon=7200.0,
    resolution=1.0,
)


def track(target_id, position, velocity=(0.0, 0.0, 0.0)):
    return ObjectTrack(
        target_id,
        ObjectKind.TARGET,
        0.0,
        position,
        velocity,
        radius=0.3,
        motion=LinearMotion(position, velocity),
    )


def request(targets, capacity=2, carried=0, budget=1.0):
    return TaskRequest(
        time=0.0,
        robot=StateEstimate(time=0.0, position=[0.0, 0.0, 0.0], converged=True),
        targets=tuple(targets),
        drop_point=DropPoint(StaticMotion((-5.0, 0.0, 0.0)), tolerance=1.0),
        capacity=capacity,
        carried=carried,
        max_speed=0.5,
        max_acceleration=0.02,
        time_budget=budget,
    )


LINE = [track(i + 1, (10.0 * (i + 1), 0.0, 0.0)) for i in range(4)]


def problem(targets=LINE, capacity=2, carried=0):
    return TaskProblem(request(targets, capacity, carried), list(targets), MODEL)


def individuals(prob, orders, drops=None, gap=50.0):
    orders = np.array(orders)
    size, n = orders.shape
    flags = repair_runs(prob, np.zeros((size, n), bool) if drops is None else np.array(drops))
    return Population(
        orders, flags, np.full((size, n), gap), np.full((size, n), gap), np.full(size, gap)
    )


def planner(**params):
    return GeneticTaskPlanner(params, np.random.default_rng(0))


def is_valid(prob, pop):
    orders_ok = all(sorted(row) == list(range(prob.n)) for row in pop.order)
    return orders_ok and np.array_equal(repair_runs(prob, pop.drops), pop.drops)


# --------------------------------------------------------------------- operators


def test_greedy_crossover_builds_permutations_from_the_cheaper_parent_steps():
    prob = problem()
    rng = np.random.default_rng(1)
    mothers = min_distance_times(prob, individuals(prob, [[0, 1, 2, 3]] * 3))
    fathers = min_distance_times(prob, individuals(prob, [[3, 2, 1, 0]] * 3))
    children = greedy_crossover(
        prob,
        mothers,
        fathers,
        evaluate(prob, mothers).arrival_cost,
        evaluate(prob, fathers).arrival_cost,
        rng,
    )
    assert is_valid(prob, children)
    # Starting at the origin, the mother's first target (10 m away) is cheaper than the
    # father's (40 m); after it the father's next one is taken, so the child goes in order.
    np.testing.assert_array_equal(children.order, [[0, 1, 2, 3]] * 3)
    # Each pickup carries the duration of the leg that reached it in its parent.
    np.testing.assert_allclose(children.gaps[:, 0], mothers.gaps[:, 0])


def test_greedy_crossover_of_random_parents_always_gives_permutations():
    prob = problem([track(i, np.random.default_rng(i).uniform(-40, 40, 3)) for i in range(1, 9)])
    rng = np.random.default_rng(2)
    parents = random_population(prob, 60, rng, timed=True)
    costs = evaluate(prob, parents).arrival_cost
    half = np.arange(30)
    children = greedy_crossover(
        prob, parents.take(half), parents.take(half + 30), costs[half], costs[half + 30], rng
    )
    assert is_valid(prob, children)


def test_swap_mutation_exchanges_exactly_two_targets_and_keeps_times():
    prob = problem()
    pop = individuals(prob, [[0, 1, 2, 3]] * 4)
    mutated = swap_mutation(pop, np.array([1, 3]), np.random.default_rng(3))
    np.testing.assert_array_equal(mutated.order[[0, 2]], pop.order[[0, 2]])
    for row in (1, 3):
        changed = np.flatnonzero(mutated.order[row] != pop.order[row])
        assert len(changed) == 2
        assert sorted(mutated.order[row]) == [0, 1, 2, 3]
    np.testing.assert_array_equal(mutated.gaps, pop.gaps)


@pytest.mark.parametrize("moving", [False, True])
def test_time_mutation_lowers_or_keeps_the_cost(moving):
    req = random_request(np.random.default_rng(4), 6, moving)
    prob = TaskProblem(req, list(req.targets), MODEL)
    rng = np.random.default_rng(5)
    pop = random_population(prob, 40, rng, timed=False)
    before = evaluate(prob, pop).cost
    after = evaluate(prob, min_distance_times(prob, pop)).cost
    if moving:
        # Each leg is timed greedily from the one before, so a random timing can beat it
        # on a rare individual; almost all must improve and none be infeasible.
        assert np.mean(after <= before + 1e-9) >= 0.9
    else:
        assert np.all(after <= before + 1e-9)
    assert np.all(evaluate(prob, min_distance_times(prob, pop)).violation == 0)


def test_migrants_are_valid_feasible_individuals():
    req = random_request(np.random.default_rng(6), 7, True)
    prob = TaskProblem(req, list(req.targets), MODEL)
    fresh = random_population(prob, 50, np.random.default_rng(7), timed=True)
    assert is_valid(prob, fresh)
    assert len({tuple(row) for row in fresh.order}) > 40
    assert np.all(evaluate(prob, fresh).violation == 0)


def test_runs_are_repaired_to_the_capacity():
    prob = problem(capacity=2, carried=1)
    fixed = repair_runs(prob, np.zeros((1, 4), bool))
    # One already on board: the first run holds one pickup, then runs of two.
    np.testing.assert_array_equal(fixed, [[True, False, True, True]])


# --------------------------------------------------------------------- search control


def test_search_stops_when_the_best_cost_settles():
    ga = planner(MAX_DIFERENTIAL=1.0, CONSECUTIVE_BESTS=3)
    ga.plan(request(LINE))
    assert ga.statistics.converged
    assert ga.statistics.iterations == 3


def test_search_stops_at_max_iterations_without_convergence():
    ga = planner(MAX_DIFERENTIAL=0.0, MAX_ITERATIONS=5)
    ga.plan(request(LINE))
    assert not ga.statistics.converged
    assert ga.statistics.iterations == 5


def test_best_cost_never_rises_over_generations():
    ga = planner()
    ga.plan(random_request(np.random.default_rng(8), 9, True))
    costs = np.array(ga.statistics.best_costs)
    assert np.all(np.diff(costs) <= 1e-12)
    assert costs[-1] < costs[0]


# --------------------------------------------------------------------- plans


@pytest.mark.parametrize("strategy", ["brute-force", "minimum-distance", "mixed"])
def test_every_time_strategy_gives_a_viable_plan(strategy):
    req = random_request(np.random.default_rng(9), 7, True)
    ga = planner(time_strategy=strategy)
    plan = ga.plan(req)
    times = [t.pickup_time for t in plan.tasks]
    assert sorted(t.target_id for t in plan.tasks) == list(range(1, 8))
    assert times[0] >= req.time + 1.0
    assert np.all(np.diff(times) >= 1.0)
    for task in plan.tasks:
        truth = next(t for t in req.targets if t.id == task.target_id).predict(task.pickup_time)
        np.testing.assert_allclose(task.pickup_point, truth[0])
    # The search's own cost (states read from its interpolated table) is the public one.
    assert ga.statistics.best_costs[-1] == pytest.approx(plan_cost(req, plan, 0.005), rel=1e-6)


def test_capacity_bounds_every_run_and_each_run_ends_at_the_drop_point():
    req = random_request(np.random.default_rng(10), 8, False)
    req = dataclasses.replace(req, capacity=2)
    plan = planner().plan(req)
    ends = [-1] + [v.after_task for v in plan.drop_visits]
    assert ends[-1] == len(plan.tasks) - 1
    assert max(np.diff(ends)) <= 2
    for visit in plan.drop_visits:
        np.testing.assert_allclose(visit.point, req.drop_point.state_at(visit.time)[0])
        assert visit.time > plan.tasks[visit.after_task].pickup_time


def test_a_full_collector_first_flies_to_the_drop_point():
    plan = planner().plan(request(LINE, capacity=2, carried=2))
    assert plan.drop_visits[0].after_task == -1
    assert plan.drop_visits[0].time < plan.tasks[0].pickup_time


def test_cargo_and_no_target_gives_a_single_drop_visit():
    plan = planner().plan(request([], capacity=2, carried=1))
    assert plan.tasks == ()
    assert [v.after_task for v in plan.drop_visits] == [-1]


def test_unreachable_targets_are_left_out():
    runaway = track(9, (30.0, 0.0, 0.0), velocity=(2.0, 0.0, 0.0))  # faster than the collector
    plan = planner().plan(request([*LINE[:2], runaway]))
    assert sorted(t.target_id for t in plan.tasks) == [1, 2]


def test_stationary_plans_match_the_exact_optimum():
    rules = LegRules(0.005, 1.0, 0.8, 600.0)
    gaps = []
    for seed in range(5):
        req = random_request(np.random.default_rng(100 + seed), 7, False)
        best = optimal_static_plan(req, rules)
        gaps.append(planner().plan(req).cost / best.cost - 1.0)
    assert min(gaps) >= -1e-9
    assert np.median(gaps) <= 0.005
