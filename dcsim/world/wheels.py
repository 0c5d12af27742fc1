"""Reaction wheels: a robot base's attitude actuators when ``robot.actuators`` lists
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

import numpy as np

from dcsim.scenario.model import WheelSpec, wheel_axes
from dcsim.world.vector3 import Matrix, Vec, cross, rotated, turn, turn_back

_AT_LIMIT = 1.0 - 1e-12
"""Fraction of ``max_momentum`` from which a wheel counts as saturated (rounding)."""

_ITERATIONS = 3
"""Fixed-point iterations of the base's reaction per physics step."""


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
    peak_fraction : float
        Largest ``|h_i| / max_momentum_i`` reached so far.
    """

    def __init__(self, wheels: list[WheelSpec]) -> None:
        self.axes = wheel_axes(wheels)
        self._axis_list = [tuple(axis) for axis in self.axes.T.tolist()]
        self._allocation = np.linalg.pinv(self.axes)
        self._inertia = np.array([wheel.inertia for wheel in wheels])
        self._max_torque = np.array([wheel.max_torque for wheel in wheels])
        self._limits = [wheel.max_momentum for wheel in wheels]
        self._h = [0.0] * len(wheels)
        self._tau = [0.0] * len(wheels)
        self._command_list = [0.0] * len(wheels)
        self._saturated = [False] * len(wheels)
        self._started: list[int] = []
        self._fraction = 0.0
        self.peak_fraction = 0.0

    @property
    def momentum(self) -> np.ndarray:
        """Each wheel's angular momentum about its spin axis, N·m·s (N,)."""
        return np.array(self._h)

    @property
    def torque(self) -> np.ndarray:
        """Each wheel's torque over the last physics step, N·m (N,): what the base reacts
        to."""
        return np.array(self._tau)

    @property
    def speeds(self) -> np.ndarray:
        """Each wheel's spin rate ``h_i / J_i``, rad/s (N,): about its axis in inertial
        space (its rate relative to the base plus the base's about the axis)."""
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
        command = np.clip(torques, -self._max_torque, self._max_torque)
        self._command_list = command.tolist()
        return command

    def momentum_fraction(self) -> float:
        """The largest ``|h_i| / max_momentum_i`` of the wheels now."""
        return self._fraction

    def body_momentum(self) -> np.ndarray:
        """The wheels' angular momentum ``A h``, body frame, N·m·s (3,)."""
        return np.array(self._body(self._h))

    def step(
        self,
        rotation: Matrix,
        angular_velocity: Vec,
        moments: Vec,
        torque: Vec,
        dt: float,
    ) -> Vec:
        """One physics step: the wheels' torques, their momenta, the base's reaction.

        Parameters
        ----------
        rotation : tuple of 9 float
            The base's body-to-world rotation at the step's start, row by row.
        angular_velocity : tuple of 3 float
            The base's angular velocity at the step's start, world frame, rad/s.
        moments : tuple of 3 float
            The base's principal moments of inertia about its centre of mass, along
            the body axes, kg·m².
        torque : tuple of 3 float
            Any other torque on the base over the step, world frame, N·m.
        dt : float
            The physics step, s.

        Returns
        -------
        tuple of 3 float
            The wheels' torque on the base over the step, world frame, N·m.
        """
        torques, momenta, saturated, fraction = [], [], [], 0.0
        for command, h, limit in zip(self._command_list, self._h, self._limits, strict=True):
            low, high = min((-limit - h) / dt, 0.0), max((limit - h) / dt, 0.0)
            tau = low if command < low else high if command > high else command
            h_next = h + tau * dt
            h_next = -limit if h_next < -limit else limit if h_next > limit else h_next
            torques.append(tau)
            momenta.append(h_next)
            saturated.append(abs(h_next) >= _AT_LIMIT * limit)
            fraction = max(fraction, abs(h_next) / limit)
        self._started = [
            i
            for i, (now, was) in enumerate(zip(saturated, self._saturated, strict=True))
            if now and not was
        ]
        before = turn(rotation, self._body(self._h))
        body_after = self._body(momenta)
        self._tau, self._h, self._saturated = torques, momenta, saturated
        self._fraction, self.peak_fraction = fraction, max(self.peak_fraction, fraction)
        ix, iy, iz = moments

        def rate_change(applied: Vec) -> Vec:
            """I⁻¹ applied Δt, world frame, rad/s."""
            bx, by, bz = turn_back(rotation, applied)
            return turn(rotation, (bx / ix * dt, by / iy * dt, bz / iz * dt))

        wx, wy, wz = turn_back(rotation, angular_velocity)
        spin = turn(rotation, (ix * wx, iy * wy, iz * wz))  # I ω, world frame
        gyroscopic = cross(angular_velocity, spin)
        free = rate_change(
            (torque[0] - gyroscopic[0], torque[1] - gyroscopic[1], torque[2] - gyroscopic[2])
        )
        free_rate = (
            angular_velocity[0] + free[0],
            angular_velocity[1] + free[1],
            angular_velocity[2] + free[2],
        )
        wheel = turn(rotation, self._body(torques))
        carried = cross(angular_velocity, before)
        reaction = (-wheel[0] - carried[0], -wheel[1] - carried[1], -wheel[2] - carried[2])
        after = turn(rotation, body_after)
        for _ in range(_ITERATIONS):
            change = rate_change(reaction)
            rotation_step = (
                (free_rate[0] + change[0]) * dt,
                (free_rate[1] + change[1]) * dt,
                (free_rate[2] + change[2]) * dt,
            )
            turned = rotated(rotation_step, after)
            reaction = (
                (before[0] - turned[0]) / dt,
                (before[1] - turned[1]) / dt,
                (before[2] - turned[2]) / dt,
            )
        return reaction

    def _body(self, values: list[float]) -> Vec:
        """``A v`` for per-wheel values ``v`` (momenta or torques), body frame."""
        x = y = z = 0.0
        for (ax, ay, az), value in zip(self._axis_list, values, strict=True):
            x, y, z = x + ax * value, y + ay * value, z + az * value
        return (x, y, z)

    def newly_saturated(self) -> list[int]:
        """Indices of the wheels that reached their momentum limit in the last physics
        step (:meth:`step`): a wheel is saturated while ``|h_i|`` is at ``max_momentum``,
        and reported once per such episode."""
        return self._started

    def delivered(self) -> np.ndarray:
        """The torque the wheels gave the base over the last physics step, ``-A τ``,
        body frame, N·m (3,): the commanded torque where no limit cut it."""
        return -np.array(self._body(self._tau))
