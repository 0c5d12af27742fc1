"""The fuel cost of flying a task plan, the common yardstick of task planners.

The collector flies straight constant-velocity legs between the nodes of a plan (its
start, each pickup point, each drop visit) and burns impulsively at every node to match
the node's velocity (a target's, the drop point's) and to leave on the next leg. The
cost is the total delta-v of those burns.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from dcsim.messages import Plan, TaskRequest


def leg_delta_v(
    start_position: ArrayLike,
    start_velocity: ArrayLike,
    end_position: ArrayLike,
    end_velocity: ArrayLike,
    duration: ArrayLike,
) -> np.ndarray:
    """Delta-v of the two burns of one straight constant-velocity leg (vectorised).

    Parameters
    ----------
    start_position, end_position : array_like, shape (..., 3)
        Where the leg starts and ends, m.
    start_velocity, end_velocity : array_like, shape (..., 3)
        Velocity to leave from and to match on arrival, m/s.
    duration : array_like, shape (...)
        Leg duration, s (positive).

    Returns
    -------
    ndarray, shape (...)
        ``|v − v_start| + |v − v_end|`` with leg velocity ``v = Δp / duration``, m/s.
    """
    start_position = np.asarray(start_position, dtype=float)
    duration = np.asarray(duration, dtype=float)
    velocity = (np.asarray(end_position, dtype=float) - start_position) / duration[..., None]
    return _norm(velocity - start_velocity) + _norm(velocity - end_velocity)


def _norm(vectors: np.ndarray) -> np.ndarray:
    """Euclidean norm over the last axis (faster than ``np.linalg.norm`` on small vectors)."""
    return np.sqrt(np.einsum("...i,...i->...", vectors, vectors))


def legs_delta_v(times: ArrayLike, positions: ArrayLike, velocities: ArrayLike) -> float:
    """Total impulsive delta-v of flying straight legs through timed nodes.

    Parameters
    ----------
    times : array_like, shape (N,)
        Node times, strictly increasing, s.
    positions : array_like, shape (N, 3)
        Node positions, m.
    velocities : array_like, shape (N, 3)
        Velocity to match at each node (the first is the start velocity), m/s.

    Returns
    -------
    float
        Sum over nodes of ``|v_leg_in − v_node| + |v_leg_out − v_node|``, m/s (the first
        node has no incoming leg, the last no outgoing one).
    """
    t = np.asarray(times, dtype=float)
    p = np.asarray(positions, dtype=float)
    v = np.asarray(velocities, dtype=float)
    if len(t) < 2:
        return 0.0
    return float(leg_delta_v(p[:-1], v[:-1], p[1:], v[1:], np.diff(t)).sum())


def plan_nodes(request: TaskRequest, plan: Plan) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The timed nodes a plan flies through: start, pickups and drop visits in order.

    Returns
    -------
    times, positions, velocities : ndarray
        Shapes (N,), (N, 3), (N, 3).
    """
    nodes = [(request.time, request.robot.position, request.robot.velocity)]
    drops = {visit.after_task: visit for visit in plan.drop_visits}

    def add_drop(index: int) -> None:
        visit = drops.get(index)
        if visit is not None:
            nodes.append((visit.time, visit.point, request.drop_point.state_at(visit.time)[1]))

    add_drop(-1)
    for index, task in enumerate(plan.tasks):
        nodes.append((task.pickup_time, task.pickup_point, task.pickup_velocity))
        add_drop(index)
    times = np.array([n[0] for n in nodes])
    return times, np.array([n[1] for n in nodes]), np.array([n[2] for n in nodes])


def plan_delta_v(request: TaskRequest, plan: Plan) -> float:
    """Total impulsive delta-v (m/s) of flying ``plan`` from the request's robot state."""
    return legs_delta_v(*plan_nodes(request, plan))


def plan_duration(request: TaskRequest, plan: Plan) -> float:
    """Time (s) from the request to the plan's last pickup or drop visit."""
    times = plan_nodes(request, plan)[0]
    return float(times[-1] - request.time)


def plan_cost(request: TaskRequest, plan: Plan, time_weight: float = 0.0) -> float:
    """Fuel-and-time cost of a plan: ``plan_delta_v + time_weight * plan_duration``.

    Parameters
    ----------
    request, plan
        The request and a plan for it.
    time_weight : float
        Price of plan time, (m/s)/s.

    Returns
    -------
    float
        m/s.
    """
    return plan_delta_v(request, plan) + time_weight * plan_duration(request, plan)
