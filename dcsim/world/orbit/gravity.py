"""Gravity of the central body in the inertial frame: point mass, and point mass with J2.

Both take positions of shape (…, 3) in m (Earth-centred inertial, z the body's spin
axis) and give accelerations of the same shape in m/s².
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from dcsim.geometry import Vector

Point = tuple[float, float, float]
"""One inertial position or acceleration in plain floats, m or m/s²."""


class Gravity(Protocol):
    """An acceleration field: inertial positions (…, 3), m → accelerations (…, 3), m/s²;
    :meth:`at` gives one point's in plain floats (the per-period linearisation calls it
    for a few points, where numpy's overhead is most of the cost)."""

    def __call__(self, position: Vector) -> Vector:
        """Accelerations (…, 3), m/s², at inertial positions (…, 3), m."""
        ...

    def at(self, x: float, y: float, z: float) -> Point:
        """The acceleration at one inertial position, m/s²."""
        ...


@dataclass(frozen=True)
class _PointMass:
    mu: float

    def __call__(self, position: Vector) -> Vector:
        r2 = np.einsum("...i,...i->...", position, position)[..., None]
        return -self.mu * position / (r2 * np.sqrt(r2))

    def at(self, x: float, y: float, z: float) -> Point:
        r2 = x * x + y * y + z * z
        scale = -self.mu / (r2 * math.sqrt(r2))
        return (scale * x, scale * y, scale * z)


@dataclass(frozen=True)
class _PointMassJ2:
    central: _PointMass
    factor: float  # −(3/2) J2 μ R², m⁵/s²

    def __call__(self, position: Vector) -> Vector:
        r2 = np.einsum("...i,...i->...", position, position)[..., None]
        z2 = position[..., 2:3] ** 2 / r2
        scale = self.factor / (r2 * r2 * np.sqrt(r2))
        plane = 1.0 - 5.0 * z2
        zonal = np.concatenate(
            (position[..., :2] * plane, position[..., 2:3] * (plane + 2.0)), axis=-1
        )
        return self.central(position) + scale * zonal

    def at(self, x: float, y: float, z: float) -> Point:
        r2 = x * x + y * y + z * z
        r = math.sqrt(r2)
        plane = 1.0 - 5.0 * (z * z / r2)
        scale = self.factor / (r2 * r2 * r)
        cx, cy, cz = self.central.at(x, y, z)
        return (cx + scale * x * plane, cy + scale * y * plane, cz + scale * z * (plane + 2.0))


def point_mass(mu: float) -> Gravity:
    """``a = −μ r / |r|³`` (μ in m³/s²)."""
    return _PointMass(mu)


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
    return _PointMassJ2(_PointMass(mu), -1.5 * j2 * mu * body_radius**2)


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
