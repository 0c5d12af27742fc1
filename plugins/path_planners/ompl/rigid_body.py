"""The RRT course project's 12-DoF rigid spacecraft (its eq. 2) as a plain-float model.

The state vector is ``(p, q, v, ω, t, Δv)``: position (m), attitude ``[x, y, z, w]``
(body to world), velocity (m/s) and angular velocity (rad/s), all in the world frame,
then the time (s) and the delta-v spent (m/s). The model is kept in plain Python floats:
OMPL calls it once per propagation step, and numpy's per-call overhead would dominate
vectors this short.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from dcsim.api import PathProblem

DIMENSION = 15
"""State vector length: p (3), q (4, ``[x, y, z, w]``), v (3), ω (3), t, Δv."""
P, Q, V, W, T, DV = slice(0, 3), slice(3, 7), slice(7, 10), slice(10, 13), 13, 14
_FORCE_SET = (1.0, -1.0, 0.0)  # along the body z axis, per unit force
_TORQUE_SET = ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1), (0, 0, 0))


def discrete_control(first: float, second: float) -> tuple[int, int]:
    """Indices into the source's force and torque sets of a control sampled in
    ``[0, 3) × [0, 7)``: each component floored and kept inside its set."""
    return min(max(int(first), 0), 2), min(max(int(second), 0), 6)


def _clip(x: float, y: float, z: float, limit: float) -> tuple[float, float, float]:
    """``(x, y, z)`` scaled back onto the ball of radius ``limit`` if longer."""
    norm = math.sqrt(x * x + y * y + z * z)
    if norm <= limit:
        return x, y, z
    s = limit / norm
    return x * s, y * s, z * s


@dataclass(frozen=True)
class Model:
    """Eq. 2 with its control magnitudes: everything a propagation step needs.

    Attributes
    ----------
    acceleration : float
        Thrust acceleration magnitude, m/s².
    torque : float
        Torque magnitude, N·m.
    mass : float
        kg.
    inertia : tuple of float
        Principal moments, kg·m².
    discrete : bool
        The source's control sets, else continuous controls.
    rk4 : bool
        RK4 steps, else Euler.
    mean_motion : float
        Clohessy–Wiltshire mean motion, rad/s (0 for an inertial frame).
    """

    acceleration: float
    torque: float
    mass: float
    inertia: tuple[float, float, float]
    discrete: bool
    rk4: bool
    mean_motion: float

    @property
    def control_dimension(self) -> int:
        """Length of the real control vector OMPL samples."""
        return 2 if self.discrete else 6

    def control_bounds(self) -> tuple[list[float], list[float]]:
        """Lower and upper bounds of the sampled control vector."""
        if self.discrete:
            return [0.0, 0.0], [3.0, 7.0]
        a, tau = self.acceleration, self.torque
        return [-a, -a, -a, -tau, -tau, -tau], [a, a, a, tau, tau, tau]

    def wrench(self, u: tuple[float, ...], q: Sequence[float]) -> tuple[float, ...]:
        """Thrust acceleration (m/s², world) and torque (N·m, world) of control ``u`` at
        attitude ``q``, as ``(ax, ay, az, τx, τy, τz)``."""
        if self.discrete:
            i, j = discrete_control(u[0], u[1])
            f = _FORCE_SET[i] * self.acceleration
            x, y, z, w = q
            tx, ty, tz = _TORQUE_SET[j]
            tau = self.torque
            return (
                2.0 * (x * z + y * w) * f,
                2.0 * (y * z - x * w) * f,
                (1.0 - 2.0 * (x * x + y * y)) * f,
                tx * tau,
                ty * tau,
                tz * tau,
            )
        return (
            *_clip(u[0], u[1], u[2], self.acceleration),
            *_clip(u[3], u[4], u[5], self.torque),
        )

    def derivative(self, x: list[float], wrench: tuple[float, ...]) -> list[float]:
        """Eq. 2: the time derivative of the state vector ``x`` under ``wrench``
        (:meth:`wrench`, recomputed at ``x``'s attitude for a body-fixed thrust)."""
        qx, qy, qz, qw = x[3], x[4], x[5], x[6]
        wx, wy, wz = x[10], x[11], x[12]
        ax, ay, az, tx, ty, tz = wrench
        # ω̇ = R I⁻¹ Rᵀ τ: torque to body axes, divide, back to the world
        r00, r01, r02 = (
            1 - 2 * (qy * qy + qz * qz),
            2 * (qx * qy - qz * qw),
            2 * (qx * qz + qy * qw),
        )
        r10, r11, r12 = (
            2 * (qx * qy + qz * qw),
            1 - 2 * (qx * qx + qz * qz),
            2 * (qy * qz - qx * qw),
        )
        r20, r21, r22 = (
            2 * (qx * qz - qy * qw),
            2 * (qy * qz + qx * qw),
            1 - 2 * (qx * qx + qy * qy),
        )
        i0, i1, i2 = self.inertia
        b0 = (r00 * tx + r10 * ty + r20 * tz) / i0
        b1 = (r01 * tx + r11 * ty + r21 * tz) / i1
        b2 = (r02 * tx + r12 * ty + r22 * tz) / i2
        vx, vy, vz = x[7], x[8], x[9]
        n = self.mean_motion
        if n:
            ax, ay, az = ax + 3 * n * n * x[0] + 2 * n * vy, ay - 2 * n * vx, az - n * n * x[2]
        thrust = math.sqrt(wrench[0] ** 2 + wrench[1] ** 2 + wrench[2] ** 2)
        return [
            vx,
            vy,
            vz,
            0.5 * (qw * wx + wy * qz - wz * qy),
            0.5 * (qw * wy + wz * qx - wx * qz),
            0.5 * (qw * wz + wx * qy - wy * qx),
            -0.5 * (wx * qx + wy * qy + wz * qz),
            ax,
            ay,
            az,
            r00 * b0 + r01 * b1 + r02 * b2,
            r10 * b0 + r11 * b1 + r12 * b2,
            r20 * b0 + r21 * b1 + r22 * b2,
            1.0,
            thrust,
        ]

    def step(self, x: list[float], u: tuple[float, ...], dt: float) -> list[float]:
        """The state ``dt`` s after ``x`` under control ``u`` (one Euler or RK4 step);
        the quaternion comes out unit."""
        k1 = self.derivative(x, self.wrench(u, x[3:7]))
        if self.rk4:
            y = [a + 0.5 * dt * b for a, b in zip(x, k1, strict=True)]
            k2 = self.derivative(y, self.wrench(u, y[3:7]))
            y = [a + 0.5 * dt * b for a, b in zip(x, k2, strict=True)]
            k3 = self.derivative(y, self.wrench(u, y[3:7]))
            y = [a + dt * b for a, b in zip(x, k3, strict=True)]
            k4 = self.derivative(y, self.wrench(u, y[3:7]))
            h = dt / 6.0
            new = [
                a + h * (b + 2 * c + 2 * d + e)
                for a, b, c, d, e in zip(x, k1, k2, k3, k4, strict=True)
            ]
        else:
            new = [a + dt * b for a, b in zip(x, k1, strict=True)]
        norm = math.sqrt(new[3] ** 2 + new[4] ** 2 + new[5] ** 2 + new[6] ** 2)
        new[3], new[4], new[5], new[6] = new[3] / norm, new[4] / norm, new[5] / norm, new[6] / norm
        return new


def state_vector(problem: PathProblem) -> list[float]:
    """The start's state vector (p, q, v, ω, t, Δv = 0), quaternion normalised."""
    start = problem.start
    q = np.asarray(start.attitude, dtype=float)
    q = q / np.linalg.norm(q)
    return [
        *map(float, start.position),
        *map(float, q),
        *map(float, start.velocity),
        *map(float, start.angular_velocity),
        float(start.time),
        0.0,
    ]
