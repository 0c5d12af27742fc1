"""``nearest`` task planner: greedily pick the target that can be reached soonest.

From the collector's estimated position the planner computes, for every remaining
target, the earliest time it can be intercepted, and takes the soonest. Interception
means flying straight at the target in the frame moving with the target's velocity at
pickup, from rest to rest in that frame with the request's acceleration limit and a
cruise speed of ``speed_fraction`` of the speed limit less the target's speed (the
profile the ``straight-line`` path planner flies). When the collector is full it first
visits the drop point (also at its earliest reachable time). Pickup times are spaced by at least
``min_time_step``. Targets that cannot be reached within ``horizon`` are left out.
The plan's cost is its impulsive delta-v (:func:`dcsim.api.plan_delta_v`). Once 70 % of
the request's time budget is spent no further pickup is added, and the plan ends at its
last drop visit that can be reached.
"""

from __future__ import annotations

import time as wallclock
from collections.abc import Callable

import numpy as np

from dcsim.api import (
    DropVisit,
    Plan,
    PlanTask,
    PluginParams,
    TaskPlanner,
    TaskRequest,
    hookimpl,
    plan_delta_v,
    quantity,
    rest_to_rest_time,
)

Predictor = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]


_BUDGET_SHARE = 0.7
"""Share of the time budget after which no further pickup is added."""


class NearestParams(PluginParams):
    """Parameters of :class:`NearestTaskPlanner`."""

    min_time_step: float = quantity(
        1.0, unit="s", gt=0, description="Least time between two plan events (MIN_TIME_STEP)."
    )
    speed_fraction: float = quantity(
        0.8, gt=0, le=1, description="Fraction of the speed limit the plan assumes."
    )
    horizon: float = quantity(
        3600.0, unit="s", gt=0, description="Latest pickup considered, after the request time."
    )
    time_resolution: float = quantity(
        1.0, unit="s", gt=0, description="Grid step of the interception search, before refinement."
    )


def earliest_intercept(
    t0: float,
    p0: np.ndarray,
    speed: float,
    acceleration: float,
    predict: Predictor,
    t_min: float,
    horizon: float,
    resolution: float,
) -> float | None:
    """Earliest time ``t ≥ t_min`` at which a mover can be met from ``p0`` (at rest at ``t0``).

    The mover at ``x(t)`` with velocity ``u(t)`` can be met at ``t`` when the rest-to-rest
    time over ``|x(t) − u(t)(t − t0) − p0|`` (the distance in its moving frame), at
    cruise speed ``speed − |u(t)|`` and ``acceleration``, fits in ``t − t0``. The
    condition is scanned on a grid of step ``resolution`` up to ``t0 + horizon`` and
    refined by bisection.

    Returns
    -------
    float or None
        The interception time, s, or None if none within the horizon.
    """

    def slack(t: np.ndarray) -> np.ndarray:
        position, velocity = predict(t)
        elapsed = t - t0
        distance = np.linalg.norm(
            position - velocity * np.asarray(elapsed)[..., None] - p0, axis=-1
        )
        cruise = speed - np.linalg.norm(velocity, axis=-1)
        needed = rest_to_rest_time(distance, np.maximum(cruise, 1e-12), acceleration)
        return elapsed - np.where(cruise > 0, needed, np.inf)

    grid = np.arange(t_min, t0 + horizon + resolution, resolution)
    ok = np.flatnonzero(slack(grid) >= 0)
    if ok.size == 0:
        return None
    i = int(ok[0])
    if i == 0:
        return float(grid[0])
    lo, hi = float(grid[i - 1]), float(grid[i])
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if slack(np.array(mid)) >= 0 else (mid, hi)
    return hi


class NearestTaskPlanner(TaskPlanner):
    """Greedy plan: always the target reachable soonest, drop visits when full."""

    name = "nearest"
    summary = "Greedy soonest-reachable target first, capacity-aware (baseline)"
    Params = NearestParams
    params: NearestParams

    def plan(self, request: TaskRequest) -> Plan:
        """Plan greedily; see the module documentation."""
        p = self.params
        speed = p.speed_fraction * request.max_speed
        t, position = request.time, np.array(request.robot.position)
        carried = request.carried
        remaining = {track.id: track for track in request.targets}
        tasks: list[PlanTask] = []
        drops: list[DropVisit] = []
        committed = (0, 0)  # tasks and drops that end in a feasible drop visit
        # Stop adding pickups once most of the budget is spent, keeping time to close the
        # plan with its drop visit.
        deadline = wallclock.perf_counter() + _BUDGET_SHARE * request.time_budget

        def search(predict: Predictor, after: float) -> float | None:
            return earliest_intercept(
                t,
                position,
                speed,
                request.max_acceleration,
                predict,
                after,
                request.time + p.horizon - t,
                p.time_resolution,
            )

        def visit_drop() -> bool:
            nonlocal t, position, carried, committed
            arrival = search(request.drop_point.state_at, t + p.min_time_step)
            if arrival is None:
                return False
            point = request.drop_point.state_at(arrival)[0]
            drops.append(DropVisit(after_task=len(tasks) - 1, time=arrival, point=point))
            t, position, carried = arrival, point, 0
            committed = (len(tasks), len(drops))
            return True

        if carried >= request.capacity and not visit_drop():
            return Plan()
        while remaining and wallclock.perf_counter() < deadline:
            times = {
                target_id: search(track.predict, t + p.min_time_step)
                for target_id, track in remaining.items()
            }
            reachable = {k: v for k, v in times.items() if v is not None}
            if not reachable:
                break
            target_id = min(reachable, key=lambda k: (reachable[k], k))
            pickup = reachable[target_id]
            point, velocity = remaining.pop(target_id).predict(pickup)
            tasks.append(PlanTask(target_id, pickup, point, velocity))
            t, position, carried = pickup, point, carried + 1
            if carried >= request.capacity and remaining and not visit_drop():
                break
        if carried > 0:
            visit_drop()
        plan = Plan(tasks=tuple(tasks[: committed[0]]), drop_visits=tuple(drops[: committed[1]]))
        return Plan(plan.tasks, plan.drop_visits, plan_delta_v(request, plan))


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the nearest task planner."""
    return [NearestTaskPlanner]
