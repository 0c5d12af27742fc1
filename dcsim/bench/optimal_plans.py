"""Exact task plans for benchmarking task planners: Held–Karp dynamic programming.

Both solvers plan every target of a request under the plan model of the ``ga`` planner
(and of :func:`dcsim.api.plan_cost`): straight constant-velocity legs with impulsive
burns matching each node's velocity, cost = delta-v + ``time_weight`` × duration, runs of
at most ``capacity`` pickups each ending with a drop visit (the collector starts with
nothing on board), and a leg feasible when its duration lies between
``min_time_step`` (and the rest-to-rest time of its length) and ``max_leg_time``.

- :func:`optimal_static_plan`: stationary targets and drop point, a collector at rest.
  Every leg then costs ``2 d / T + w T`` on its own, so each leg's best duration is
  known in closed form and dynamic programming over (visited subset, last target, load)
  is exact.
- :func:`optimal_grid_plan`: moving targets, every node time on the grid
  ``t0 + k * time_step``. The same dynamic programming with the node time in the
  state gives the optimum over that grid (an upper bound on the continuous optimum).

Cost is exponential in the number of targets (2^n subsets); both are meant for n ≤ 11.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from dcsim.api import (
    DropVisit,
    Plan,
    PlanTask,
    TaskRequest,
    leg_delta_v,
    plan_cost,
    shortest_leg,
)


@dataclass(frozen=True)
class LegRules:
    """The plan model's settings (see the module documentation).

    Attributes
    ----------
    time_weight : float
        Price of plan time, (m/s)/s (positive for the static solver).
    min_time_step : float
        Least leg duration, s.
    speed_fraction : float
        Fraction of the request's speed limit a leg may fly at.
    max_leg_time : float
        Longest leg, s.
    """

    time_weight: float
    min_time_step: float
    speed_fraction: float
    max_leg_time: float

    def min_duration(self, request: TaskRequest, distance: np.ndarray) -> np.ndarray:
        """Shortest feasible leg over ``distance`` m, s."""
        speed = self.speed_fraction * request.max_speed
        return shortest_leg(distance, speed, request.max_acceleration, self.min_time_step)


@dataclass
class _Route:
    """A solved visiting sequence: targets in order, drop flags, leg arrival times."""

    order: list[int]
    drop_after: list[bool]
    pickup_times: list[float]
    drop_times: list[float]


# --------------------------------------------------------------------- static


def optimal_static_plan(request: TaskRequest, rules: LegRules) -> Plan:
    """The cheapest plan for stationary targets (exact).

    Parameters
    ----------
    request : TaskRequest
        Targets and drop point must not move; the collector must be at rest and carry
        nothing.
    rules : LegRules
        The plan model's settings.

    Returns
    -------
    Plan
        The optimal plan, its ``cost`` by :func:`dcsim.api.plan_cost`.
    """
    n = len(request.targets)
    t0 = request.time
    states = [track.predict(t0) for track in request.targets]
    points = np.array([p for p, _ in states])
    speeds = np.array([v for _, v in states])
    if np.any(speeds) or np.any(request.robot.velocity) or request.carried:
        raise ValueError(
            "optimal_static_plan needs stationary targets, a collector at rest and nothing on board"
        )
    drop = request.drop_point.state_at(t0)[0]
    nodes = np.vstack([points, drop, request.robot.position])  # targets, drop n, start n+1
    distance = np.linalg.norm(nodes[:, None] - nodes[None], axis=-1)
    lowest = rules.min_duration(request, distance)
    free = np.sqrt(2.0 * distance / rules.time_weight)
    duration = np.clip(free, lowest, rules.max_leg_time)
    cost = 2.0 * distance / duration + rules.time_weight * duration
    cost[lowest > rules.max_leg_time] = np.inf
    order, drops = _held_karp(cost, n, request.capacity)
    times, drop_times, t, here = [], [], t0, n + 1
    for target, drop_after in zip(order, drops, strict=True):
        t += duration[here, target]
        times.append(t)
        here = target
        if drop_after:
            t += duration[here, n]
            drop_times.append(t)
            here = n
        else:
            drop_times.append(np.nan)
    return _plan(request, rules, _Route(order, drops, times, drop_times))


def _held_karp(cost: np.ndarray, n: int, capacity: int) -> tuple[list[int], list[bool]]:
    """Cheapest order and drop flags over leg costs ``cost`` (nodes: targets, drop n, start n+1)."""
    full = (1 << n) - 1
    loads = capacity + 1
    value = np.full((1 << n, n, loads), np.inf)
    parent = np.full((1 << n, n, loads, 3), -1)  # previous target, previous load, via drop
    direct, via = cost[:n, :n], cost[:n, n][:, None] + cost[n, :n][None, :]
    for m in range(n):
        value[1 << m, m, 1] = cost[n + 1, m]
    for mask in range(1, full + 1):
        here = value[mask]  # (n, loads)
        if not np.isfinite(here).any():
            continue
        outside = [m for m in range(n) if not mask & (1 << m)]
        for m in outside:
            nxt = mask | (1 << m)
            # straight on (load + 1) for loads below capacity
            step = here[:, :capacity] + direct[:, m][:, None]  # (n, capacity)
            best_j = np.argmin(step, axis=0)
            best = step[best_j, np.arange(capacity)]
            better = best < value[nxt, m, 1:]
            value[nxt, m, 1:][better] = best[better]
            parent[nxt, m, 1:][better] = np.stack(
                [best_j[better], np.flatnonzero(better), np.zeros(better.sum(), int)], axis=1
            )
            # through the drop point (load back to 1)
            through = here + via[:, m][:, None]
            j, load = np.unravel_index(np.argmin(through), through.shape)
            if through[j, load] < value[nxt, m, 1]:
                value[nxt, m, 1] = through[j, load]
                parent[nxt, m, 1] = (j, load, 1)
    final = value[full] + cost[:n, n][:, None]
    j, load = np.unravel_index(np.argmin(final), final.shape)
    if not np.isfinite(final[j, load]):
        raise ValueError("no feasible plan visits every target")
    order, drops, mask, after_drop = [], [], full, True
    while j >= 0:
        order.append(int(j))
        drops.append(after_drop)
        pj, pload, through = parent[mask, j, load]
        mask &= ~(1 << int(j))
        j, load, after_drop = pj, pload, bool(through)
    return order[::-1], drops[::-1]


# --------------------------------------------------------------------- moving


def optimal_grid_plan(
    request: TaskRequest, rules: LegRules, time_step: float, horizon: float
) -> Plan:
    """The cheapest plan with every node time on a grid (exact over the grid).

    Parameters
    ----------
    request : TaskRequest
        Targets may move; the collector must carry nothing.
    rules : LegRules
        The plan model's settings.
    time_step : float
        Grid step, s.
    horizon : float
        Latest node time after the request, s.

    Returns
    -------
    Plan
        The grid-optimal plan, its ``cost`` by :func:`dcsim.api.plan_cost`.
    """
    if request.carried:
        raise ValueError("optimal_grid_plan needs a collector with nothing on board")
    n = len(request.targets)
    t0 = request.time
    grid = t0 + time_step * np.arange(1, int(horizon / time_step) + 1)
    states = [track.predict(grid) for track in request.targets]
    drop_p, drop_v = request.drop_point.state_at(grid)
    states.append(
        (np.broadcast_to(drop_p, grid.shape + (3,)), np.broadcast_to(drop_v, grid.shape + (3,)))
    )
    position = np.stack([p for p, _ in states])  # (n + 1, G, 3)
    velocity = np.stack([v for _, v in states])
    legs = _grid_legs(request, rules, position, velocity, grid)  # (n+1, G, n+1, G)
    start_p = np.broadcast_to(request.robot.position, position.shape)
    start_v = np.broadcast_to(request.robot.velocity, position.shape)
    first = _leg(request, rules, start_p, start_v, t0, position, velocity, grid)  # (n+1, G)
    route = _grid_dp(legs, first, n, request.capacity)
    order, drops, pick_k, drop_k = route
    pickup_times = [float(grid[k]) for k in pick_k]
    drop_times = [float(grid[k]) if k >= 0 else np.nan for k in drop_k]
    return _plan(request, rules, _Route(order, drops, pickup_times, drop_times))


def _leg(request, rules, p_from, v_from, t_from, p_to, v_to, t_to) -> np.ndarray:
    """Cost of legs (broadcast), inf where infeasible."""
    duration = t_to - t_from
    ok = duration > 0
    safe = np.where(ok, duration, 1.0)
    distance = np.linalg.norm(p_to - p_from, axis=-1)
    cost = leg_delta_v(p_from, v_from, p_to, v_to, safe) + rules.time_weight * safe
    feasible = ok & (safe >= rules.min_duration(request, distance)) & (safe <= rules.max_leg_time)
    return np.where(feasible, cost, np.inf)


def _grid_legs(request, rules, position, velocity, grid) -> np.ndarray:
    """Leg costs between every pair of (object, grid time): shape (N, G, N, G)."""
    return _leg(
        request,
        rules,
        position[:, :, None, None],
        velocity[:, :, None, None],
        grid[None, :, None, None],
        position[None, None],
        velocity[None, None],
        grid[None, None, None, :],
    )


def _grid_dp(legs: np.ndarray, first: np.ndarray, n: int, capacity: int):
    """Dynamic programming over (subset, last target, load, time index)."""
    size = legs.shape[1]
    drop = n
    full = (1 << n) - 1
    value = np.full((1 << n, n, capacity + 1, size), np.inf)
    parent = np.full((1 << n, n, capacity + 1, size, 4), -1)  # prev j, load, k, drop k
    direct = legs[:n, :, :n, :]  # (j, k, m, k')
    # through the drop point: best drop time k'' between k and k'
    to_drop = legs[:n, :, drop, :]  # (j, k, k'')
    from_drop = legs[drop, :, :n, :]  # (k'', m, k')
    via = np.full(direct.shape, np.inf)
    via_k = np.full(direct.shape, -1)
    for k2 in range(size):
        trial = to_drop[:, :, k2][:, :, None, None] + from_drop[k2][None, None]
        better = trial < via
        via[better] = trial[better]
        via_k[better] = k2
    for m in range(n):
        value[1 << m, m, 1] = first[m]
    for mask in range(1, full + 1):
        here = value[mask]  # (j, load, k)
        if not np.isfinite(here).any():
            continue
        for m in (m for m in range(n) if not mask & (1 << m)):
            nxt = mask | (1 << m)
            for load in range(1, capacity + 1):
                src = here[:, load, :]  # (j, k)
                if not np.isfinite(src).any():
                    continue
                if load < capacity:
                    _relax(value, parent, nxt, m, load + 1, src, direct[:, :, m, :], load, None)
                _relax(value, parent, nxt, m, 1, src, via[:, :, m, :], load, via_k[:, :, m, :])
    final_cost = value[full] + np.min(legs[:n, :, drop, :], axis=-1)[:, None, :]
    j, load, k = map(int, np.unravel_index(np.argmin(final_cost), final_cost.shape))
    if not np.isfinite(final_cost[j, load, k]):
        raise ValueError("no feasible plan on the grid visits every target")
    last_drop = int(np.argmin(legs[j, k, drop, :]))
    order, drops, pick_k, drop_k, mask = [], [], [], [], full
    pending_drop = last_drop
    while j >= 0:
        order.append(int(j))
        pick_k.append(int(k))
        drops.append(pending_drop >= 0)
        drop_k.append(int(pending_drop))
        pj, pload, pk, dk = parent[mask, j, load, k]
        mask &= ~(1 << int(j))
        j, load, k, pending_drop = pj, pload, pk, dk
    return order[::-1], drops[::-1], pick_k[::-1], drop_k[::-1]


def _relax(value, parent, nxt, m, new_load, src, legs, load, drop_k) -> None:
    """Improve ``value[nxt, m, new_load, :]`` from ``src`` (j, k) over ``legs`` (j, k, k')."""
    trial = src[:, :, None] + legs  # (j, k, k')
    flat = trial.reshape(-1, trial.shape[-1])
    best = np.argmin(flat, axis=0)
    cost = flat[best, np.arange(flat.shape[1])]
    better = cost < value[nxt, m, new_load]
    if not better.any():
        return
    j, k = np.unravel_index(best[better], trial.shape[:2])
    k_new = np.flatnonzero(better)
    dk = drop_k[j, k, k_new] if drop_k is not None else np.full(k_new.size, -1)
    value[nxt, m, new_load, k_new] = cost[better]
    parent[nxt, m, new_load, k_new] = np.stack([j, np.full(k_new.size, load), k, dk], axis=1)


# --------------------------------------------------------------------- output


def _plan(request: TaskRequest, rules: LegRules, route: _Route) -> Plan:
    """A route as a :class:`Plan` with its cost."""
    tracks = request.targets
    tasks = []
    visits = []
    for index, (target, t) in enumerate(zip(route.order, route.pickup_times, strict=True)):
        point, velocity = tracks[target].predict(t)
        tasks.append(PlanTask(tracks[target].id, t, point, velocity))
        if route.drop_after[index]:
            at = route.drop_times[index]
            visits.append(DropVisit(index, at, request.drop_point.state_at(at)[0]))
    plan = Plan(tuple(tasks), tuple(visits))
    return dataclasses.replace(plan, cost=plan_cost(request, plan, rules.time_weight))
