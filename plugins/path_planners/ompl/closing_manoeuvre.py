"""Closing manoeuvres of ``ompl-control``: cubic-in-time paths from a tree node into the
goal region, within the limits and clear of the obstacles (see ``ompl_control``'s module
docstring for when they are tried)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from dcsim_plugins.path_planners.ompl.rigid_body import DV, Model, P, Q, T, V, W

from dcsim.api import (
    PathProblem,
    quaternion_conjugate,
    quaternion_from_rotation_vector,
    quaternion_multiply,
    rotation_vector,
)

if TYPE_CHECKING:
    from dcsim_plugins.path_planners.ompl.control import StateCheck

_DURATIONS = np.geomspace(1.0, 2000.0, 48)  # durations tried, in steps


def _cubic(
    start: np.ndarray, rate0: np.ndarray, end: np.ndarray, rate1: np.ndarray, tau: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Cubic Hermite from ``(start, rate0)`` at 0 to ``(end, rate1)`` at ``tau[-1]``:
    values, rates at ``tau`` (k,) and the second derivatives at both ends (2, 3)."""
    span = tau[-1]
    c2 = (3 * (end - start) - (2 * rate0 + rate1) * span) / span**2
    c3 = (2 * (start - end) + (rate0 + rate1) * span) / span**3
    s = tau[:, None]
    values = start + rate0 * s + c2 * s**2 + c3 * s**3
    rates = rate0 + 2 * c2 * s + 3 * c3 * s**2
    return values, rates, np.array([2 * c2, 2 * c2 + 6 * c3 * span])


@dataclass(frozen=True)
class Closing:
    """A closing manoeuvre: state vectors at every step (the first is the node's) and the
    thrust acceleration (m/s²) and angular acceleration (rad/s²) over each step."""

    states: np.ndarray
    accelerations: np.ndarray
    angular_accelerations: np.ndarray


class ClosingManoeuvre:
    """Cubic manoeuvres from a tree node into the goal region (see the module docstring).

    Parameters
    ----------
    problem : PathProblem
        The goal, limits and frame.
    check : StateCheck
        Validity of every step of the manoeuvre.
    model : Model
        Thrust and torque limits.
    step : float
        Spacing of the manoeuvre's samples, s.
    """

    def __init__(self, problem: PathProblem, check: StateCheck, model: Model, step: float) -> None:
        self.goal, self.check, self.step = problem.goal, check, step
        self.acceleration = model.acceleration * (1 - 1e-9)
        inertia_max = max(model.inertia)
        self.angular = min(problem.max_angular_acceleration, model.torque / inertia_max)
        self.speed = problem.max_speed
        self.inertial = model.mean_motion == 0.0
        self.attempts = 0

    def aim(self, p0: np.ndarray) -> np.ndarray:
        """The point aimed at: ``p0`` pulled into the inner half of the goal region, m."""
        goal = self.goal
        offset = p0 - goal.position
        if goal.half_extents is None:
            norm = float(np.linalg.norm(offset))
            half = 0.5 * goal.tolerance
            return goal.position + (offset if norm <= half else offset * (half / norm))
        return goal.position + np.clip(offset, -0.5 * goal.half_extents, 0.5 * goal.half_extents)

    def __call__(self, x: list[float]) -> Closing | None:
        """A valid manoeuvre from state vector ``x`` into the goal, or None."""
        if not self.inertial:
            return None  # the cubic ignores the Clohessy–Wiltshire terms
        self.attempts += 1
        goal, a = self.goal, np.asarray(x)
        p0, v0 = a[P], a[V]
        p1 = self.aim(p0)
        if goal.time is not None:
            spans = np.array([goal.time - a[T]])
        else:
            spans = self.step * _DURATIONS
        spans = spans[spans >= self.step]
        for ends in self._end_velocities(p0, v0, p1, spans):
            feasible = np.flatnonzero(self._feasible(p0, v0, p1, ends, spans))
            closing = None
            if len(feasible):
                closing = self._build(a, p1, ends[feasible[0]], float(spans[feasible[0]]))
            if closing is not None:
                return closing
        return None

    def _end_velocities(
        self, p0: np.ndarray, v0: np.ndarray, p1: np.ndarray, spans: np.ndarray
    ) -> list[np.ndarray]:
        """The end velocities (k, 3) m/s tried for each duration of ``spans`` (k,) s: the
        goal's, or, when it leaves the velocity free, the node's own and then the one of
        constant acceleration."""
        count = len(spans)
        if math.isfinite(self.goal.velocity_tolerance):
            return [np.broadcast_to(self.goal.velocity, (count, 3))]
        return [np.broadcast_to(v0, (count, 3)), 2 * (p1 - p0) / spans[:, None] - v0]

    def _feasible(
        self, p0: np.ndarray, v0: np.ndarray, p1: np.ndarray, v1: np.ndarray, spans: np.ndarray
    ) -> np.ndarray:
        """Which cubics of durations ``spans`` (k,) s, ending at velocities ``v1`` (k, 3)
        m/s, keep within the acceleration limit at their ends (where it peaks) and the
        speed limit at nine points."""
        s = spans[:, None]
        drift = (p1 - p0) / s**2
        first = 6 * drift - (4 * v0 + 2 * v1) / s
        last = -6 * drift + (2 * v0 + 4 * v1) / s
        peak = np.maximum(np.linalg.norm(first, axis=1), np.linalg.norm(last, axis=1))
        c2 = 3 * drift - (2 * v0 + v1) / s
        c3 = (v0 + v1) / s**2 - 2 * drift / s
        tau = np.linspace(0.0, 1.0, 9)[None, :, None] * s[:, :, None]
        velocities = v0 + 2 * c2[:, None, :] * tau + 3 * c3[:, None, :] * tau**2
        speeds = np.linalg.norm(velocities, axis=2)
        return (peak <= self.acceleration) & (speeds.max(axis=1) <= self.speed)

    def _build(self, a: np.ndarray, p1: np.ndarray, v1: np.ndarray, span: float) -> Closing | None:
        """The manoeuvre of duration ``span`` s from state vector ``a``, or None if it
        breaks a limit or meets an obstacle."""
        count = max(1, math.ceil(span / self.step - 1e-9))
        tau = np.linspace(0.0, span, count + 1)
        positions, velocities, _ = _cubic(a[P], a[V], p1, v1, tau)
        q0, w0 = a[Q], a[W]
        if self.goal.attitude is None:
            turn, w1 = w0 * span, w0
        else:
            error = quaternion_multiply(self.goal.attitude, quaternion_conjugate(q0))
            turn, w1 = rotation_vector(error), np.zeros(3)
        angles, rates, spins = _cubic(np.zeros(3), w0, turn, w1, tau)
        if np.linalg.norm(spins, axis=1).max() > self.angular * (1 + 1e-9):
            return None
        attitudes = quaternion_multiply(quaternion_from_rotation_vector(angles), q0)
        steps = np.diff(velocities, axis=0)
        spent = np.concatenate([[0.0], np.cumsum(np.linalg.norm(steps, axis=1))])
        states = np.column_stack(
            [positions, attitudes, velocities, rates, a[T] + tau, a[DV] + spent]
        )
        if not self.check.all_valid(states[1:]):
            return None
        durations = np.diff(tau)[:, None]
        return Closing(states, steps / durations, np.diff(rates, axis=0) / durations)
