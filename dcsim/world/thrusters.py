"""Thrusters: a robot base's force (and, without wheels, torque) actuators when
``robot.actuators.thrusters`` is given.

Each thruster ``i`` sits at ``p_i`` (body frame, from the base's centre of mass) and
pushes the base along the unit direction ``d_i`` with at most ``F_i`` newtons. Firing at
full thrust for ``t_i`` seconds of a control period of ``T`` seconds gives the impulse
``F_i t_i d_i`` and the angular impulse ``F_i t_i (p_i × d_i)``, body frame.

**Allocation.** A commanded body wrench ``w = [force; torque]`` held over the period
is shared among the thrusters by non-negative least squares: ``min |B f − w|`` over
thrusts ``f ≥ 0``, with ``B``'s column ``i`` ``[d_i; (p_i × d_i) / L]`` and ``w``'s
torque rows also divided by ``L`` (``L`` the thrusters' mean distance from the centre
of mass, so newtons and newton-metres weigh alike). The active-set solution fires few
thrusters; it is not the propellant optimum. If a thrust exceeds its ``F_i`` the whole
allocation is scaled down so the wrench keeps its direction. What no thrust set can
give (the residual) and what the scaling took off are reported as a shortfall.

**Pulse-width modulation.** Thruster ``i`` fires for ``t_i = T f_i / F_i`` from the
period's start. An on-time shorter than the minimum impulse bit's ``t_min = MIB_i / F_i``
is rounded to 0 below ``t_min / 2`` and to ``t_min`` from there. What the rounding took
off or added is carried into the thruster's next period (error feedback, at most
``t_min`` either way), so a steady command too small for one pulse is met on average by
pulses every few periods instead of never. A physics step of length ``Δt`` only partly
covered by a firing receives the covered fraction of the thrust, so the impulse over
the period is exactly ``F_i t_i``.

**Propellant.** Thruster ``i`` burns ``F_i / (Isp_i g₀)`` kilograms per second of firing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import nnls

from dcsim.scenario.model import ThrusterSpec, thruster_matrices
from dcsim.world.environment import STANDARD_GRAVITY


@dataclass(frozen=True)
class Firing:
    """The thrusters' on-times over one control period and what they fall short of.

    Attributes
    ----------
    on_times : ndarray (N,)
        Each thruster's firing time from the period's start, s, before the minimum
        impulse bit's rounding (:meth:`Thrusters.modulate`).
    shortfall : float
        Size of the part of the commanded wrench the thrusters cannot give (before the
        minimum impulse bit's rounding): ``|w − B f|`` with torque divided by the mean arm,
        N.
    """

    on_times: np.ndarray
    shortfall: float


class Thrusters:
    """A set of body-fixed thrusters and their allocation.

    Parameters
    ----------
    specs : list of ThrusterSpec
        Position and direction (body frame), maximum thrust, minimum impulse bit and
        specific impulse of each thruster.
    default_isp : float
        Specific impulse of a thruster that gives none, s.
    control_period : float
        The control period ``T``, s.
    physics_step : float
        The physics step ``Δt``, s.

    Attributes
    ----------
    max_thrust : ndarray (N,)
        Each thruster's thrust when on, N.
    forces, torques : ndarray (3, N)
        Force (N) and torque (N·m) of each thruster at full thrust, body frame.
    mass_flow : ndarray (N,)
        Propellant each thruster burns per second on, kg/s.
    arm : float
        The thrusters' mean distance from the centre of mass, m (the allocation divides
        torques by it).
    """

    def __init__(
        self,
        specs: list[ThrusterSpec],
        default_isp: float,
        control_period: float,
        physics_step: float,
    ) -> None:
        self.forces, self.torques = thruster_matrices(specs)
        self.max_thrust = np.array([s.max_thrust for s in specs], dtype=float)
        self._min_on_time = np.array([s.min_impulse_bit for s in specs]) / self.max_thrust
        isp = [default_isp if s.specific_impulse is None else s.specific_impulse for s in specs]
        self.mass_flow = self.max_thrust / (np.array(isp, dtype=float) * STANDARD_GRAVITY)
        positions = np.array([s.position for s in specs], dtype=float)
        self.arm = max(float(np.linalg.norm(positions, axis=1).mean()), 1e-9)
        self._unit_wrench = np.vstack([self.forces, self.torques / self.arm]) / self.max_thrust
        self.period = control_period
        steps = round(control_period / physics_step)
        self._step_starts = np.arange(steps) * physics_step
        self._dt = physics_step
        self._carried = np.zeros(len(specs))

    @property
    def count(self) -> int:
        """Number of thrusters."""
        return len(self.max_thrust)

    def allocate(self, force: np.ndarray, torque: np.ndarray) -> Firing:
        """On-times that give ``force`` and ``torque`` (body frame) over the period.

        Parameters
        ----------
        force : ndarray (3,)
            Mean force wanted on the base over the period, body frame, N.
        torque : ndarray (3,)
            Mean torque wanted about the centre of mass, body frame, N·m.

        Returns
        -------
        Firing
            On-times (not yet rounded to the minimum impulse bit) and the shortfall.
        """
        wanted = np.concatenate([force, np.asarray(torque, dtype=float) / self.arm])
        if not wanted.any():
            return Firing(np.zeros(self.count), 0.0)
        thrust = nnls(self._unit_wrench, wanted)[0]
        scale = float(np.max(thrust / self.max_thrust))
        if scale > 1.0:
            thrust = thrust / scale
        given = self._unit_wrench @ thrust
        shortfall = float(np.linalg.norm(wanted - given))
        return Firing(self.period * thrust / self.max_thrust, shortfall)

    def modulate(self, on_times: np.ndarray) -> np.ndarray:
        """The on-times fired this period: ``on_times`` plus what earlier periods' rounding
        left over, rounded to the minimum impulse bit (:meth:`round_on_times`), s; the new
        remainder, within ``±t_min``, is kept for the next period."""
        wanted = np.clip(on_times + self._carried, 0.0, self.period)
        fired = self.round_on_times(wanted)
        self._carried = np.clip(wanted - fired, -self._min_on_time, self._min_on_time)
        return fired

    def round_on_times(self, on_times: np.ndarray) -> np.ndarray:
        """On-times within ``[0, T]`` and rounded to the minimum impulse bit, s.

        An on-time below ``t_min / 2`` becomes 0, one from ``t_min / 2`` to ``t_min``
        becomes ``t_min`` (``t_min`` = minimum impulse bit / maximum thrust).
        """
        on = np.clip(np.asarray(on_times, dtype=float), 0.0, self.period)
        short = on < self._min_on_time
        on[short] = np.where(
            on[short] < 0.5 * self._min_on_time[short], 0.0, self._min_on_time[short]
        )
        return on

    def step_fractions(self, on_times: np.ndarray) -> np.ndarray:
        """The fraction of each physics step each thruster fires, (steps, N).

        Thruster ``i`` fires from the period's start for ``on_times[i]`` seconds; a step
        it covers in part gets that part.
        """
        covered = (on_times[None, :] - self._step_starts[:, None]) / self._dt
        return np.clip(covered, 0.0, 1.0)

    def wrench(self, fractions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Body force (N) and torque (N·m) of each physics step, (steps, 3) each."""
        return fractions @ self.forces.T, fractions @ self.torques.T

    def propellant(self, fractions: np.ndarray) -> np.ndarray:
        """Propellant burnt in each physics step, kg (steps,)."""
        return (fractions @ self.mass_flow) * self._dt
