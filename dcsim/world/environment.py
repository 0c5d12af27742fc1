"""The space environment the collector flies in: orbital forces and its propellant.

- **Clohessy–Wiltshire**: in the ``lvlh`` frame a body feels the relative-motion
  accelerations ``(3n²x + 2nẏ, −2nẋ, −n²z)``, applied as external forces at its centre;
  ``geocentric`` is force-free, as in the source thesis.
- **Propellant**: the thrusters burn ``|F| dt / (Isp g0)`` a physics step; delta-v
  accumulates ``|F| dt / m`` with ``m`` the mass of the collector and what it carries.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from dcsim.geometry import length
from dcsim.world.pybullet_client import pb

STANDARD_GRAVITY = 9.80665
"""g0 used with the specific impulse, m/s²."""

Force = tuple[float, float, float]


def cw_acceleration(
    mean_motion: float,
    position: Sequence[float] | np.ndarray,
    velocity: Sequence[float] | np.ndarray,
) -> Force:
    """Clohessy–Wiltshire acceleration at an LVLH state.

    Parameters
    ----------
    mean_motion : float
        Mean motion ``n`` of the reference orbit, rad/s.
    position, velocity : sequence of 3 floats or ndarray (3,)
        LVLH state (x radial, y along-track), m and m/s.

    Returns
    -------
    tuple of 3 floats
        Acceleration, LVLH frame, m/s².
    """
    n = mean_motion
    return (
        3.0 * n * n * position[0] + 2.0 * n * velocity[1],
        -2.0 * n * velocity[0],
        -n * n * position[2],
    )


def apply_cw_force(client: int, body: int, mass: float, mean_motion: float) -> None:
    """Apply the Clohessy–Wiltshire force on ``body`` (mass in kg) for the next physics step.

    The force, ``mass`` times :func:`cw_acceleration` at the body's current state, acts
    at its centre of mass in the world (LVLH) frame.
    """
    # the client id is passed by position: PyBullet parses a keyword more slowly, and this
    # runs for every carried object every physics step
    p, _ = pb.getBasePositionAndOrientation(body, client)
    v, _ = pb.getBaseVelocity(body, client)
    cx, cy, cz = cw_acceleration(mean_motion, p, v)
    pb.applyExternalForce(body, -1, (mass * cx, mass * cy, mass * cz), p, pb.WORLD_FRAME, client)


def apply_cw_force_on_link(
    client: int, body: int, link: int, mass: float, mean_motion: float
) -> None:
    """Apply the Clohessy–Wiltshire force on link ``link`` of multibody ``body`` (mass in kg)
    for the next physics step, at the link's centre of mass (world frame)."""
    state = pb.getLinkState(body, link, computeLinkVelocity=1, physicsClientId=client)
    p, v = state[0], state[6]
    cx, cy, cz = cw_acceleration(mean_motion, p, v)
    pb.applyExternalForce(
        body, link, (mass * cx, mass * cy, mass * cz), p, pb.WORLD_FRAME, physicsClientId=client
    )


class Propellant:
    """The thrusters' propellant: what is left and used, and the delta-v flown.

    Parameters
    ----------
    mass : float
        Usable propellant at the start, kg.
    specific_impulse : float
        Thruster specific impulse, s.
    physics_step : float
        Physics time step, s.
    steps : int
        Physics steps in a control period.

    Attributes
    ----------
    remaining : float
        Propellant left, kg.
    used : float
        Propellant used so far, kg.
    delta_v : float
        Delta-v accumulated, m/s.
    last_acceleration : ndarray (3,)
        Mean thrust acceleration over the last burn, world frame, m/s².
    """

    def __init__(
        self, mass: float, specific_impulse: float, physics_step: float, steps: int
    ) -> None:
        self.remaining = mass
        self.used = 0.0
        self.delta_v = 0.0
        self.last_acceleration = np.zeros(3)
        self._specific_impulse = specific_impulse
        self._dt = physics_step
        self._steps = steps

    def burn(self, force: np.ndarray, mass: float) -> list[Force]:
        """Thrust of each physics step of the coming control period, with the bookkeeping.

        The commanded force is held over the period until the propellant runs out.

        Parameters
        ----------
        force : ndarray (3,)
            Commanded thrust, world frame, N (already within the limit).
        mass : float
            Mass accelerated over the period (collector and cargo), kg.

        Returns
        -------
        list of tuple
            The thrust (N, world frame) of each physics step of the period.
        """
        steps, dt = self._steps, self._dt
        magnitude = length(force)
        per_step = magnitude * dt / (self._specific_impulse * STANDARD_GRAVITY)
        if per_step == 0 or (self.remaining - per_step * (steps - 1)) / per_step >= 1.0:
            # the whole period at one fraction, 0 or 1: the general case's numbers, exactly
            fraction = 0.0 if per_step == 0 else 1.0
            burnt, mean = fraction * steps, fraction
            thrusts = [tuple(fraction * f for f in force.tolist())] * steps
        else:
            fractions = np.clip((self.remaining - per_step * np.arange(steps)) / per_step, 0.0, 1.0)
            burnt, mean = float(fractions.sum()), float(fractions.mean())
            thrusts = [tuple(thrust) for thrust in np.outer(fractions, force).tolist()]
        used = per_step * burnt
        self.remaining = max(self.remaining - used, 0.0)
        self.used += used
        self.delta_v += magnitude * dt * burnt / mass
        self.last_acceleration = force * (mean / mass)
        return thrusts

    def draw(self, needed: np.ndarray) -> np.ndarray:
        """Take the propellant that each physics step of the coming period needs, in turn,
        until none is left.

        Parameters
        ----------
        needed : ndarray (steps,)
            Propellant each step's firing burns, kg.

        Returns
        -------
        ndarray (steps,)
            The fraction of each step's firing the propellant allowed: 1 until it runs
            out, then the part left, then 0.
        """
        before = np.cumsum(needed) - needed
        room = np.maximum(self.remaining - before, 0.0)
        fractions = np.where(
            needed > 0, np.minimum(room / np.where(needed > 0, needed, 1.0), 1.0), 1.0
        )
        used = float(needed @ fractions)
        self.remaining = max(self.remaining - used, 0.0)
        self.used += used
        return fractions

    def book_thrust(self, magnitudes: np.ndarray, mean_force: np.ndarray, mass: float) -> None:
        """Book a period of thrust that :meth:`draw` paid for.

        Parameters
        ----------
        magnitudes : ndarray (steps,)
            The net thrust's magnitude in each physics step, N.
        mean_force : ndarray (3,)
            The mean net thrust over the period, world frame, N.
        mass : float
            Mass accelerated over the period, kg.
        """
        self.delta_v += float(magnitudes.sum()) * self._dt / mass
        self.last_acceleration = mean_force / mass
