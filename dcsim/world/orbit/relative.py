"""Exact relative motion in the chief's rotating LVLH frame.

A point at LVLH relative state ``(ρ, ρ̇)`` has the relative acceleration

``ρ̈ = Cᵀ (g(r_c + C ρ) − a_c) − 2 ω × ρ̇ − ω̇ × ρ − ω × (ω × ρ)``

with ``g`` the gravity field, ``(r_c, a_c)`` the chief's inertial position and
acceleration, ``C`` the LVLH axes and ``ω``, ``ω̇`` the frame's angular velocity and
its rate (LVLH components). :class:`RelativeDynamics` evaluates it for many points at
once; :meth:`RelativeDynamics.linearised` expands it over one control period about each
body's state at the period's start, so that each physics step costs a few
multiplications (:class:`AffineAcceleration`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dcsim.geometry import Vector
from dcsim.world.orbit.frame import LvlhFrame, lvlh_axes, lvlh_rate
from dcsim.world.orbit.gravity import Gravity
from dcsim.world.orbit.propagation import InertialMotion

RATE_CHANGE_STEP = 0.5
"""Half the time span (s) over which the frame rate's derivative is differenced."""

JACOBIAN_STEP = 1.0
"""Position step (m) of the central differences that give ∂ρ̈/∂ρ."""


class RelativeDynamics:
    """The chief's LVLH frame at any time and the relative acceleration in it.

    Parameters
    ----------
    chief : InertialMotion
        The chief's inertial motion (one body).
    gravity : Gravity
        The field every body feels (the chief's own acceleration included).
    """

    def __init__(self, chief: InertialMotion, gravity: Gravity) -> None:
        self.chief = chief
        self.gravity = gravity

    def frame(self, t: float) -> LvlhFrame:
        """The LVLH frame at time ``t`` (s), its rate change differenced over ±0.5 s."""
        step = RATE_CHANGE_STEP
        times = np.array([t, t - step, t + step]) if t >= step else np.array([t, t, t + step])
        positions, velocities = self.chief.states(times)
        positions, velocities = positions[:, 0], velocities[:, 0]
        accelerations = self.gravity(positions)
        rates = lvlh_rate(positions, velocities, accelerations)
        rate_change = (rates[2] - rates[1]) / (times[2] - times[1])
        return LvlhFrame(
            positions[0],
            velocities[0],
            accelerations[0],
            lvlh_axes(positions[0], velocities[0]),
            rates[0],
            rate_change,
        )

    def acceleration(self, frame: LvlhFrame, rho: Vector, rho_dot: Vector) -> Vector:
        """Relative accelerations (…, 3), m/s², LVLH, of points at ``(ρ, ρ̇)`` (…, 3)."""
        axes, w, w_dot = frame.axes, frame.rate, frame.rate_change
        differential = (self.gravity(frame.position + rho @ axes.T) - frame.acceleration) @ axes
        return (
            differential
            - 2.0 * np.cross(w, rho_dot)
            - np.cross(w_dot, rho)
            - np.cross(w, np.cross(w, rho))
        )

    def linearised(
        self, start: LvlhFrame, end: LvlhFrame, period: float, rho: Vector, rho_dot: Vector
    ) -> list[AffineAcceleration]:
        """Each body's relative acceleration over one period, expanded about its state.

        Parameters
        ----------
        start, end : LvlhFrame
            The frame at the period's start and end.
        period : float
            The period's length, s.
        rho, rho_dot : ndarray (N, 3)
            The bodies' LVLH states at the period's start, m and m/s.
        """
        at_start = self.acceleration(start, rho, rho_dot)
        at_end = self.acceleration(end, rho, rho_dot)
        h = JACOBIAN_STEP
        offsets = np.concatenate((np.eye(3) * h, -np.eye(3) * h))  # (6, 3)
        shifted = self.acceleration(
            start, rho[:, None, :] + offsets, np.repeat(rho_dot[:, None, :], 6, axis=1)
        )  # (N, 6, 3)
        jacobians = np.swapaxes((shifted[:, :3] - shifted[:, 3:]) / (2.0 * h), 1, 2)
        w = start.rate
        velocity_jacobian = -2.0 * np.array(
            [[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]]
        )
        drift = (at_end - at_start) / period
        return [
            AffineAcceleration.of(a, d, j, velocity_jacobian, p, v)
            for a, d, j, p, v in zip(at_start, drift, jacobians, rho, rho_dot, strict=True)
        ]


@dataclass(frozen=True, slots=True)
class AffineAcceleration:
    """``a(τ, ρ, ρ̇) = a₀ + ȧ τ + J_ρ (ρ − ρ₀) + J_v (ρ̇ − ρ̇₀)``, in plain floats.

    ``τ`` is the time since the period's start (s). Each tuple holds three rows of
    three floats (the Jacobians) or three floats (the vectors).
    """

    base: tuple[float, float, float]
    drift: tuple[float, float, float]
    position_jacobian: tuple[tuple[float, float, float], ...]
    velocity_jacobian: tuple[tuple[float, float, float], ...]
    position: tuple[float, float, float]
    velocity: tuple[float, float, float]

    @classmethod
    def of(
        cls,
        base: Vector,
        drift: Vector,
        position_jacobian: Vector,
        velocity_jacobian: Vector,
        position: Vector,
        velocity: Vector,
    ) -> AffineAcceleration:
        """From arrays: the vectors (3,) and the Jacobians (3, 3)."""
        return cls(
            tuple(base.tolist()),
            tuple(drift.tolist()),
            tuple(tuple(row) for row in position_jacobian.tolist()),
            tuple(tuple(row) for row in velocity_jacobian.tolist()),
            tuple(position.tolist()),
            tuple(velocity.tolist()),
        )

    def at(
        self, tau: float, position: tuple[float, ...], velocity: tuple[float, ...]
    ) -> tuple[float, float, float]:
        """The acceleration (m/s², LVLH) at ``τ`` (s) of a body at ``(ρ, ρ̇)``."""
        dx, dy, dz = (position[i] - self.position[i] for i in range(3))
        du, dv, dw = (velocity[i] - self.velocity[i] for i in range(3))
        out = []
        for i in range(3):
            p, v = self.position_jacobian[i], self.velocity_jacobian[i]
            out.append(
                self.base[i]
                + self.drift[i] * tau
                + p[0] * dx
                + p[1] * dy
                + p[2] * dz
                + v[0] * du
                + v[1] * dv
                + v[2] * dw
            )
        return out[0], out[1], out[2]
