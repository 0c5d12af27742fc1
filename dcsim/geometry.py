"""Small geometric helpers shared by the world, messages and plugins.

Conventions: vectors are numpy arrays in metres (or m/s) in the world frame;
quaternions are ``[x, y, z, w]`` (PyBullet's order); spherical coordinates follow the
physics convention of the source thesis: polar angle from +z, azimuth from +x towards +y.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

Vector = NDArray[np.float64]

_EPS = 1e-12


def spherical_to_cartesian(r: ArrayLike, polar_deg: ArrayLike, azimuth_deg: ArrayLike) -> Vector:
    """Convert spherical coordinates to Cartesian.

    Parameters
    ----------
    r : array_like
        Radial distance, m.
    polar_deg : array_like
        Polar angle from +z, degrees.
    azimuth_deg : array_like
        Azimuth from +x towards +y, degrees.

    Returns
    -------
    ndarray, shape (..., 3)
        Position, m.
    """
    r = np.asarray(r, dtype=float)
    theta = np.radians(polar_deg)
    phi = np.radians(azimuth_deg)
    return np.stack(
        [r * np.sin(theta) * np.cos(phi), r * np.sin(theta) * np.sin(phi), r * np.cos(theta)],
        axis=-1,
    )


def unit(v: ArrayLike, fallback: ArrayLike = (1.0, 0.0, 0.0)) -> Vector:
    """Return ``v`` scaled to unit length, or ``fallback`` when ``v`` is (near) zero."""
    v = np.asarray(v, dtype=float)
    n = np.linalg.norm(v)
    return v / n if n > _EPS else np.asarray(fallback, dtype=float)


def clip_norm(vector: ArrayLike, largest: float) -> Vector:
    """``vector`` scaled down, keeping its direction, so its norm is at most ``largest``."""
    vector = np.asarray(vector, dtype=float)
    norm = float(np.linalg.norm(vector))
    return vector * (largest / norm) if norm > largest else vector


def quaternion_between(a: ArrayLike, b: ArrayLike) -> Vector:
    """Shortest rotation taking direction ``a`` onto direction ``b``.

    Parameters
    ----------
    a, b : array_like, shape (3,)
        Directions (need not be unit length, must be non-zero).

    Returns
    -------
    ndarray, shape (4,)
        Unit quaternion ``[x, y, z, w]``. For opposite directions the rotation is half a
        turn about an axis perpendicular to ``a``.
    """
    a, b = unit(a), unit(b)
    d = float(np.dot(a, b))
    if d < -1.0 + 1e-9:
        axis = np.cross(a, [1.0, 0.0, 0.0])
        if np.linalg.norm(axis) < 1e-6:
            axis = np.cross(a, [0.0, 1.0, 0.0])
        return np.append(unit(axis), 0.0)
    q = np.append(np.cross(a, b), 1.0 + d)
    return q / np.linalg.norm(q)


def rotate(q: ArrayLike, v: ArrayLike) -> Vector:
    """Rotate vector ``v`` by unit quaternion ``q = [x, y, z, w]``."""
    q = np.asarray(q, dtype=float)
    v = np.asarray(v, dtype=float)
    u, w = q[:3], q[3]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)
