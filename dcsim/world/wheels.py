"""Reaction wheels: a free flyer's attitude actuators when ``robot.actuators`` lists
``reaction_wheels``.

The wheels' spin is bookkept here; PyBullet sees only the base. Each control period
the commanded base torque ``t`` (body frame) is shared among the wheels by the
minimum-norm solution ``τ = -A⁺ t`` (``A`` the 3×N matrix of unit spin axes; the base
receives ``-A τ = t``), each wheel's torque clipped to its limit. Each physics step a
wheel's torque is further clipped so that its momentum stays within ``±max_momentum``
(a saturated wheel gives no more torque in the direction that would exceed it), its
momentum integrates ``h_i += τ_i Δt``, and the base receives the wheels' reaction as an
external torque ``T``, world frame, such that the wheels' momentum in the world frame
``W = R A h`` changes by exactly ``-T Δt`` over the step:

    T Δt = -(R' A h' - R A h)

(``R`` the base's body-to-world rotation, ``'`` after the step). This is the wheels'
torque on the base ``-R A τ`` and the gyroscopic coupling ``-ω × W`` of the momentum
they carry, discretised as PyBullet steps the base: its angular velocity by
semi-implicit Euler, ``ω' = ω + I⁻¹(T + D - ω × I ω) Δt`` (``D`` any other torque),
and its attitude by ``R' = exp(ω' Δt) R``. ``R'`` depends on ``T``; a few fixed-point
iterations (each shrinking the error by ``|W| Δt / I``) solve it to rounding. The
base's angular momentum plus the wheels' is then conserved step by step as far as
PyBullet conserves the base's own (exactly for equal principal moments; PyBullet's
explicit gyroscopic term drifts for unequal ones, wheels or not).
"""

from __future__ import annotations

import math

import numpy as np

from dcsim.scenario.model import WheelSpec, wheel_axes

_AT_LIMIT = 1.0 - 1e-12
"""Fraction of ``max_momentum`` from which a wheel counts as saturated (rounding)."""

_ITERATIONS = 3
"""Fixed-point iterations of the base's reaction per physics step."""


def _rotation_matrix(rotation_vector: np.ndarray) -> np.ndarray:
    """The rotation matrix of a rotation vector (axis times angle, rad), by Rodrigues."""
    x, y, z = rotation_vector.tolist()
    angle = math.sqrt(x * x + y * y + z * z)
    if angle == 0.0:
        return np.eye(3)
    x, y, z = x / angle, y / angle, z / angle
    s, c = math.sin(angle), 1.0 - math.cos(angle)
    return np.array(
        [
            [1.0 - c * (y * y + z * z), c * x * y - s * z, c * x * z + s * y],
            [c * x * y + s * z, 1.0 - c * (x * x + z * z), c * y * z - s * x],
            [c * x * z - s * y, c * y * z + s * x, 1.0 - c * (x * x + y * y)],
        ]
    )


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a × b`` of two 3-vectors (np.cross costs ten times more at this size)."""
    ax, ay, az = a.tolist()
    bx, by, bz = b.tolist()
    return np.array([ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx])


class ReactionWheels:
    """Three or more reaction wheels fixed in the base.

    Parameters
    ----------
    wheels : list of WheelSpec
        The scenario's wheels: spin axes (body frame), inertias, torque and momentum
        limits.

    Attributes
    ----------
    axes : ndarray (3, N)
        Unit spin axes as columns, body frame.
    momentum : ndarray (N,)
        Each wheel's angular momentum about its spin axis, N·m·s.
    torque : ndarray (N,)
        Each wheel's torque over the last physics step, N·m (what the base reacts to).
    peak_fraction : float
        Largest ``|h_i| / max_momentum_i`` reached so far.
    """

    def __init__(self, wheels: list[WheelSpec]) -> None:
        self.axes = wheel_axes(wheels)
        self._allocation = np.linalg.pinv(self.axes)
        self._inertia = np.array([wheel.inertia for wheel in wheels])
        self._max_torque = np.array([wheel.max_torque for wheel in wheels])
        self._max_momentum = np.array([wheel.max_momentum for wheel in wheels])
        self.momentum = np.zeros(len(wheels))
        self.torque = np.zeros(len(wheels))
        self._command = np.zeros(len(wheels))
        self._saturated = np.zeros(len(wheels), dtype=bool)
        self.peak_fraction = 0.0

    @property
    def speeds(self) -> np.ndarray:
        """Each wheel's spin rate relative to the base, ``h_i / J_i``, rad/s (N,)."""
        return self.momentum / self._inertia

    def command(self, body_torque: np.ndarray) -> np.ndarray:
        """Share a commanded base torque among the wheels for the coming control period.

        Parameters
        ----------
        body_torque : ndarray (3,)
            Torque wanted on the base, body frame, N·m.

        Returns
        -------
        ndarray (N,)
            The wheel torques commanded, N·m: the minimum-norm allocation ``-A⁺ t``, each
            clipped to its ``max_torque`` (momentum limits apply step by step,
            :meth:`step`).
        """
        return self.command_wheels(-(self._allocation @ np.asarray(body_torque, dtype=float)))

    def command_wheels(self, torques: np.ndarray) -> np.ndarray:
        """Set each wheel's torque for the coming control period.

        Parameters
        ----------
        torques : ndarray (N,)
            Torque on each wheel about its spin axis, N·m (the base receives ``-A τ``).

        Returns
        -------
        ndarray (N,)
            The torques commanded, each clipped to its ``max_torque``, N·m.
        """
        torques = np.asarray(torques, dtype=float)
        self._command = np.clip(torques, -self._max_torque, self._max_torque)
        return self._command

    def momentum_fraction(self) -> float:
        """The largest ``|h_i| / max_momentum_i`` of the wheels now."""
        return float((np.abs(self.momentum) / self._max_momentum).max())

    def body_momentum(self) -> np.ndarray:
        """The wheels' angular momentum ``A h``, body frame, N·m·s (3,)."""
        return self.axes @ self.momentum

    def step(
        self,
        rotation: np.ndarray,
        angular_velocity: np.ndarray,
        moments: np.ndarray,
        torque: np.ndarray,
        dt: float,
    ) -> np.ndarray:
        """One physics step: the wheels' torques, their momenta, the base's reaction.

        Parameters
        ----------
        rotation : ndarray (3, 3)
            The base's body-to-world rotation at the step's start.
        angular_velocity : ndarray (3,)
            The base's angular velocity at the step's start, world frame, rad/s.
        moments : ndarray (3,)
            The base's principal moments of inertia about its centre of mass, along
            the body axes, kg·m².
        torque : ndarray (3,)
            Any other torque on the base over the step, world frame, N·m.
        dt : float
            The physics step, s.

        Returns
        -------
        ndarray (3,)
            The wheels' torque on the base over the step, world frame, N·m.
        """
        low = (-self._max_momentum - self.momentum) / dt
        high = (self._max_momentum - self.momentum) / dt
        self.torque = np.clip(self._command, np.minimum(low, 0.0), np.maximum(high, 0.0))
        before = rotation @ (self.axes @ self.momentum)
        self.momentum = np.clip(
            self.momentum + self.torque * dt, -self._max_momentum, self._max_momentum
        )
        fraction = np.abs(self.momentum) / self._max_momentum
        self.peak_fraction = max(self.peak_fraction, float(fraction.max()))
        body_after = self.axes @ self.momentum
        spin = rotation @ (moments * (angular_velocity @ rotation))  # I ω, world frame

        def rate_change(applied: np.ndarray) -> np.ndarray:
            """I⁻¹ applied Δt, world frame, rad/s."""
            return rotation @ ((applied @ rotation) / moments) * dt

        free_rate = angular_velocity + rate_change(torque - _cross(angular_velocity, spin))
        reaction = -(rotation @ (self.axes @ self.torque)) - _cross(angular_velocity, before)
        for _ in range(_ITERATIONS):
            turned = _rotation_matrix((free_rate + rate_change(reaction)) * dt) @ rotation
            reaction = (before - turned @ body_after) / dt
        return reaction

    def newly_saturated(self) -> list[int]:
        """Indices of the wheels that reached their momentum limit since the last call.

        A wheel is saturated while ``|h_i|`` is at ``max_momentum``; it is reported once
        per such episode.
        """
        at_limit = np.abs(self.momentum) >= _AT_LIMIT * self._max_momentum
        started = np.flatnonzero(at_limit & ~self._saturated)
        self._saturated = at_limit
        return started.tolist()

    def delivered(self) -> np.ndarray:
        """The torque the wheels gave the base over the last physics step, ``-A τ``,
        body frame, N·m (3,): the commanded torque where no limit cut it."""
        return -(self.axes @ self.torque)
