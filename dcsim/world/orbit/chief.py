"""The chief of a scenario's orbit: its initial state from the elements, and its motion."""

from __future__ import annotations

import math

from dcsim.scenario.model import OrbitSpec
from dcsim.world.orbit.frame import elements_to_state
from dcsim.world.orbit.gravity import (
    Potential,
    j2_potential,
    point_mass,
    point_mass_potential,
    with_j2,
)
from dcsim.world.orbit.propagation import KeplerOrbit, NumericalOrbits
from dcsim.world.orbit.relative import RelativeDynamics


def orbit_period(orbit: OrbitSpec) -> float:
    """The chief's Keplerian period, s."""
    return 2.0 * math.pi / orbit.mean_motion


def relative_dynamics(orbit: OrbitSpec) -> RelativeDynamics:
    """The chief's motion and the gravity field of a ``two-body`` or ``j2`` orbit.

    The chief starts at the orbit's elements (angles in degrees in ``orbit``); under
    ``two-body`` it follows Kepler's equation exactly, under ``j2`` it is integrated
    with the J2 field like every other body.

    Raises
    ------
    ValueError
        For a ``cw`` orbit, whose relative motion is linearised instead.
    """
    if orbit.model == "cw":
        raise ValueError("a cw orbit has no exact relative dynamics")
    elements = orbit.chief_orbit()
    position, velocity = elements_to_state(
        elements.semi_major_axis,
        elements.eccentricity,
        elements.inclination,
        elements.raan,
        elements.argument_of_perigee,
        elements.true_anomaly,
        elements.mu,
    )
    if orbit.model == "two-body":
        return RelativeDynamics(KeplerOrbit(position, velocity, orbit.mu), point_mass(orbit.mu))
    gravity = with_j2(orbit.mu, orbit.j2, orbit.earth_radius)
    chief = NumericalOrbits(position[None], velocity[None], gravity, orbit_period(orbit))
    return RelativeDynamics(chief, gravity)


def orbit_potential(orbit: OrbitSpec) -> Potential:
    """The potential of a ``two-body`` or ``j2`` orbit's gravity field."""
    if orbit.model == "j2":
        return j2_potential(orbit.mu, orbit.j2, orbit.earth_radius)
    return point_mass_potential(orbit.mu)
