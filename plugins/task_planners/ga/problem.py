"""A task request as arrays, for evaluating whole populations of plans at once.

The ``ga`` planner's model of a plan (see :mod:`dcsim_plugins.task_planners.ga.planner`): the
collector flies straight constant-velocity legs between timed nodes — its start, each
pickup, each drop visit — and burns impulsively at every node to match the node's
velocity. A leg from ``(p_a, u_a)`` at ``t_a`` to ``(p_b, u_b)`` at ``t_b`` costs

    |v − u_a| + |v − u_b| + w (t_b − t_a),        v = (p_b − p_a) / (t_b − t_a),

(:func:`dcsim.api.leg_delta_v` plus the time weight ``w``), so a plan costs
``plan_delta_v + w * plan_duration`` (:func:`dcsim.api.plan_cost`). A leg is feasible
when it lasts at least ``MIN_TIME_STEP`` and at least the rest-to-rest time of its
length at the plan's speed and the request's acceleration, and ends within the horizon.

The states of all targets and of the drop point are tabulated once per request on a
fine time grid; every later lookup is a vectorised linear interpolation, so one numpy
expression evaluates a leg for any mix of targets and times.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dcsim.api import ObjectTrack, TaskRequest, leg_delta_v, shortest_leg

#: Cost added per second of leg-time shortfall, (m/s)/s: large enough that any feasible
#: plan beats an infeasible one of similar shape.
INFEASIBILITY_PRICE = 10.0

#: Points of the geometric duration grid of a leg-time search.
SEARCH_POINTS = 32


@dataclass(frozen=True)
class PlanModel:
    """Settings of the plan model shared by a request's legs.

    Attributes
    ----------
    time_weight : float
        Price of plan time, (m/s)/s.
    min_time_step : float
        Least duration of a leg, s (MIN_TIME_STEP).
    speed_fraction : float
        Fraction of the request's speed limit a leg may fly at.
    max_leg_time : float
        Longest leg the time search and random times consider, s.
    horizon : float
        Latest node time after the request, s.
    resolution : float
        Step of the state table, s.
    """

    time_weight: float
    min_time_step: float
    speed_fraction: float
    max_leg_time: float
    horizon: float
    resolution: float


@dataclass(frozen=True)
class Legs:
    """Legs evaluated in bulk (all arrays share the leading shape)."""

    cost: np.ndarray
    violation: np.ndarray
    position: np.ndarray
    velocity: np.ndarray

    def penalised(self) -> np.ndarray:
        """Cost plus the price of infeasibility, m/s."""
        return self.cost + INFEASIBILITY_PRICE * self.violation


class TaskProblem:
    """One request's targets, drop point and limits, ready for vectorised evaluation.

    Objects are indexed ``0 … n−1`` for the targets (in ``targets`` order) and ``n`` for
    the drop point.

    Parameters
    ----------
    request : TaskRequest
        The request (start state, drop point, capacity, limits).
    targets : sequence of ObjectTrack
        The targets to plan.
    model : PlanModel
        Cost and feasibility settings.
    """

    def __init__(self, request: TaskRequest, targets: list[ObjectTrack], model: PlanModel):
        self.targets = targets
        self.model = model
        self.n = len(targets)
        self.drop = self.n
        self.t0 = request.time
        self.t_end = request.time + model.horizon
        self.start_position = np.array(request.robot.position)
        self.start_velocity = np.array(request.robot.velocity)
        self.speed = model.speed_fraction * request.max_speed
        self.acceleration = request.max_acceleration
        self.capacity = request.capacity
        self.pre_drop = request.carried >= request.capacity
        self.first_load = 0 if self.pre_drop else request.carried
        grid = request.time + np.arange(0.0, model.horizon + 2 * model.resolution, model.resolution)
        states = [track.predict(grid) for track in targets] + [request.drop_point.state_at(grid)]
        table = np.stack(
            [np.concatenate(np.broadcast_arrays(p, v), axis=-1) for p, v in states]
        )  # (objects, times, 6)
        self._steps = table.shape[1]
        self._table = table[:, :-1].reshape(-1, 6)
        self._slopes = np.diff(table, axis=1).reshape(-1, 6)
        self.durations = np.geomspace(model.min_time_step, model.max_leg_time, SEARCH_POINTS)

    # ------------------------------------------------------------------ lookups
    def state(self, obj: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Positions and velocities of objects ``obj`` at times ``t`` (same shape), m, m/s."""
        u = np.clip((np.asarray(t) - self.t0) / self.model.resolution, 0.0, self._steps - 1.0)
        i = np.minimum(u.astype(int), self._steps - 2)
        row = obj * (self._steps - 1) + i
        state = self._table.take(row, axis=0) + self._slopes.take(row, axis=0) * (u - i)[..., None]
        return state[..., :3], state[..., 3:]

    def min_duration(self, distance: np.ndarray) -> np.ndarray:
        """Shortest feasible leg over ``distance`` m, s."""
        return shortest_leg(distance, self.speed, self.acceleration, self.model.min_time_step)

    # ------------------------------------------------------------------ legs
    def legs(
        self,
        position: np.ndarray,
        velocity: np.ndarray,
        t_from: np.ndarray,
        obj: np.ndarray,
        t_to: np.ndarray,
    ) -> Legs:
        """Evaluate legs from states at ``t_from`` to objects ``obj`` at ``t_to`` (broadcast).

        Parameters
        ----------
        position, velocity : ndarray (..., 3)
            State the legs leave from, m and m/s.
        t_from, t_to : ndarray (...)
            Departure and arrival times, s.
        obj : ndarray of int (...)
            Object index of each leg's end.
        """
        end_position, end_velocity = self.state(obj, t_to)
        duration = t_to - t_from
        offset = end_position - position
        distance = np.sqrt(np.einsum("...i,...i->...", offset, offset))
        cost = leg_delta_v(position, velocity, end_position, end_velocity, duration)
        shortfall = np.maximum(self.min_duration(distance) - duration, 0.0)
        late = np.maximum(t_to - self.t_end, 0.0)
        return Legs(
            cost + self.model.time_weight * duration, shortfall + late, end_position, end_velocity
        )

    def best_arrival(
        self, position: np.ndarray, velocity: np.ndarray, t_from: np.ndarray, obj: np.ndarray
    ) -> np.ndarray:
        """The cheapest feasible arrival time of each leg (the minimum-distance search).

        A geometric grid of durations from ``MIN_TIME_STEP`` to ``max_leg_time`` brackets
        the cheapest feasible duration; a parabola through the bracket (in log duration)
        and the shortest feasible duration near it are tried as refinements, and the
        cheapest feasible candidate is kept (the least infeasible if none is feasible).

        Parameters
        ----------
        position, velocity : ndarray (M, 3)
            Departure states, m and m/s.
        t_from : ndarray (M,)
            Departure times, s.
        obj : ndarray of int (M,)
            Object each leg flies to.

        Returns
        -------
        ndarray (M,)
            Arrival times, s.
        """
        grid = self.durations
        coarse = self.legs(
            position[:, None],
            velocity[:, None],
            t_from[:, None],
            obj[:, None],
            t_from[:, None] + grid,
        )
        scores = coarse.penalised()
        rows = np.arange(len(t_from))
        best = np.argmin(scores, axis=1)
        k = np.clip(best, 1, len(grid) - 2)
        x = np.log(grid)
        f0, f1, f2 = scores[rows, k - 1], scores[rows, k], scores[rows, k + 1]
        curvature = f0 - 2.0 * f1 + f2
        step = np.where(
            curvature > 0, 0.5 * (f0 - f2) / np.where(curvature > 0, curvature, 1.0), 0.0
        )
        spacing = x[1] - x[0]
        vertex = np.exp(x[k] + np.clip(step, -1.0, 1.0) * spacing)
        distance = np.linalg.norm(coarse.position[rows, k] - position, axis=-1)
        edge = self.min_duration(distance) * (1.0 + 1e-9)
        candidates = np.stack([grid[best], vertex, edge], axis=1)
        tried = self.legs(
            position[:, None],
            velocity[:, None],
            t_from[:, None],
            obj[:, None],
            t_from[:, None] + candidates,
        )
        feasible = np.where(tried.violation > 0, np.inf, tried.cost)
        any_feasible = np.any(np.isfinite(feasible), axis=1)
        score = np.where(any_feasible[:, None], feasible, tried.penalised())
        return t_from + candidates[rows, np.argmin(score, axis=1)]
