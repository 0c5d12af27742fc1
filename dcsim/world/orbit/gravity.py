"""Gravity of the central body in the inertial frame: point mass, and point mass with J2.

Both take positions of shape (…, 3) in m (Earth-centred inertial, z the body's spin
axis) and give accelerations of the same shape in m/s².
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from dcsim.geometry import Vector

Gravity = Callable[[Vector], Vector]
"""An acceleration field: inertial positions (…, 3), m → accelerations (…, 3), m/s²."""


def point_mass(mu: float) -> Gravity:
    """``a = −μ r / |r|³`` (μ in m³/s²)."""

    def gravity(position: Vector) -> Vector:
        r2 = np.einsum("...i,...i->...", position, position)[..., None]
        return -mu * position / (r2 * np.sqrt(r2))

    return gravity


def with_j2(mu: float, j2: float, body_radius: float) -> Gravity:
    """Point mass plus the second zonal harmonic.

    ``a_J2 = −(3/2) J2 μ R² / |r|⁵ · [x (1 − 5z²/r²), y (1 − 5z²/r²), z (3 − 5z²/r²)]``

    Parameters
    ----------
    mu : float
        m³/s².
    j2 : float
        Dimensionless.
    body_radius : float
        The harmonic's reference radius, m.
    """
    central = point_mass(mu)
    factor = -1.5 * j2 * mu * body_radius**2

    def gravity(position: Vector) -> Vector:
        r2 = np.einsum("...i,...i->...", position, position)[..., None]
        z2 = position[..., 2:3] ** 2 / r2
        scale = factor / (r2 * r2 * np.sqrt(r2))
        plane = 1.0 - 5.0 * z2
        zonal = np.concatenate(
            (position[..., :2] * plane, position[..., 2:3] * (plane + 2.0)), axis=-1
        )
        return central(position) + scale * zonal

    return gravity


Potential = Callable[[Vector], Vector]
"""A potential: inertial positions (…, 3), m → potential energy per mass (…), m²/s²."""


def point_mass_potential(mu: float) -> Potential:
    """``U = −μ / |r|`` (μ in m³/s²)."""

    def potential(position: Vector) -> Vector:
        return -mu / np.linalg.norm(position, axis=-1)

    return potential


def j2_potential(mu: float, j2: float, body_radius: float) -> Potential:
    """``U = −μ/r + μ J2 R² (3 z²/r² − 1) / (2 r³)``: the potential of :func:`with_j2`."""

    def potential(position: Vector) -> Vector:
        r = np.linalg.norm(position, axis=-1)
        z2 = position[..., 2] ** 2 / r**2
        return -mu / r + mu * j2 * body_radius**2 * (3.0 * z2 - 1.0) / (2.0 * r**3)

    return potential
