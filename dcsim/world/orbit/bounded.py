"""Drift-free starts: the along-track velocity that keeps a body near the chief.

Under Clohessy–Wiltshire a start is bounded when ``ẏ = −2 n x`` (the ``cw`` motion
spec's ``bounded`` key sets it). Under two-body a body
stays near the chief when its orbit has the chief's period, that is the chief's
specific energy; under J2 the same energy matching (with the J2 potential) removes the
secular drift to first order (the differential J2 precession that remains is small
near the chief; docs/architecture.md gives the measured residual).
"""

from __future__ import annotations

import math

import numpy as np

from dcsim.geometry import Vector
from dcsim.world.orbit.gravity import Potential
from dcsim.world.orbit.relative import RelativeDynamics


def energy_matched_velocity(
    dynamics: RelativeDynamics, potential: Potential, position: Vector, velocity: Vector
) -> Vector:
    """``velocity`` (LVLH, at t = 0) with the along-track component that gives the body
    the chief's specific energy; the root nearer the chief's own motion.

    Raises
    ------
    ValueError
        If no along-track velocity gives the chief's energy (the body is too far out).
    """
    frame = dynamics.frame(0.0)
    rho = np.asarray(position, dtype=float)
    across = np.array([velocity[0], 0.0, velocity[2]], dtype=float)
    inertial_position, base = frame.to_inertial(rho, across)
    along = frame.axes[:, 1]
    chief_energy = float(frame.velocity @ frame.velocity) / 2.0 + float(potential(frame.position))
    target = 2.0 * (chief_energy - float(potential(inertial_position)))
    b = float(base @ along)
    c = float(base @ base) - target
    discriminant = b * b - c
    if discriminant < 0:
        raise ValueError(f"no drift-free start at {rho.tolist()} m: it is too far from the chief")
    root = math.sqrt(discriminant)
    speed = -c / (b + root) if b >= 0 else c / (root - b)  # the root of smaller magnitude
    bounded = across.copy()
    bounded[1] = speed
    return bounded
