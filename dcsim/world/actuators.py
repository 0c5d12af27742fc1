"""A robot base's thrusters and reaction wheels over one control period.

The world asks this module, at each control period's start, what the hardware does
with the controller's command:

- **Thrusters** (:mod:`~dcsim.world.thrusters`) take the commanded force, turned into
  body axes with the attitude at the period's start, and, without reaction wheels, the
  commanded torque, both about the centre of mass of the robot and its cargo (the
  thrusters' positions are from the base's, so a force through a centre moved by cargo
  needs a torque about the base's), and modulated with the minimum impulse bit; a
  command's own ``thruster_on_times`` replace the allocation (rounded to the minimum
  impulse bit, with nothing carried over). The
  firing profile is cut where the propellant runs out. The world applies each physics
  step's body force and torque rotated by the attitude of that step.
- **Reaction wheels** (:mod:`~dcsim.world.wheels`) take the commanded torque (a
  command's own ``wheel_torques`` replace the allocation), less what the thrusters' firing
  gives this period.
- **Momentum unloading**: with both, when a wheel's momentum passes
  ``unloading.start_fraction`` of its limit, the thrusters are asked for the torque
  ``-H / time_constant`` (``H`` the wheels' momentum, body frame) until every wheel is
  below ``unloading.stop_fraction``; the wheels give the rest of the commanded torque,
  so the base feels the command while the wheels' momentum decays.
- **Propellant split**: a period's propellant counts for translation as far as the
  allocation of its delivered mean force alone (no torque) would have burnt it; the
  rest counts for attitude.

What happens is recorded as events: ``wheel_saturated``, ``unloading_started``,
``unloading_ended`` and ``thrust_shortfall`` (the start of a run of periods whose
command the thrusters cannot give).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from dcsim.geometry import cross, row_lengths
from dcsim.scenario.model import ActuatorsSpec
from dcsim.world.environment import Propellant
from dcsim.world.thrusters import Thrusters
from dcsim.world.wheels import ReactionWheels

_SHORTFALL = 1e-3
"""Relative size of the part of a command the thrusters cannot give from which the
period counts as short (rounding and the minimum impulse bit excepted)."""


@dataclass(frozen=True)
class ActuatorEvent:
    """Something the hardware did that a run records as an event.

    Attributes
    ----------
    time : float
        s.
    name : str
        ``wheel_saturated``, ``unloading_started``, ``unloading_ended`` or
        ``thrust_shortfall``.
    data : dict
        The event's own fields (a wheel's number from 1 and momentum, N·m·s; the
        wheels' largest momentum fraction; the wrench that could not be given, N).
    """

    time: float
    name: str
    data: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class ThrustProfile:
    """What the thrusters give in each physics step of a control period, body frame.

    Attributes
    ----------
    forces : ndarray (steps, 3)
        Force on the base, N.
    torques : ndarray (steps, 3)
        Torque about the base's centre of mass, N·m.
    mean_torque : ndarray (3,)
        Mean torque over the period about the centre of mass of the robot and its
        cargo, N·m (what the wheels need not give).
    """

    forces: np.ndarray
    torques: np.ndarray
    mean_torque: np.ndarray


class Actuators:
    """A robot base's thrusters and reaction wheels, either of them absent.

    Parameters
    ----------
    spec : ActuatorsSpec
        The scenario's ``robot.actuators``.
    specific_impulse : float
        ``robot.specific_impulse``, for thrusters that give none, s.
    control_period, physics_step : float
        s.

    Attributes
    ----------
    thrusters : Thrusters or None
    wheels : ReactionWheels or None
    duty : ndarray (N,)
        Each thruster's firing time over the last control period as a fraction of it.
    unloading : bool
        Whether the thrusters are unloading the wheels.
    events : list of ActuatorEvent
        Every event so far.
    attitude_propellant : float
        Propellant counted for attitude so far, kg.
    """

    def __init__(
        self,
        spec: ActuatorsSpec,
        specific_impulse: float,
        control_period: float,
        physics_step: float,
    ) -> None:
        self.thrusters = (
            None
            if spec.thrusters is None
            else Thrusters(spec.thrusters, specific_impulse, control_period, physics_step)
        )
        self.wheels = None if spec.reaction_wheels is None else ReactionWheels(spec.reaction_wheels)
        self._unloading = spec.unloading
        self._period = control_period
        self._dt = physics_step
        self.duty = np.zeros(0 if self.thrusters is None else self.thrusters.count)
        self.unloading = False
        self._short = False
        self.events: list[ActuatorEvent] = []
        self.attitude_propellant = 0.0

    def command_wheels(
        self,
        time: float,
        rotation: np.ndarray,
        torque: np.ndarray,
        wheel_torques: np.ndarray,
        thrust: ThrustProfile | None,
    ) -> None:
        """Command the wheels for the coming period.

        Parameters
        ----------
        time : float
            The period's start, s.
        rotation : ndarray (3, 3)
            The base's body-to-world rotation at the period's start.
        torque : ndarray (3,)
            The commanded torque, world frame, N·m (within the limit).
        wheel_torques : ndarray (N,) or empty
            The command's own wheel torques, N·m; empty: allocate ``torque``.
        thrust : ThrustProfile or None
            The thrusters' firing this period, whose mean torque the wheels leave out.
        """
        assert self.wheels is not None
        if len(wheel_torques):
            self.wheels.command_wheels(wheel_torques)
            return
        wanted = rotation.T @ torque
        if thrust is not None:
            wanted = wanted - thrust.mean_torque
        self.wheels.command(wanted)

    def fire(
        self,
        time: float,
        rotation: np.ndarray,
        force: np.ndarray,
        torque: np.ndarray,
        on_times: np.ndarray,
        propellant: Propellant,
        mass: float,
        centre: np.ndarray,
    ) -> ThrustProfile:
        """The thrusters' firing over the coming period, with its propellant booked.

        Parameters
        ----------
        time : float
            The period's start, s.
        rotation : ndarray (3, 3)
            The base's body-to-world rotation at the period's start.
        force, torque : ndarray (3,)
            The commanded force (N) and torque (N·m), world frame, within the limits;
            the torque goes to the thrusters only without wheels.
        on_times : ndarray (N,) or empty
            The command's own on-times, s; empty: allocate (and, with wheels, unload them
            when their momentum says so; given on-times leave unloading to the command).
        propellant : Propellant
            The propellant, which this firing spends.
        mass : float
            Mass accelerated over the period, kg.
        centre : ndarray (3,)
            The centre of mass of the robot and its cargo relative to the base's, body
            frame, m: the commanded torque is about it, so the thrusters are asked for
            ``torque + centre × force`` about the base's.
        """
        thrusters = self.thrusters
        assert thrusters is not None
        body_force = rotation.T @ force
        if len(on_times):
            on_times = thrusters.round_on_times(on_times)
        else:
            body_torque = (
                rotation.T @ torque if self.wheels is None else self._unloading_torque(time)
            )
            body_torque = body_torque + cross(centre, body_force)
            firing = thrusters.allocate(body_force, body_torque)
            self._note_shortfall(time, firing.shortfall, body_force, body_torque)
            on_times = thrusters.modulate(firing.on_times)
        fractions = thrusters.step_fractions(on_times)
        needed = thrusters.propellant(fractions)
        allowed = propellant.draw(needed)
        fractions = fractions * allowed[:, None]
        forces, torques = thrusters.wrench(fractions)
        self.duty = fractions.sum(axis=0) * self._dt / self._period
        mean_force = forces.mean(axis=0)
        propellant.book_thrust(row_lengths(forces), rotation @ mean_force, mass)
        self._split_propellant(float(needed @ allowed), mean_force, centre)
        mean_torque = torques.mean(axis=0) - cross(centre, mean_force)
        return ThrustProfile(forces, torques, mean_torque)

    def note_saturations(self, time: float) -> None:
        """Record the wheels that reached their momentum limit in the last physics step."""
        assert self.wheels is not None
        for index in self.wheels.newly_saturated():
            momentum = float(self.wheels.momentum[index])
            self.events.append(
                ActuatorEvent(time, "wheel_saturated", {"wheel": index + 1, "momentum": momentum})
            )

    def _unloading_torque(self, time: float) -> np.ndarray:
        """The torque asked of the thrusters to unload the wheels, body frame, N·m (zero
        outside unloading); starts and ends unloading as the wheels' momentum says."""
        assert self.wheels is not None
        fraction = self.wheels.momentum_fraction()
        if not self.unloading and fraction > self._unloading.start_fraction:
            self.unloading = True
            self.events.append(ActuatorEvent(time, "unloading_started", {"fraction": fraction}))
        elif self.unloading and fraction < self._unloading.stop_fraction:
            self.unloading = False
            self.events.append(ActuatorEvent(time, "unloading_ended", {"fraction": fraction}))
        if not self.unloading:
            return np.zeros(3)
        return -self.wheels.body_momentum() / self._unloading.time_constant

    def _note_shortfall(
        self, time: float, shortfall: float, force: np.ndarray, torque: np.ndarray
    ) -> None:
        """Record the start of a run of periods whose command the thrusters cannot give."""
        assert self.thrusters is not None
        size = float(np.linalg.norm(np.concatenate([force, torque / self.thrusters.arm])))
        short = shortfall > _SHORTFALL * size
        if short and not self._short:
            data = {"missing": shortfall, "force": force.tolist(), "torque": torque.tolist()}
            self.events.append(ActuatorEvent(time, "thrust_shortfall", data))
        self._short = short

    def _split_propellant(self, used: float, mean_force: np.ndarray, centre: np.ndarray) -> None:
        """Count the part of ``used`` (kg) beyond what the mean force alone (no torque about
        the centre of mass at ``centre``) costs for attitude."""
        if used == 0.0:
            return
        assert self.thrusters is not None
        alone = self.thrusters.allocate(mean_force, cross(centre, mean_force)).on_times
        translation = float(alone @ self.thrusters.mass_flow)
        self.attitude_propellant += min(max(used - translation, 0.0), used)
