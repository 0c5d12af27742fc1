"""Inertial motion under gravity: the chief's orbit and the free objects.

:class:`KeplerOrbit` is the exact two-body motion of one body (Kepler's equation).
:class:`NumericalOrbits` integrates any number of bodies under a gravity field with
scipy's DOP853 (eighth order, relative tolerance 1e-12), one orbital period at a time,
as far as it is asked for, and interpolates its dense output in between.
"""

from __future__ import annotations

import math
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike
from scipy.integrate import OdeSolution, solve_ivp

from dcsim.geometry import Vector
from dcsim.world.orbit.gravity import Gravity

RELATIVE_TOLERANCE = 1e-12
"""DOP853's relative tolerance."""

ABSOLUTE_TOLERANCE = 1e-9
"""DOP853's absolute tolerance (m and m/s)."""


class InertialMotion(Protocol):
    """Inertial states of one or more bodies at any time."""

    def states(self, t: ArrayLike) -> tuple[Vector, Vector]:
        """Positions and velocities at time(s) ``t`` (s), shape ``t.shape + (N, 3)``,
        m and m/s."""
        ...


class KeplerOrbit:
    """One body's exact two-body motion from its inertial state at t = 0.

    Parameters
    ----------
    position, velocity : ndarray (3,)
        Inertial state at t = 0, m and m/s (an elliptic orbit).
    mu : float
        Gravitational parameter, m³/s².
    """

    def __init__(self, position: Vector, velocity: Vector, mu: float) -> None:
        self.mu = mu
        r0 = float(np.linalg.norm(position))
        energy = float(velocity @ velocity) / 2.0 - mu / r0
        self.semi_major_axis = -mu / (2.0 * energy)
        h = np.cross(position, velocity)
        e_vector = np.cross(velocity, h) / mu - position / r0
        self.eccentricity = float(np.linalg.norm(e_vector))
        a, e = self.semi_major_axis, self.eccentricity
        normal = h / np.linalg.norm(h)
        towards = e_vector if e > 1e-14 else position  # the perigee, or any point if circular
        in_plane = towards - (towards @ normal) * normal  # rounding leaves it off the plane
        p_hat = in_plane / np.linalg.norm(in_plane)
        q_hat = np.cross(normal, p_hat)
        self._axes = np.column_stack((p_hat, q_hat))  # perifocal x and y, inertial
        true_anomaly = math.atan2(float(position @ q_hat), float(position @ p_hat))
        anomaly = 2.0 * math.atan2(
            math.sqrt(1.0 - e) * math.sin(true_anomaly / 2.0),
            math.sqrt(1.0 + e) * math.cos(true_anomaly / 2.0),
        )
        self._mean_anomaly = anomaly - e * math.sin(anomaly)
        self.mean_motion = math.sqrt(mu / a**3)

    def states(self, t: ArrayLike) -> tuple[Vector, Vector]:
        """Positions and velocities at time(s) ``t`` (s), shape ``t.shape + (1, 3)``."""
        a, e, n = self.semi_major_axis, self.eccentricity, self.mean_motion
        mean = self._mean_anomaly + n * np.asarray(t, dtype=float)
        anomaly = _eccentric_anomaly(mean, e)
        cos_e, sin_e = np.cos(anomaly), np.sin(anomaly)
        root = math.sqrt(1.0 - e * e)
        x, y = a * (cos_e - e), a * root * sin_e
        rate = n / (1.0 - e * cos_e)
        vx, vy = -a * sin_e * rate, a * root * cos_e * rate
        position = x[..., None] * self._axes[:, 0] + y[..., None] * self._axes[:, 1]
        velocity = vx[..., None] * self._axes[:, 0] + vy[..., None] * self._axes[:, 1]
        return position[..., None, :], velocity[..., None, :]


def _eccentric_anomaly(mean: np.ndarray, eccentricity: float) -> np.ndarray:
    """Kepler's equation ``M = E − e sin E`` solved for ``E`` by Newton's method."""
    anomaly = mean + eccentricity * np.sin(mean)
    for _ in range(50):
        step = (anomaly - eccentricity * np.sin(anomaly) - mean) / (
            1.0 - eccentricity * np.cos(anomaly)
        )
        anomaly = anomaly - step
        if np.all(np.abs(step) < 1e-15 * (1.0 + np.abs(anomaly))):
            break
    return anomaly


class NumericalOrbits:
    """Bodies moving under a gravity field, integrated one period at a time.

    Parameters
    ----------
    positions, velocities : ndarray (N, 3)
        Inertial states at t = 0, m and m/s.
    gravity : Gravity
        The acceleration field.
    period : float
        Length of each integrated span, s (an orbital period).
    """

    def __init__(
        self, positions: Vector, velocities: Vector, gravity: Gravity, period: float
    ) -> None:
        self._count = len(positions)
        self._gravity = gravity
        self._period = period
        self._start = np.concatenate((positions, velocities), axis=1).reshape(-1)
        self._solution: OdeSolution | None = None
        self._ts: list[float] = [0.0]
        self._interpolants: list[object] = []
        self._end = 0.0

    def _rates(self, _t: float, y: np.ndarray) -> np.ndarray:
        state = y.reshape(self._count, 6)
        return np.concatenate((state[:, 3:], self._gravity(state[:, :3])), axis=1).reshape(-1)

    def _extend_to(self, t_end: float) -> None:
        """Integrate further, a period at a time, until ``t_end`` is covered."""
        while self._solution is None or self._end < t_end:
            y0 = self._start if self._solution is None else self._solution(self._end)
            span = (self._end, self._end + self._period)
            result = solve_ivp(
                self._rates,
                span,
                y0,
                method="DOP853",
                rtol=RELATIVE_TOLERANCE,
                atol=ABSOLUTE_TOLERANCE,
                dense_output=True,
            )
            piece = result.sol
            self._ts = [*self._ts[:-1], *piece.ts]
            self._interpolants = [*self._interpolants, *piece.interpolants]
            self._solution = OdeSolution(self._ts, self._interpolants)
            self._end = span[1]

    def states(self, t: ArrayLike) -> tuple[Vector, Vector]:
        """Positions and velocities at time(s) ``t`` (s, not negative), shape
        ``t.shape + (N, 3)``."""
        times = np.asarray(t, dtype=float)
        self._extend_to(float(np.max(times)))
        assert self._solution is not None
        values = self._solution(times.reshape(-1))  # (6N, K)
        state = values.T.reshape(*times.shape, self._count, 6)
        return state[..., :3], state[..., 3:]
