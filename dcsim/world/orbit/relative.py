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

        The acceleration at the period's start and end, and its gradient in position by
        central differences of the gravity (±``JACOBIAN_STEP`` along each LVLH axis; the
        frame's terms are exact), evaluated body by body in plain floats: for the few
        bodies of a robot, numpy's overhead would be most of the cost.

        Parameters
        ----------
        start, end : LvlhFrame
            The frame at the period's start and end.
        period : float
            The period's length, s.
        rho, rho_dot : ndarray (N, 3)
            The bodies' LVLH states at the period's start, m and m/s.
        """
        first, last = _FloatFrame.of(start), _FloatFrame.of(end)
        gravity, h = self.gravity.at, JACOBIAN_STEP
        fields = []
        for p, v in zip(rho.tolist(), rho_dot.tolist(), strict=True):
            px, py, pz = first.inertial(p)
            at_start = first.relative(gravity(px, py, pz), p, v)
            at_end = last.relative(gravity(*last.inertial(p)), p, v)
            rows = []  # row j: ∂(Cᵀ g)/∂ρ_j
            for ax, ay, az in first.columns:
                ux, uy, uz = gravity(px + h * ax, py + h * ay, pz + h * az)
                wx, wy, wz = gravity(px - h * ax, py - h * ay, pz - h * az)
                scale = 0.5 / h
                rows.append(
                    first.to_lvlh(((ux - wx) * scale, (uy - wy) * scale, (uz - wz) * scale))
                )
            (a11, a12, a13), (a21, a22, a23), (a31, a32, a33) = first.position_terms
            jacobian = (
                (rows[0][0] + a11, rows[1][0] + a12, rows[2][0] + a13),
                (rows[0][1] + a21, rows[1][1] + a22, rows[2][1] + a23),
                (rows[0][2] + a31, rows[1][2] + a32, rows[2][2] + a33),
            )
            drift = (
                (at_end[0] - at_start[0]) / period,
                (at_end[1] - at_start[1]) / period,
                (at_end[2] - at_start[2]) / period,
            )
            position = (p[0], p[1], p[2])
            velocity = (v[0], v[1], v[2])
            fields.append(
                AffineAcceleration(
                    at_start, drift, jacobian, first.velocity_terms, position, velocity
                )
            )
        return fields


Vec = tuple[float, float, float]
"""A 3-vector in plain floats."""

Rows = tuple[Vec, Vec, Vec]
"""A 3×3 matrix in plain floats, row by row."""


def _rows(matrix: Vector) -> Rows:
    (a, b, c), (d, e, f), (g, i, j) = matrix.tolist()
    return ((a, b, c), (d, e, f), (g, i, j))


@dataclass(frozen=True)
class _FloatFrame:
    """An :class:`~dcsim.world.orbit.frame.LvlhFrame` in plain floats: the chief's
    position and acceleration, the axes matrix ``C`` by rows and by columns (the LVLH
    axes in inertial components) and the frame's terms."""

    position: Vec
    acceleration: Vec
    rows: Rows
    columns: Rows
    position_terms: Rows
    velocity_terms: Rows

    @classmethod
    def of(cls, frame: LvlhFrame) -> _FloatFrame:
        """The frame's numbers as floats."""
        position_terms, velocity_terms = frame.frame_terms
        (x, y, z), (ax, ay, az) = frame.position.tolist(), frame.acceleration.tolist()
        return cls(
            (x, y, z),
            (ax, ay, az),
            _rows(frame.axes),
            _rows(frame.axes.T),
            _rows(position_terms),
            _rows(velocity_terms),
        )

    def inertial(self, rho: list[float]) -> Vec:
        """``r_c + C ρ``, m."""
        x, y, z = rho
        (a, b, c), (d, e, f), (g, h, i) = self.rows
        cx, cy, cz = self.position
        return (cx + a * x + b * y + c * z, cy + d * x + e * y + f * z, cz + g * x + h * y + i * z)

    def to_lvlh(self, vector: Vec) -> Vec:
        """``Cᵀ v``: an inertial vector's LVLH components."""
        x, y, z = vector
        (a, b, c), (d, e, f), (g, h, i) = self.columns
        return (a * x + b * y + c * z, d * x + e * y + f * z, g * x + h * y + i * z)

    def relative(self, pull: Vec, rho: list[float], rho_dot: list[float]) -> Vec:
        """The relative acceleration of a point at ``(ρ, ρ̇)`` feeling ``pull`` (m/s²,
        inertial): ``Cᵀ (g − a_c) + A_ρ ρ + A_v ρ̇``."""
        ax, ay, az = self.acceleration
        gx, gy, gz = self.to_lvlh((pull[0] - ax, pull[1] - ay, pull[2] - az))
        x, y, z = rho
        u, v, w = rho_dot
        (p11, p12, p13), (p21, p22, p23), (p31, p32, p33) = self.position_terms
        (q11, q12, q13), (q21, q22, q23), (q31, q32, q33) = self.velocity_terms
        return (
            gx + p11 * x + p12 * y + p13 * z + q11 * u + q12 * v + q13 * w,
            gy + p21 * x + p22 * y + p23 * z + q21 * u + q22 * v + q23 * w,
            gz + p31 * x + p32 * y + p33 * z + q31 * u + q32 * v + q33 * w,
        )


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
