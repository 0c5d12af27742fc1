"""``ga`` task planner: the source thesis's genetic algorithm for moving targets (chapter 3).

What it optimises
-----------------
The fuel of flying the plan. The collector flies straight constant-velocity legs from
its estimated state to each pickup and to the drop point, burning impulsively at every
node to match the velocity there (a target's at its pickup time, through the target's
motion model; the drop point's). The cost is the total delta-v of those burns plus
``time_weight`` times the plan's duration (:func:`dcsim.api.plan_cost`); without a
weight on time, flying ever slower would always be cheaper. ``Plan.cost`` is this cost,
m/s. A leg must last at least ``MIN_TIME_STEP`` and at least the rest-to-rest time of
its length at ``speed_fraction`` of the speed limit and the request's acceleration, so
every plan can be flown and its pickup times strictly increase.

How
---
An individual is a pickup order with a time for each pickup and the drop visits
between runs (at most MAX_CARRIED_OBJ = the request's capacity per run; runs may be
shorter where that is cheaper). The population has n(n−1) individuals for n targets;
fitness is the normalised inverse cost; parents are chosen by roulette; children come
from the thesis's greedy crossover (each next target taken from the parent for which
it is cheaper to reach, with the duration of the leg that reached it); swap mutation
exchanges two targets (MUTATION_PROBABILITY), and as often a drop-visit flag flips;
migration replaces a child by a fresh random individual (MIGRATION_PROBABILITY). The
best individual always survives. The search stops when the relative change of the best
cost stays below MAX_DIFERENTIAL for CONSECUTIVE_BESTS generations, after
MAX_ITERATIONS, or when the request's time budget runs out (the best so far is returned).

Time strategies (``time_strategy``, thesis §3.2.2)
    ``brute-force``: random leg durations; children inherit them; a time mutation
    (TIME_MUTATION_PROBABILITY) gives one leg a new random duration.
    ``minimum-distance``: every individual's times are recomputed by the
    minimum-distance search after every change — slow, as the thesis found.
    ``mixed`` (the thesis's choice, the default): the initial population and migrants
    are timed by the search; children inherit durations; a time mutation re-times the
    whole individual by the search.

The minimum-distance search times one leg at a time, in flying order: it takes the
arrival time that makes that leg cheapest (the thesis took the time of closest
approach, which says nothing for stationary targets; the leg's own cost is the
criterion the distance stood in for). A geometric grid of durations from MIN_TIME_STEP
to ``max_leg_time`` brackets the optimum; a parabola through the bracket and the
shortest feasible duration are tried as refinements (in place of the thesis's gradient
descent and MIN_GRAD).
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass
from typing import Literal

import numpy as np
from dcsim_plugins.task_planners.ga.population import (
    Evaluation,
    Population,
    evaluate,
    greedy_crossover,
    min_distance_times,
    neighbours,
    random_population,
    retime_one_leg,
    run_mutation,
    swap_mutation,
)
from dcsim_plugins.task_planners.ga.problem import PlanModel, TaskProblem

from dcsim.api import (
    DropVisit,
    Plan,
    PlanTask,
    PluginParams,
    TaskPlanner,
    TaskRequest,
    hookimpl,
    plan_cost,
    quantity,
)

TimeStrategy = Literal["brute-force", "minimum-distance", "mixed"]


class GeneticParams(PluginParams):
    """Parameters of :class:`GeneticTaskPlanner` (the thesis's names where it has one)."""

    time_strategy: TimeStrategy = quantity(
        "mixed", description="How pickup times are chosen: brute-force, minimum-distance or mixed."
    )
    POPULATION_SIZE: int = quantity(
        0, ge=0, description="Individuals per generation; 0 for n(n-1) with n targets (at least 4)."
    )
    MAX_ITERATIONS: int = quantity(500, ge=1, description="Most generations.")
    CONSECUTIVE_BESTS: int = quantity(
        20, ge=1, description="Convergent generations in a row that end the search."
    )
    MAX_DIFERENTIAL: float = quantity(
        1e-4,
        ge=0,
        description="Relative change of the best cost below which a generation is convergent.",
    )
    MUTATION_PROBABILITY: float = quantity(
        0.3, ge=0, le=1, description="Probability that a child has two targets swapped."
    )
    MIGRATION_PROBABILITY: float = quantity(
        0.05, ge=0, le=1, description="Probability that a child is replaced by a random one."
    )
    TIME_MUTATION_PROBABILITY: float = quantity(
        0.2, ge=0, le=1, description="Probability of a time mutation of a child."
    )
    MIN_TIME_STEP: float = quantity(
        1.0, unit="s", gt=0, description="Least time between two plan events."
    )
    local_search: bool = quantity(
        True,
        description="Replace the best individual by its best neighbour (swap, reversal, move, "
        "drop flip) each generation; false for the thesis's algorithm alone.",
    )
    time_weight: float = quantity(
        0.005, unit="(m/s)/s", ge=0, description="Price of plan duration in the cost."
    )
    speed_fraction: float = quantity(
        0.8, gt=0, le=1, description="Fraction of the speed limit a leg may fly at."
    )
    max_leg_time: float = quantity(
        600.0, unit="s", gt=0, description="Longest leg the time search and random times try."
    )
    horizon: float = quantity(
        7200.0, unit="s", gt=0, description="Latest plan event, after the request time."
    )
    time_resolution: float = quantity(
        1.0, unit="s", gt=0, description="Step of the table of target states the search reads."
    )


@dataclass(frozen=True)
class SearchStatistics:
    """How the last :meth:`GeneticTaskPlanner.plan` call went.

    Attributes
    ----------
    iterations : int
        Generations run.
    converged : bool
        True if the convergence test stopped the search (not the iteration cap or budget).
    best_costs : tuple of float
        Best cost after the initial population and after each generation, m/s.
    """

    iterations: int
    converged: bool
    best_costs: tuple[float, ...]


class GeneticTaskPlanner(TaskPlanner):
    """The thesis's genetic task planner; see the module documentation."""

    name = "ga"
    summary = "Genetic algorithm over pickup order, times and drop visits (thesis ch. 3)"
    Params = GeneticParams
    params: GeneticParams

    #: Statistics of the last plan, for benchmarks (None before the first).
    statistics: SearchStatistics | None = None

    def plan(self, request: TaskRequest) -> Plan:
        """Plan the request's targets; see the module documentation."""
        deadline = time.perf_counter() + request.time_budget
        problem = self._problem(request, list(request.targets))
        reachable = self._reachable(problem)
        if len(reachable) < problem.n:
            problem = self._problem(request, reachable)
        if problem.n == 0:
            self.statistics = SearchStatistics(0, True, ())
            return self._drop_only(request, problem)
        population = random_population(problem, self._size(problem.n), self.rng, self._timed())
        best = self._search(problem, population, deadline)
        return self._to_plan(request, problem, best)

    # ------------------------------------------------------------------ set-up
    def _problem(self, request: TaskRequest, targets: list) -> TaskProblem:
        p = self.params
        model = PlanModel(
            p.time_weight,
            p.MIN_TIME_STEP,
            p.speed_fraction,
            p.max_leg_time,
            p.horizon,
            p.time_resolution,
        )
        return TaskProblem(request, targets, model)

    def _reachable(self, problem: TaskProblem) -> list:
        """Targets with a feasible first leg from the collector's start."""
        count = problem.n
        start_p = np.broadcast_to(problem.start_position, (count, 3))
        start_v = np.broadcast_to(problem.start_velocity, (count, 3))
        t0 = np.full(count, problem.t0)
        objects = np.arange(count)
        arrival = problem.best_arrival(start_p, start_v, t0, objects)
        ok = problem.legs(start_p, start_v, t0, objects, arrival).violation <= 0
        return [t for t, good in zip(problem.targets, ok, strict=True) if good]

    def _size(self, n: int) -> int:
        return self.params.POPULATION_SIZE or max(n * (n - 1), 4)

    def _timed(self) -> bool:
        return self.params.time_strategy != "brute-force"

    # ------------------------------------------------------------------ search
    def _search(self, problem: TaskProblem, population: Population, deadline: float) -> Population:
        """Evolve ``population``; return the best individual (a population of one)."""
        p = self.params
        scores = evaluate(problem, population)
        best = population.take(np.array([np.argmin(scores.cost)]))
        history = [float(scores.cost.min())]
        calm, converged, iterations = 0, False, 0
        searching = p.local_search and problem.n >= 2
        elite_settled = False
        while iterations < p.MAX_ITERATIONS and not converged:
            started = time.perf_counter()
            population = self._generation(problem, population, scores, best)
            scores = evaluate(problem, population)
            if searching:
                population, scores, elite_settled = self._descend(
                    problem, population, scores, elite_settled
                )
            i = int(np.argmin(scores.cost))
            elite_settled = elite_settled and i == 0
            best = population.take(np.array([i]))
            history.append(float(scores.cost[i]))
            iterations += 1
            previous, current = history[-2], history[-1]
            change = abs(previous - current) / max(previous, current, 1e-12)
            calm = calm + 1 if change < p.MAX_DIFERENTIAL else 0
            converged = calm >= p.CONSECUTIVE_BESTS
            if time.perf_counter() + (time.perf_counter() - started) > deadline:
                break
        self.statistics = SearchStatistics(iterations, converged, tuple(history))
        return best

    def _generation(
        self, problem: TaskProblem, population: Population, scores: Evaluation, best: Population
    ) -> Population:
        """One generation: roulette, crossover, mutations, migration, the best kept."""
        p, rng = self.params, self.rng
        size = len(population)
        fitness = 1.0 / np.maximum(scores.cost, 1e-12)
        parents = rng.choice(size, size=(size, 2), p=fitness / fitness.sum())
        mothers, fathers = parents[:, 0], parents[:, 1]
        children = greedy_crossover(
            problem,
            population.take(mothers),
            population.take(fathers),
            scores.arrival_cost[mothers],
            scores.arrival_cost[fathers],
            rng,
        )
        children = swap_mutation(children, self._pick(size, p.MUTATION_PROBABILITY), rng)
        children = run_mutation(problem, children, self._pick(size, p.MUTATION_PROBABILITY), rng)
        migrants = self._pick(size, p.MIGRATION_PROBABILITY)
        if migrants.size:
            fresh = random_population(problem, migrants.size, rng, timed=False)
            children = children.put(migrants, fresh)
        children = self._time_mutation(problem, children, migrants)
        return children.put(np.array([0]), best)

    def _descend(
        self, problem: TaskProblem, population: Population, scores: Evaluation, elite_settled: bool
    ) -> tuple[Population, Evaluation, bool]:
        """One local-search step: on row 0 (the kept best), or on the best child once it settled.

        The individual is replaced by its best neighbour if that is cheaper. Returns the
        population, its scores, and whether row 0 is now known to be a local optimum.
        """
        row = 1 + int(np.argmin(scores.cost[1:])) if elite_settled else 0
        around = neighbours(problem, population.take(np.array([row])))
        around_scores = evaluate(problem, around)
        i = int(np.argmin(around_scores.cost))
        improved = around_scores.cost[i] < scores.cost[row]
        if improved:
            population = population.put(np.array([row]), around.take(np.array([i])))
            scores = scores.put(row, around_scores, i)
        return population, scores, elite_settled or not improved

    def _time_mutation(
        self, problem: TaskProblem, children: Population, migrants: np.ndarray
    ) -> Population:
        """Re-time children as the time strategy says (migrants are timed like the initial ones)."""
        strategy, rng = self.params.time_strategy, self.rng
        if strategy == "minimum-distance":
            return min_distance_times(problem, children)
        rows = self._pick(len(children), self.params.TIME_MUTATION_PROBABILITY)
        if strategy == "brute-force":
            return retime_one_leg(problem, children, rows, rng) if rows.size else children
        rows = np.union1d(rows, migrants)
        return min_distance_times(problem, children, rows) if rows.size else children

    def _pick(self, size: int, probability: float) -> np.ndarray:
        return np.flatnonzero(self.rng.random(size) < probability)

    # ------------------------------------------------------------------ output
    def _to_plan(self, request: TaskRequest, problem: TaskProblem, best: Population) -> Plan:
        times = best.pickup_times(problem.t0, problem.pre_drop)[0]
        tasks = []
        for target_index, pickup in zip(best.order[0], times, strict=True):
            track = problem.targets[target_index]
            point, velocity = track.predict(pickup)
            tasks.append(PlanTask(track.id, float(pickup), point, velocity))
        visits = []
        if problem.pre_drop:
            visits.append(self._visit(request, -1, problem.t0 + float(best.pre_gap[0])))
        for k in np.flatnonzero(best.drops[0]):
            visits.append(self._visit(request, int(k), float(times[k] + best.drop_gaps[0, k])))
        return self._costed(request, Plan(tuple(tasks), tuple(visits)))

    @staticmethod
    def _visit(request: TaskRequest, after_task: int, at: float) -> DropVisit:
        return DropVisit(after_task, at, request.drop_point.state_at(at)[0])

    def _drop_only(self, request: TaskRequest, problem: TaskProblem) -> Plan:
        """With no target to plan: a drop visit if anything is on board, else nothing."""
        if request.carried == 0:
            return Plan()
        arrival = problem.best_arrival(
            problem.start_position[None],
            problem.start_velocity[None],
            np.array([problem.t0]),
            np.array([problem.drop]),
        )
        return self._costed(
            request, Plan(drop_visits=(self._visit(request, -1, float(arrival[0])),))
        )

    def _costed(self, request: TaskRequest, plan: Plan) -> Plan:
        return dataclasses.replace(plan, cost=plan_cost(request, plan, self.params.time_weight))


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the genetic task planner."""
    return [GeneticTaskPlanner]
