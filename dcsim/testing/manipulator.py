"""A space manipulator's closed loop on its own model, for testing its controllers
without the world.

:func:`simulate` integrates the model's equation of motion ``M(q) q̈ + C(q, q̇) q̇ = τ``
(the space manipulator thesis's eq. 4.3) with scipy's ``solve_ivp``, the controller's command
held over each control period; the base quaternion follows ``q̇ = ½ [ω, 0] ⊗ q`` (world
frame ``ω``) and is renormalised after every period.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

import numpy as np
from scipy.integrate import solve_ivp

from dcsim.geometry import quaternion_multiply
from dcsim.messages import Command, Reference, RobotSpec, StateEstimate, Surroundings
from dcsim.registry.interfaces import Controller
from dcsim.robots.dh import thesis_manipulator
from dcsim.robots.manipulator import manipulator_model


def thesis_robot(
    max_force: float = np.inf, max_torque: float = np.inf, joint_torque: float = np.inf
) -> RobotSpec:
    """The thesis's manipulator as a :class:`RobotSpec` carrying its model.

    Parameters
    ----------
    max_force, max_torque : float
        Base thrust (N) and torque (N·m) limits.
    joint_torque : float
        Every joint's torque limit, N·m.
    """
    dh = thesis_manipulator()
    model = manipulator_model(dh)
    total_mass = dh.base.mass + float(dh.column("mass").sum())
    return RobotSpec(
        mass=total_mass,
        inertia=np.diag(dh.base.inertia),
        radius=float(np.linalg.norm(dh.base.size)) / 2 + dh.reach,
        max_force=max_force,
        max_torque=max_torque,
        max_speed=np.inf,
        joint_position_limits=np.tile([-np.inf, np.inf], (dh.n_joints, 1)),
        joint_torque_limits=np.full(dh.n_joints, joint_torque),
        model=model,
    )


def estimate_of(time: float, q: np.ndarray, qd: np.ndarray) -> StateEstimate:
    """The exact estimate of state ``q`` (7 + n,), ``qd`` (6 + n,) at ``time``."""
    return StateEstimate(
        time=time,
        position=q[:3],
        attitude=q[3:7],
        velocity=qd[:3],
        angular_velocity=qd[3:6],
        joint_positions=q[7:],
        joint_velocities=qd[6:],
        converged=True,
    )


@dataclass(frozen=True)
class ClosedLoop:
    """A simulated closed loop, sampled at the control instants.

    Attributes
    ----------
    times : ndarray (k,)
        s.
    q : ndarray (k, 7 + n)
        States ``[r, quaternion, θ]``.
    qd : ndarray (k, 6 + n)
        Generalised velocities ``[v, ω, θ̇]``.
    commands : list of Command
        The command applied from each instant to the next (k − 1).
    """

    times: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    commands: list[Command]


def simulate(
    controller: Controller,
    robot: RobotSpec,
    reference: Callable[[float], Reference],
    q0: np.ndarray,
    qd0: np.ndarray,
    duration: float,
    period: float,
    rtol: float = 1e-9,
    atol: float = 1e-12,
    integrator: Literal["solve_ivp", "euler"] = "solve_ivp",
) -> ClosedLoop:
    """Fly ``controller`` (already reset for ``robot``) on ``robot.model``.

    Parameters
    ----------
    controller : Controller
        Asked for a command at every multiple of ``period`` with the exact state.
    robot : RobotSpec
        Its ``model`` is the plant.
    reference : callable
        ``reference(t)``: what to track at time ``t`` (s).
    q0, qd0 : ndarray
        Initial state ``[r, quaternion, θ]`` and velocity ``[v, ω, θ̇]``.
    duration, period : float
        Simulated time and control period, s.
    rtol, atol : float
        ``solve_ivp``'s tolerances.
    integrator : {"solve_ivp", "euler"}
        ``"solve_ivp"``: scipy's RK45 over each period (first trying the whole period in
        one step). ``"euler"``: one semi-implicit Euler step per period, for quick checks
        where the plant's accuracy matters less than the run's length.
    """
    model = robot.model
    steps = int(round(duration / period))
    q, qd = np.array(q0, dtype=float), np.array(qd0, dtype=float)
    n_q = q.size
    times, qs, qds, commands = [0.0], [q.copy()], [qd.copy()], []
    for k in range(steps):
        t = k * period
        command = controller.command(t, estimate_of(t, q, qd), reference(t), Surroundings())
        tau = np.concatenate([command.force, command.torque, command.joint_torques])
        if integrator == "euler":
            qd = qd + period * _acceleration(model, q, qd, tau)
            q = q + period * _configuration_rate(q, qd)
        else:
            y = solve_ivp(
                _plant,
                (0.0, period),  # the plant is autonomous: local time
                np.concatenate([q, qd]),
                method="RK45",
                rtol=rtol,
                atol=atol,
                first_step=period,
                args=(model, tau, n_q),
            ).y[:, -1]
            q, qd = y[:n_q].copy(), y[n_q:].copy()
        q[3:7] /= np.linalg.norm(q[3:7])
        times.append(t + period)
        qs.append(q.copy())
        qds.append(qd.copy())
        commands.append(command)
    return ClosedLoop(np.array(times), np.array(qs), np.array(qds), commands)


def _plant(_t: float, y: np.ndarray, model, tau: np.ndarray, n_q: int) -> np.ndarray:
    """``d/dt [q, q̇]`` of the free-floating manipulator under generalised force ``tau``."""
    q, qd = y[:n_q].copy(), y[n_q:]
    q[3:7] /= np.linalg.norm(q[3:7])
    return np.concatenate([_configuration_rate(q, qd), _acceleration(model, q, qd, tau)])


def _configuration_rate(q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """``d/dt [r, quaternion, θ]`` from ``q̇ = [v, ω, θ̇]``."""
    quaternion_rate = 0.5 * quaternion_multiply(np.append(qd[3:6], 0.0), q[3:7])
    return np.concatenate([qd[:3], quaternion_rate, qd[6:]])


def _acceleration(model, q: np.ndarray, qd: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """``q̈ = M⁻¹ (τ − C q̇)`` (eq. 4.3)."""
    mass, coriolis = model.dynamics(q, qd)
    return np.linalg.solve(mass, tau - coriolis @ qd)
