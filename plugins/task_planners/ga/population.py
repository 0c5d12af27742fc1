"""Individuals of the ``ga`` planner and the genetic operators on them (vectorised).

An individual (thesis appendix A.2, ``Individual``) is

- ``order``: the targets in pickup order (a permutation of ``0 … n−1``);
- ``drops``: whether the collector flies to the drop point after each pickup (always
  after the last; a run never exceeds the capacity, MAX_CARRIED_OBJ);
- ``gaps``: the duration of the leg that ends at each pickup, s;
- ``drop_gaps``: the duration of the leg from each pickup to the drop point, s (used
  where ``drops``);
- ``pre_gap``: the duration of the leg to the drop point before the first pickup, s
  (used when the collector starts full).

Times follow from the durations, so pickup times always increase by at least
``MIN_TIME_STEP``. A :class:`Population` holds many individuals as arrays with one row
per individual, and every operator works on all rows at once.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from dcsim_plugins.task_planners.ga.problem import TaskProblem


@dataclass(frozen=True)
class Population:
    """Individuals as row-aligned arrays (see the module documentation).

    Attributes
    ----------
    order : ndarray of int (P, n)
    drops : ndarray of bool (P, n)
    gaps, drop_gaps : ndarray (P, n), s
    pre_gap : ndarray (P,), s
    """

    order: np.ndarray
    drops: np.ndarray
    gaps: np.ndarray
    drop_gaps: np.ndarray
    pre_gap: np.ndarray

    def __len__(self) -> int:
        return len(self.order)

    def take(self, rows: np.ndarray) -> Population:
        """The individuals at ``rows`` (copies)."""
        return Population(*(np.array(a[rows]) for a in self._arrays()))

    def put(self, rows: np.ndarray, other: Population) -> Population:
        """A copy with the individuals at ``rows`` replaced by ``other``'s."""
        arrays = []
        for mine, theirs in zip(self._arrays(), other._arrays(), strict=True):
            merged = np.array(mine)
            merged[rows] = theirs
            arrays.append(merged)
        return Population(*arrays)

    def _arrays(self) -> tuple[np.ndarray, ...]:
        return self.order, self.drops, self.gaps, self.drop_gaps, self.pre_gap

    def pickup_times(self, t0: float, pre_drop: bool) -> np.ndarray:
        """Pickup times (P, n), s, for a request at ``t0`` (``pre_drop``: starts full)."""
        drop_time = np.where(self.drops, self.drop_gaps, 0.0)
        before = np.cumsum(drop_time, axis=1) - drop_time
        start = t0 + (self.pre_gap[:, None] if pre_drop else 0.0)
        return start + np.cumsum(self.gaps, axis=1) + before


@dataclass(frozen=True)
class Evaluation:
    """Costs of a population.

    Attributes
    ----------
    cost : ndarray (P,)
        Penalised plan cost, m/s (the plan cost when feasible).
    violation : ndarray (P,)
        Total leg-time shortfall, s (0 for a feasible plan).
    arrival_cost : ndarray (P, n)
        Cost of getting to each pickup from the previous one (through any drop visit
        between them), m/s: the thesis's per-chromosome ``cost``.
    """

    cost: np.ndarray
    violation: np.ndarray
    arrival_cost: np.ndarray

    def put(self, row: int, other: Evaluation, other_row: int) -> Evaluation:
        """A copy with row ``row`` replaced by ``other``'s row ``other_row``."""
        arrays = []
        for mine, theirs in zip(
            (self.cost, self.violation, self.arrival_cost),
            (other.cost, other.violation, other.arrival_cost),
            strict=True,
        ):
            merged = np.array(mine)
            merged[row] = theirs[other_row]
            arrays.append(merged)
        return Evaluation(*arrays)


def evaluate(problem: TaskProblem, population: Population) -> Evaluation:
    """Cost every individual of ``population`` on ``problem`` (one pass, no loop over rows)."""
    pop = population
    size = len(pop)
    t_pick = pop.pickup_times(problem.t0, problem.pre_drop)
    t_drop = t_pick + pop.drop_gaps
    drop_obj = np.full(pop.order.shape, problem.drop)
    drop_p, drop_v = problem.state(drop_obj, t_drop)
    pick_p, pick_v = problem.state(pop.order, t_pick)

    first_p = np.broadcast_to(problem.start_position, (size, 3))
    first_v = np.broadcast_to(problem.start_velocity, (size, 3))
    first_t = np.full(size, problem.t0)
    pre_cost = np.zeros(size)
    pre_violation = np.zeros(size)
    if problem.pre_drop:
        pre = problem.legs(first_p, first_v, first_t, drop_obj[:, 0], first_t + pop.pre_gap)
        pre_cost, pre_violation = pre.penalised(), pre.violation
        first_p, first_v, first_t = pre.position, pre.velocity, first_t + pop.pre_gap

    after_drop = pop.drops[:, :-1, None]
    prev_p = np.concatenate(
        [first_p[:, None], np.where(after_drop, drop_p[:, :-1], pick_p[:, :-1])], 1
    )
    prev_v = np.concatenate(
        [first_v[:, None], np.where(after_drop, drop_v[:, :-1], pick_v[:, :-1])], 1
    )
    prev_t = np.concatenate(
        [first_t[:, None], np.where(pop.drops[:, :-1], t_drop[:, :-1], t_pick[:, :-1])], 1
    )
    pickups = problem.legs(prev_p, prev_v, prev_t, pop.order, t_pick)
    drops = problem.legs(pick_p, pick_v, t_pick, drop_obj, t_drop)
    drop_cost = np.where(pop.drops, drops.penalised(), 0.0)
    arrival = pickups.penalised() + np.concatenate([pre_cost[:, None], drop_cost[:, :-1]], axis=1)
    violation = (
        pre_violation
        + pickups.violation.sum(axis=1)
        + np.where(pop.drops, drops.violation, 0.0).sum(axis=1)
    )
    return Evaluation(arrival.sum(axis=1) + drop_cost[:, -1], violation, arrival)


# --------------------------------------------------------------------- layout


def repair_runs(problem: TaskProblem, drops: np.ndarray) -> np.ndarray:
    """Drop flags made valid: a drop visit whenever a run reaches capacity, and after the last.

    Parameters
    ----------
    drops : ndarray of bool (P, n)
        Requested drop visits (kept where valid).

    Returns
    -------
    ndarray of bool (P, n)
    """
    fixed = np.array(drops, dtype=bool)
    load = np.full(len(fixed), problem.first_load)
    for k in range(fixed.shape[1]):
        load += 1
        fixed[:, k] |= load >= problem.capacity
        load = np.where(fixed[:, k], 0, load)
    fixed[:, -1] = True
    return fixed


# --------------------------------------------------------------------- times


def min_distance_times(
    problem: TaskProblem,
    population: Population,
    rows: np.ndarray | None = None,
    start: np.ndarray | None = None,
) -> Population:
    """Time mutation: the legs of the chosen individuals re-timed by the cheapest arrival.

    Legs are re-timed in flying order, each from the newly timed node before it, so the
    result is the minimum-distance timing of the individual's order and drop visits.

    Parameters
    ----------
    rows : ndarray of int, optional
        Individuals to re-time (all if omitted).
    start : ndarray of int, optional
        Per chosen individual, the first pickup position to re-time; the legs before it
        keep their durations (all re-timed if omitted).
    """
    rows = np.arange(len(population)) if rows is None else rows
    sub = population.take(rows)
    size = len(sub)
    start = np.zeros(size, dtype=int) if start is None else start
    p = np.broadcast_to(problem.start_position, (size, 3))
    v = np.broadcast_to(problem.start_velocity, (size, 3))
    t = np.full(size, problem.t0)
    drop_obj = np.full(size, problem.drop)
    if problem.pre_drop:
        sub.pre_gap[:] = _retimed(problem, p, v, t, drop_obj, sub.pre_gap, start <= 0) - t
        p, v = problem.state(drop_obj, t + sub.pre_gap)
        t = t + sub.pre_gap
    for k in range(sub.order.shape[1]):
        active = start <= k
        arrival = _retimed(problem, p, v, t, sub.order[:, k], sub.gaps[:, k], active)
        sub.gaps[:, k] = arrival - t
        p, v = problem.state(sub.order[:, k], arrival)
        t = arrival
        going = sub.drops[:, k]
        at_drop = _retimed(problem, p, v, t, drop_obj, sub.drop_gaps[:, k], active & going)
        sub.drop_gaps[:, k] = np.where(going, at_drop - t, sub.drop_gaps[:, k])
        drop_p, drop_v = problem.state(drop_obj, at_drop)
        p = np.where(going[:, None], drop_p, p)
        v = np.where(going[:, None], drop_v, v)
        t = np.where(going, at_drop, t)
    return population.put(rows, sub)


def _retimed(
    problem: TaskProblem,
    p: np.ndarray,
    v: np.ndarray,
    t: np.ndarray,
    obj: np.ndarray,
    gap: np.ndarray,
    search: np.ndarray,
) -> np.ndarray:
    """Arrival times: the cheapest where ``search``, after the kept ``gap`` elsewhere."""
    arrival = t + gap
    if search.any():
        arrival[search] = problem.best_arrival(p[search], v[search], t[search], obj[search])
    return arrival


def random_gaps(
    problem: TaskProblem, rng: np.random.Generator, shape: tuple[int, ...]
) -> np.ndarray:
    """Leg durations drawn log-uniformly between MIN_TIME_STEP and ``max_leg_time``, s."""
    low, high = np.log(problem.model.min_time_step), np.log(problem.model.max_leg_time)
    return np.exp(rng.uniform(low, high, shape))


def random_population(
    problem: TaskProblem, size: int, rng: np.random.Generator, timed: bool
) -> Population:
    """Individuals with random orders and random drop visits.

    Parameters
    ----------
    timed : bool
        True to time them by the minimum-distance search, False for random times
        (the brute-force strategy).
    """
    n = problem.n
    order = rng.permuted(np.tile(np.arange(n), (size, 1)), axis=1)
    drops = repair_runs(problem, rng.random((size, n)) < 0.5 / max(problem.capacity, 1))
    population = Population(
        order,
        drops,
        random_gaps(problem, rng, (size, n)),
        random_gaps(problem, rng, (size, n)),
        random_gaps(problem, rng, (size,)),
    )
    return min_distance_times(problem, population) if timed else population


def retime_one_leg(
    problem: TaskProblem, population: Population, rows: np.ndarray, rng: np.random.Generator
) -> Population:
    """Brute-force time mutation: one random leg of each chosen individual is re-drawn."""
    sub = population.take(rows)
    k = rng.integers(0, problem.n, len(rows))
    at_drop = sub.drops[np.arange(len(rows)), k] & (rng.random(len(rows)) < 0.5)
    fresh = random_gaps(problem, rng, (len(rows),))
    index = np.arange(len(rows))
    sub.gaps[index[~at_drop], k[~at_drop]] = fresh[~at_drop]
    sub.drop_gaps[index[at_drop], k[at_drop]] = fresh[at_drop]
    return population.put(rows, sub)


# --------------------------------------------------------------------- reproduction


def _by_target(values: np.ndarray, order: np.ndarray) -> np.ndarray:
    """Re-index per-position values (P, n) by target: ``out[p, order[p, k]] = values[p, k]``."""
    out = np.empty_like(values)
    np.put_along_axis(out, order, values, axis=1)
    return out


def _successors(order: np.ndarray) -> np.ndarray:
    """``succ[p, j]``: the target after ``j`` in individual ``p``'s order (−1 for the last)."""
    following = np.concatenate([order[:, 1:], np.full((len(order), 1), -1)], axis=1)
    return _by_target(following, order)


def greedy_crossover(
    problem: TaskProblem,
    mothers: Population,
    fathers: Population,
    mother_costs: np.ndarray,
    father_costs: np.ndarray,
    rng: np.random.Generator,
) -> Population:
    """The thesis's greedy crossover, one child per mother–father pair.

    The child starts with whichever parent's first target is cheaper to reach; after each
    target it takes whichever parent's next target (after that same target in the
    parent's order) is cheaper to reach, if not already taken — a random remaining target
    when both are. Each target carries the duration of the leg that reached it in the
    parent it came from; drop visits follow the mother's (valid: they depend on
    positions only).

    Parameters
    ----------
    mother_costs, father_costs : ndarray (P, n)
        The parents' per-pickup arrival costs (:attr:`Evaluation.arrival_cost`).
    """
    size, n = mothers.order.shape
    rows = np.arange(size)
    parents = (mothers, fathers)
    succ = [_successors(p.order) for p in parents]
    cost = [
        _by_target(c, p.order) for c, p in zip((mother_costs, father_costs), parents, strict=True)
    ]
    gap = [_by_target(p.gaps, p.order) for p in parents]
    taken = np.zeros((size, n), dtype=bool)
    order = np.empty((size, n), dtype=int)
    gaps = np.empty((size, n))
    options = [mothers.order[:, 0], fathers.order[:, 0]]
    for k in range(n):
        choice_cost = []
        for side in (0, 1):
            candidate = options[side]
            valid = candidate >= 0
            safe = np.where(valid, candidate, 0)
            free = valid & ~taken[rows, safe]
            choice_cost.append(np.where(free, cost[side][rows, safe], np.inf))
        use_father = choice_cost[1] < choice_cost[0]
        chosen = np.where(use_father, options[1], options[0])
        source = use_father.astype(int)
        stuck = ~np.isfinite(np.minimum(choice_cost[0], choice_cost[1]))
        if stuck.any():
            keys = np.where(taken[stuck], -1.0, rng.random((int(stuck.sum()), n)))
            chosen[stuck] = np.argmax(keys, axis=1)
            source[stuck] = 0
        order[:, k] = chosen
        gaps[:, k] = np.where(source == 1, gap[1][rows, chosen], gap[0][rows, chosen])
        taken[rows, chosen] = True
        options = [succ[0][rows, chosen], succ[1][rows, chosen]]
    return Population(
        order,
        np.array(mothers.drops),
        gaps,
        np.array(mothers.drop_gaps),
        np.array(mothers.pre_gap),
    )


def swap_mutation(population: Population, rows: np.ndarray, rng: np.random.Generator) -> Population:
    """Order mutation: two random positions of each chosen individual swap targets.

    The legs' durations stay with the positions (the thesis's "time is unmodified").
    """
    n = population.order.shape[1]
    if n < 2 or rows.size == 0:
        return population
    order = np.array(population.order)
    first = rng.integers(0, n, rows.size)
    second = (first + rng.integers(1, n, rows.size)) % n
    order[rows, first], order[rows, second] = order[rows, second], order[rows, first]
    return replace(population, order=order)


def run_mutation(
    problem: TaskProblem, population: Population, rows: np.ndarray, rng: np.random.Generator
) -> Population:
    """Layout mutation: one random drop-visit flag (not the last) of each chosen individual flips.

    Lets runs be shorter than the capacity where that is cheaper; flags are then repaired
    so that no run exceeds the capacity.
    """
    n = population.order.shape[1]
    if n < 2 or rows.size == 0:
        return population
    drops = np.array(population.drops)
    k = rng.integers(0, n - 1, rows.size)
    drops[rows, k] = ~drops[rows, k]
    return replace(population, drops=repair_runs(problem, drops))


# --------------------------------------------------------------------- local search


def neighbours(problem: TaskProblem, individual: Population) -> Population:
    """Every individual one move away from ``individual`` (a population of one), re-timed.

    Moves: swap two targets, reverse a stretch of the order, move one target elsewhere,
    flip one drop-visit flag (repaired for capacity). Each neighbour is timed by the
    minimum-distance search.
    """
    n = problem.n
    base = individual.order[0]
    i, j = np.triu_indices(n, k=1)
    positions = np.arange(n)
    swaps = np.tile(base, (len(i), 1))
    swaps[np.arange(len(i)), i], swaps[np.arange(len(i)), j] = base[j], base[i]
    inside = (positions >= i[:, None]) & (positions <= j[:, None])
    reversals = base[np.where(inside, i[:, None] + j[:, None] - positions, positions)]
    src, dst = np.nonzero(~np.eye(n, dtype=bool))
    a, b = src[:, None], dst[:, None]
    shifted = positions + np.where(a < b, 1, -1) * ((positions - a) * (positions - b) <= 0)
    moves = base[np.where(positions == b, a, shifted)]
    orders = np.concatenate([swaps, reversals, moves])
    starts = np.concatenate([i, i, np.minimum(src, dst)])
    flips = np.tile(individual.drops[0], (max(n - 1, 0), 1))
    flips[np.arange(n - 1), np.arange(n - 1)] ^= True
    orders = np.concatenate([orders, np.tile(base, (n - 1, 1))])
    starts = np.concatenate([starts, np.arange(n - 1)])
    drops = np.concatenate([np.tile(individual.drops[0], (len(orders) - (n - 1), 1)), flips])
    count = len(orders)
    candidates = Population(
        orders,
        repair_runs(problem, drops),
        np.tile(individual.gaps[0], (count, 1)),
        np.tile(individual.drop_gaps[0], (count, 1)),
        np.repeat(individual.pre_gap, count),
    )
    return min_distance_times(problem, candidates, start=starts)
