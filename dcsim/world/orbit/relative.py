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
        """The LVLH frame at time ``t`` (s)."""
        return self.frames(np.array([t]))[0]

    def frames(self, times: Vector) -> list[LvlhFrame]:
        """The LVLH frames at ``times`` (K,), s, computed together; each frame's rate
        change is differenced over ±0.5 s (forward from a time under 0.5 s)."""
        step = RATE_CHANGE_STEP
        before = np.where(times >= step, times - step, times)
        after = times + step
        samples = np.concatenate((times, before, after))
        positions, velocities = (a[:, 0] for a in self.chief.states(samples))
        accelerations = self.gravity(positions)
        rates = lvlh_rate(positions, velocities, accelerations)
        count = len(times)
        rate_change = (rates[2 * count :] - rates[count : 2 * count]) / (after - before)[:, None]
        axes = lvlh_axes(positions[:count], velocities[:count])
        return [
            LvlhFrame(
                positions[k],
                velocities[k],
                accelerations[k],
                axes[k],
                rates[k],
                rate_change[k],
            )
            for k in range(count)
        ]

    def acceleration(self, frame: LvlhFrame, rho: Vector, rho_dot: Vector) -> Vector:
        """Relative accelerations (…, 3), m/s², LVLH, of points at ``(ρ, ρ̇)`` (…, 3)."""
        axes = frame.axes
        differential = (self.gravity(frame.position + rho @ axes.T) - frame.acceleration) @ axes
        position_terms, velocity_terms = frame.frame_terms
        return differential + rho @ position_terms.T + rho_dot @ velocity_terms.T

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
        h = JACOBIAN_STEP
        count = len(rho)
        # one gravity call: each body at the start, shifted by ±h along each LVLH axis,
        # and at the end (only the gravity depends nonlinearly on position)
        start_points = start.position + rho @ start.axes.T  # (N, 3), inertial
        shifts = np.concatenate((np.eye(3), -np.eye(3))) * h @ start.axes.T  # (6, 3)
        points = np.concatenate(
            (
                start_points,
                (start_points[:, None, :] + shifts).reshape(-1, 3),
                end.position + rho @ end.axes.T,
            )
        )
        pulls = self.gravity(points)
        shifted = pulls[count : 7 * count].reshape(count, 6, 3)
        starts_terms, end_terms = start.frame_terms, end.frame_terms
        at_start = (
            (pulls[:count] - start.acceleration) @ start.axes
            + rho @ starts_terms[0].T
            + rho_dot @ starts_terms[1].T
        )
        at_end = (
            (pulls[7 * count :] - end.acceleration) @ end.axes
            + rho @ end_terms[0].T
            + rho_dot @ end_terms[1].T
        )
        gradient = (shifted[:, :3] - shifted[:, 3:]) @ start.axes / (2.0 * h)  # (N, axis j, i)
        jacobians = np.swapaxes(gradient, 1, 2) + starts_terms[0]
        velocity_jacobian = starts_terms[1]
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
        p0, v0 = self.position, self.velocity
        dx, dy, dz = position[0] - p0[0], position[1] - p0[1], position[2] - p0[2]
        du, dv, dw = velocity[0] - v0[0], velocity[1] - v0[1], velocity[2] - v0[2]
        (p11, p12, p13), (p21, p22, p23), (p31, p32, p33) = self.position_jacobian
        (v11, v12, v13), (v21, v22, v23), (v31, v32, v33) = self.velocity_jacobian
        base, drift = self.base, self.drift
        return (
            base[0]
            + drift[0] * tau
            + p11 * dx
            + p12 * dy
            + p13 * dz
            + v11 * du
            + v12 * dv
            + v13 * dw,
            base[1]
            + drift[1] * tau
            + p21 * dx
            + p22 * dy
            + p23 * dz
            + v21 * du
            + v22 * dv
            + v23 * dw,
            base[2]
            + drift[2] * tau
            + p31 * dx
            + p32 * dy
            + p33 * dz
            + v31 * du
            + v32 * dv
            + v33 * dw,
        )
