"""The chief's orbit elements, its LVLH frame, and relative states in that frame.

Inertial states are Earth-centred inertial (ECI), m and m/s. The LVLH axes of a chief
at ``(r, v)``: x̂ = r/|r|, ẑ = h/|h| with h = r × v, ŷ = ẑ × x̂. The frame turns at
``ω = (ω_x, 0, ω_z)`` (LVLH components) with ``ω_z = |h|/|r|²`` and
``ω_x = |r| (a · ẑ)/|h|``, ``a`` the chief's acceleration (zero for two-body).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from dcsim.geometry import Vector


def elements_to_state(
    semi_major_axis: float,
    eccentricity: float,
    inclination: float,
    raan: float,
    argument_of_perigee: float,
    true_anomaly: float,
    mu: float,
) -> tuple[Vector, Vector]:
    """The inertial state of an orbit given by its Keplerian elements.

    Parameters
    ----------
    semi_major_axis : float
        m.
    eccentricity : float
        In [0, 1).
    inclination, raan, argument_of_perigee, true_anomaly : float
        rad.
    mu : float
        Gravitational parameter, m³/s².

    Returns
    -------
    position, velocity : ndarray (3,)
        ECI, m and m/s.
    """
    p = semi_major_axis * (1.0 - eccentricity**2)
    cos_nu, sin_nu = np.cos(true_anomaly), np.sin(true_anomaly)
    radius = p / (1.0 + eccentricity * cos_nu)
    position = radius * np.array([cos_nu, sin_nu, 0.0])
    velocity = np.sqrt(mu / p) * np.array([-sin_nu, eccentricity + cos_nu, 0.0])
    rotation = _perifocal_to_inertial(inclination, raan, argument_of_perigee)
    return rotation @ position, rotation @ velocity


def _perifocal_to_inertial(inclination: float, raan: float, perigee: float) -> np.ndarray:
    """R3(−Ω) R1(−i) R3(−ω): perifocal components to inertial ones."""
    co, so = np.cos(raan), np.sin(raan)
    ci, si = np.cos(inclination), np.sin(inclination)
    cw, sw = np.cos(perigee), np.sin(perigee)
    return np.array(
        [
            [co * cw - so * sw * ci, -co * sw - so * cw * ci, so * si],
            [so * cw + co * sw * ci, -so * sw + co * cw * ci, -co * si],
            [sw * si, cw * si, ci],
        ]
    )


@dataclass(frozen=True)
class LvlhFrame:
    """The chief's LVLH frame at one instant.

    Attributes
    ----------
    position, velocity, acceleration : ndarray (3,)
        The chief's inertial state and acceleration, m, m/s and m/s².
    axes : ndarray (3, 3)
        LVLH unit vectors x̂, ŷ, ẑ as columns, inertial components (LVLH → inertial).
    rate : ndarray (3,)
        The frame's angular velocity ω, LVLH components, rad/s.
    rate_change : ndarray (3,)
        Its time derivative ω̇, LVLH components, rad/s².
    """

    position: Vector
    velocity: Vector
    acceleration: Vector
    axes: Vector
    rate: Vector
    rate_change: Vector

    def to_inertial(self, rho: Vector, rho_dot: Vector) -> tuple[Vector, Vector]:
        """Inertial states (…, 3) of points at LVLH relative states ``(ρ, ρ̇)`` (…, 3)."""
        position = self.position + rho @ self.axes.T
        velocity = self.velocity + (rho_dot + cross(self.rate, rho)) @ self.axes.T
        return position, velocity

    @functools.cached_property
    def frame_terms(self) -> tuple[Vector, Vector]:
        """The rotating frame's accelerations as matrices (3, 3): the relative
        acceleration's part ``−ω̇ × ρ − ω × (ω × ρ)`` is ``ρ @ A_ρ.T`` and its part
        ``−2 ω × ρ̇`` is ``ρ̇ @ A_v.T``; returns ``(A_ρ, A_v)``."""
        w, w_dot = skew(self.rate), skew(self.rate_change)
        return -w_dot - w @ w, -2.0 * w


def skew(vector: Vector) -> Vector:
    """The matrix (3, 3) ``[v×]`` with ``[v×] u = v × u``."""
    x, y, z = vector
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def cross(a: Vector, b: Vector) -> Vector:
    """``a × b`` over the last axis (…, 3), broadcast; faster than :func:`numpy.cross`
    on small arrays."""
    ax, ay, az = a[..., 0], a[..., 1], a[..., 2]
    bx, by, bz = b[..., 0], b[..., 1], b[..., 2]
    return np.stack((ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx), axis=-1)


def to_relative(
    chief_position: Vector,
    chief_velocity: Vector,
    axes: Vector,
    rate: Vector,
    position: Vector,
    velocity: Vector,
) -> tuple[Vector, Vector]:
    """LVLH relative states ``(ρ, ρ̇)`` of points at inertial states.

    Parameters
    ----------
    chief_position, chief_velocity : ndarray (K, 3)
        The chief at K times, inertial, m and m/s.
    axes : ndarray (K, 3, 3)
        The LVLH axes at those times (:func:`lvlh_axes`).
    rate : ndarray (K, 3)
        The frame's angular velocity, LVLH components, rad/s.
    position, velocity : ndarray (K, N, 3)
        N points at each time, inertial.

    Returns
    -------
    rho, rho_dot : ndarray (K, N, 3)
        LVLH, m and m/s (ρ̇ as seen in the rotating frame).
    """
    rho = np.einsum("kni,kij->knj", position - chief_position[:, None], axes)
    seen = np.einsum("kni,kij->knj", velocity - chief_velocity[:, None], axes)
    return rho, seen - cross(rate[:, None], rho)


def lvlh_axes(position: Vector, velocity: Vector) -> Vector:
    """LVLH unit vectors as columns (…, 3, 3) of chiefs at inertial ``(r, v)`` (…, 3)."""
    x = position / np.linalg.norm(position, axis=-1, keepdims=True)
    h = cross(position, velocity)
    z = h / np.linalg.norm(h, axis=-1, keepdims=True)
    return np.stack((x, cross(z, x), z), axis=-1)


def lvlh_rate(position: Vector, velocity: Vector, acceleration: Vector) -> Vector:
    """The LVLH frame's angular velocity ω (…, 3) (LVLH components, rad/s) of chiefs at
    inertial ``(r, v)`` with acceleration ``a`` (m/s²), each (…, 3)."""
    r = np.linalg.norm(position, axis=-1)
    h_vector = cross(position, velocity)
    h = np.linalg.norm(h_vector, axis=-1)
    normal_acceleration = np.einsum("...i,...i->...", acceleration, h_vector) / h
    return np.stack((r * normal_acceleration / h, np.zeros_like(r), h / r**2), axis=-1)
