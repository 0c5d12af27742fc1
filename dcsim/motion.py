"""Motion models of space objects, each exact for its own equations.

A motion model gives an object's position and velocity at any scenario time ``t``
(seconds since the scenario's start). Models are immutable values: the world moves
objects with them, and object tracks carry them so that planners can predict where a
target or obstacle will be.

Every ``state_at`` accepts a scalar time or an array of times and returns arrays of
shape ``(..., 3)``.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from dcsim.geometry import Vector, spherical_to_cartesian

STANDARD_GRAVITATIONAL_PARAMETER_EARTH = 3.986004418e14
"""Earth's gravitational parameter μ, m³/s²."""


def mean_motion(orbit_radius: float, mu: float = STANDARD_GRAVITATIONAL_PARAMETER_EARTH) -> float:
    """Mean motion n = sqrt(μ / a³) of a circular orbit, rad/s.

    Parameters
    ----------
    orbit_radius : float
        Radius of the circular reference orbit, m.
    mu : float
        Gravitational parameter of the central body, m³/s².
    """
    return float(np.sqrt(mu / orbit_radius**3))


class MotionModel(ABC):
    """An object's motion: position and velocity as functions of scenario time."""

    @abstractmethod
    def state_at(self, t: ArrayLike) -> tuple[Vector, Vector]:
        """Return ``(position, velocity)`` at time(s) ``t``.

        Parameters
        ----------
        t : float or array_like
            Scenario time, s.

        Returns
        -------
        position, velocity : ndarray, shape (..., 3)
            In m and m/s, world frame.
        """

    def position_at(self, t: ArrayLike) -> Vector:
        """Return the position (m) at time(s) ``t`` (s)."""
        return self.state_at(t)[0]


def _vec3(values: ArrayLike) -> tuple[float, float, float]:
    x, y, z = (float(v) for v in np.asarray(values, dtype=float).reshape(3))
    return (x, y, z)


@dataclass(frozen=True)
class StaticMotion(MotionModel):
    """An object at rest at ``position`` (m)."""

    position: tuple[float, float, float]

    def __post_init__(self) -> None:
        object.__setattr__(self, "position", _vec3(self.position))

    def state_at(self, t: ArrayLike) -> tuple[Vector, Vector]:
        """Return the fixed position and zero velocity at time(s) ``t``."""
        shape = np.shape(t) + (3,)
        return np.broadcast_to(np.array(self.position), shape).copy(), np.zeros(shape)


@dataclass(frozen=True)
class LinearMotion(MotionModel):
    """Force-free straight-line motion: ``p(t) = position + velocity (t - epoch)``.

    Parameters
    ----------
    position : (3,) float
        Position at ``epoch``, m.
    velocity : (3,) float
        Constant velocity, m/s.
    epoch : float
        Time at which ``position`` holds, s.
    """

    position: tuple[float, float, float]
    velocity: tuple[float, float, float]
    epoch: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "position", _vec3(self.position))
        object.__setattr__(self, "velocity", _vec3(self.velocity))

    def state_at(self, t: ArrayLike) -> tuple[Vector, Vector]:
        """Return position and velocity at time(s) ``t``."""
        dt = np.asarray(t, dtype=float)[..., None] - self.epoch
        v = np.array(self.velocity)
        return np.array(self.position) + v * dt, np.broadcast_to(v, dt.shape[:-1] + (3,)).copy()


@dataclass(frozen=True)
class SphericalMotion(MotionModel):
    """The source thesis's linear spherical orbit model (its eq. 2.1).

    ``(r, θ, φ)(t) = (r0 + v τ, θ0 + α τ, φ0 + β τ)`` with ``τ = t - epoch``, converted
    to Cartesian coordinates (polar angle θ from +z, azimuth φ from +x).

    Parameters
    ----------
    r : float
        Radial distance at ``epoch``, m.
    polar_deg, azimuth_deg : float
        Angles at ``epoch``, degrees.
    v : float
        Radial speed, m/s.
    alpha_deg_s, beta_deg_s : float
        Polar and azimuthal rates, deg/s.
    epoch : float
        Time at which the initial values hold, s.
    """

    r: float
    polar_deg: float
    azimuth_deg: float
    v: float = 0.0
    alpha_deg_s: float = 0.0
    beta_deg_s: float = 0.0
    epoch: float = 0.0

    def state_at(self, t: ArrayLike) -> tuple[Vector, Vector]:
        """Return position and velocity at time(s) ``t``, from the exact derivative."""
        tau = np.asarray(t, dtype=float) - self.epoch
        r = self.r + self.v * tau
        theta = np.radians(self.polar_deg + self.alpha_deg_s * tau)
        phi = np.radians(self.azimuth_deg + self.beta_deg_s * tau)
        position = spherical_to_cartesian(r, np.degrees(theta), np.degrees(phi))
        st, ct, sp, cp = np.sin(theta), np.cos(theta), np.sin(phi), np.cos(phi)
        e_r = np.stack([st * cp, st * sp, ct], axis=-1)
        e_theta = np.stack([ct * cp, ct * sp, -st], axis=-1)
        e_phi = np.stack([-sp, cp, np.zeros_like(sp)], axis=-1)
        theta_dot = np.radians(self.alpha_deg_s)
        phi_dot = np.radians(self.beta_deg_s)
        velocity = (
            self.v * e_r
            + (r * theta_dot)[..., None] * e_theta
            + (r * st * phi_dot)[..., None] * e_phi
        )
        return position, velocity


@dataclass(frozen=True)
class ClohessyWiltshireMotion(MotionModel):
    """Closed-form Clohessy–Wiltshire relative motion in the LVLH frame.

    Axes: x radial (away from the central body), y along-track, z orbit normal.
    Equations: ẍ = 3n²x + 2nẏ, ÿ = −2nẋ, z̈ = −n²z.

    Parameters
    ----------
    position, velocity : (3,) float
        Relative state at ``epoch``, m and m/s.
    mean_motion : float
        Mean motion n of the circular reference orbit, rad/s.
    epoch : float
        Time at which the initial state holds, s.
    """

    position: tuple[float, float, float]
    velocity: tuple[float, float, float]
    mean_motion: float
    epoch: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "position", _vec3(self.position))
        object.__setattr__(self, "velocity", _vec3(self.velocity))
        if not self.mean_motion > 0:
            raise ValueError("mean_motion must be positive")

    def state_at(self, t: ArrayLike) -> tuple[Vector, Vector]:
        """Return the exact relative position and velocity at time(s) ``t``."""
        n = self.mean_motion
        nt = n * (np.asarray(t, dtype=float) - self.epoch)
        s, c = np.sin(nt), np.cos(nt)
        x0, y0, z0 = self.position
        u0, v0, w0 = self.velocity
        x = (4 - 3 * c) * x0 + s / n * u0 + 2 / n * (1 - c) * v0
        y = 6 * (s - nt) * x0 + y0 - 2 / n * (1 - c) * u0 + (4 * s - 3 * nt) / n * v0
        z = c * z0 + s / n * w0
        vx = 3 * n * s * x0 + c * u0 + 2 * s * v0
        vy = -6 * n * (1 - c) * x0 - 2 * s * u0 + (4 * c - 3) * v0
        vz = -n * s * z0 + c * w0
        return np.stack([x, y, z], axis=-1), np.stack([vx, vy, vz], axis=-1)
