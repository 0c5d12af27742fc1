"""Small geometric helpers shared by the world, messages and plugins.

Conventions: vectors are numpy arrays in metres (or m/s) in the world frame;
quaternions are ``[x, y, z, w]`` (PyBullet's order); spherical coordinates follow the
physics convention of the source thesis: polar angle from +z, azimuth from +x towards +y.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

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


def length(vector: ArrayLike) -> float:
    """Euclidean norm of a vector: the value ``np.linalg.norm`` gives, at a fraction of
    its cost (the control loop takes a few dozen norms per tick)."""
    flat = np.asarray(vector, dtype=float).ravel()
    return math.sqrt(float(flat.dot(flat)))


def row_lengths(vectors: ArrayLike) -> np.ndarray:
    """Euclidean norms along the last axis (taken as floats): ``np.linalg.norm(vectors,
    axis=-1)`` to the bit, without its dispatch."""
    vectors = np.asarray(vectors, dtype=float)
    return np.sqrt(np.add.reduce(vectors * vectors, axis=-1))


def unit(v: ArrayLike, fallback: ArrayLike = (1.0, 0.0, 0.0)) -> Vector:
    """Return ``v`` scaled to unit length, or ``fallback`` when ``v`` is (near) zero."""
    v = np.asarray(v, dtype=float)
    n = length(v)
    return v / n if n > _EPS else np.asarray(fallback, dtype=float)


def clip_norm(vector: ArrayLike, largest: float) -> Vector:
    """``vector`` scaled down, keeping its direction, so its norm is at most ``largest``."""
    vector = np.asarray(vector, dtype=float)
    norm = length(vector)
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
    """Rotate vector ``v`` by unit quaternion ``q = [x, y, z, w]``: ``v + w t + u × t``
    with ``t = 2 u × v`` (one vector in floats, the same operations as for a stack)."""
    q = np.asarray(q, dtype=float)
    v = np.asarray(v, dtype=float)
    if q.shape == (4,) and v.shape == (3,):
        x, y, z, w = q.tolist()
        a, b, c = v.tolist()
        tx, ty, tz = (2.0 * k for k in _cross_floats(x, y, z, a, b, c))
        cx, cy, cz = _cross_floats(x, y, z, tx, ty, tz)
        return np.array((a + w * tx + cx, b + w * ty + cy, c + w * tz + cz))
    u, w = q[:3], q[3]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def cross(a: ArrayLike, b: ArrayLike) -> Vector:
    """Cross product ``a × b`` of 3-vectors (or stacks of them, broadcast).

    Computed with ``numpy.cross``'s own operations (``a₁b₂ − a₂b₁``, …), so the result
    is the same to the bit at a fraction of the cost: in floats for two single vectors,
    one array operation per term for stacks.
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if a.shape == (3,) and b.shape == (3,):
        return np.array(_cross_floats(*a.tolist(), *b.tolist()))
    if a.ndim == 0 or b.ndim == 0 or a.shape[-1] != 3 or b.shape[-1] != 3:
        return np.cross(a, b)  # 2-vectors, and numpy's own errors
    first = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out = np.empty(first.shape + (3,))
    out[..., 0] = first
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


def _cross_floats(
    a0: float, a1: float, a2: float, b0: float, b1: float, b2: float
) -> tuple[float, float, float]:
    """``a × b`` of two 3-vectors given by their components."""
    return (a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0)


_BODY_AXES = np.vstack([np.eye(3), -np.eye(3)])


def facing_axis(q: ArrayLike, direction: ArrayLike) -> Vector:
    """The body axis (±x, ±y or ±z, body frame) that points most nearly along world
    ``direction`` when the body has attitude ``q = [x, y, z, w]``: the side that faces it."""
    in_world = np.array([rotate(q, axis) for axis in _BODY_AXES])
    return _BODY_AXES[int(np.argmax(in_world @ np.asarray(direction, dtype=float)))].copy()


def sight_angle(q: ArrayLike, axis: ArrayLike, direction: ArrayLike) -> float:
    """Angle between body ``axis`` (body frame, any length) turned by attitude ``q`` and
    world ``direction``, rad in [0, π]."""
    facing = unit(rotate(q, axis))
    cosine = float(facing @ unit(direction))
    return float(np.arccos(np.clip(cosine, -1.0, 1.0)))


def quaternion_multiply(p: ArrayLike, q: ArrayLike) -> Vector:
    """Hamilton product ``p ⊗ q`` of quaternions ``[x, y, z, w]`` (rotation q, then p)."""
    p = np.asarray(p, dtype=float)
    q = np.asarray(q, dtype=float)
    pv, pw = p[..., :3], p[..., 3:]
    qv, qw = q[..., :3], q[..., 3:]
    vector = pw * qv + qw * pv + cross(pv, qv)
    scalar = pw * qw - np.sum(pv * qv, axis=-1, keepdims=True)
    return np.concatenate([vector, scalar], axis=-1)


def quaternion_conjugate(q: ArrayLike) -> Vector:
    """Conjugate of quaternion ``[x, y, z, w]`` (the inverse rotation for a unit quaternion)."""
    q = np.asarray(q, dtype=float)
    return np.concatenate([-q[..., :3], q[..., 3:]], axis=-1)


def rotation_vector(q: ArrayLike) -> Vector:
    """Rotation vector (axis times angle, rad) of unit quaternion ``[x, y, z, w]``.

    The angle is taken in ``[0, π]``: ``q`` and ``−q`` give the same vector.
    """
    q = np.asarray(q, dtype=float)
    q = np.where(q[..., 3:] < 0.0, -q, q)
    sine = np.linalg.norm(q[..., :3], axis=-1, keepdims=True)
    angle = 2.0 * np.arctan2(sine, q[..., 3:])
    scale = np.where(sine > _EPS, angle / np.maximum(sine, _EPS), 2.0)
    return q[..., :3] * scale


def quaternion_from_matrix(matrix: ArrayLike) -> Vector:
    """Unit quaternion ``[x, y, z, w]`` of a rotation matrix (3, 3), by Shepperd's method
    (the largest of the four candidate components is computed first, so it is exact
    for every rotation)."""
    m = np.asarray(matrix, dtype=float)
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0.0:
        s = 2.0 * math.sqrt(1.0 + trace)
        q = (m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1], 0.25 * s * s)
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = (0.25 * s * s, m[0, 1] + m[1, 0], m[0, 2] + m[2, 0], m[2, 1] - m[1, 2])
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = (m[0, 1] + m[1, 0], 0.25 * s * s, m[1, 2] + m[2, 1], m[0, 2] - m[2, 0])
    else:
        s = 2.0 * math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = (m[0, 2] + m[2, 0], m[1, 2] + m[2, 1], 0.25 * s * s, m[1, 0] - m[0, 1])
    quaternion = np.array(q) / s
    return quaternion / np.linalg.norm(quaternion)


def quaternion_from_rotation_vector(r: ArrayLike) -> Vector:
    """Unit quaternion ``[x, y, z, w]`` of rotation vector(s) ``r`` (..., 3) (axis times
    angle, rad); the inverse of :func:`rotation_vector` for angles up to π."""
    r = np.asarray(r, dtype=float)
    angle = np.linalg.norm(r, axis=-1, keepdims=True)
    half = 0.5 * angle
    scale = np.where(angle > _EPS, np.sin(half) / np.maximum(angle, _EPS), 0.5)
    return np.concatenate([scale * r, np.cos(half)], axis=-1)


def slerp(q0: ArrayLike, q1: ArrayLike, fraction: ArrayLike) -> Vector:
    """Spherical linear interpolation between unit quaternions, along the shorter arc.

    Parameters
    ----------
    q0, q1 : array_like, shape (..., 4)
        Start and end attitudes ``[x, y, z, w]``.
    fraction : array_like, shape (...)
        0 gives ``q0``, 1 gives ``q1``.

    Returns
    -------
    ndarray, shape (..., 4)
        Unit quaternions.
    """
    q0 = np.asarray(q0, dtype=float)
    q1 = np.asarray(q1, dtype=float)
    s = np.asarray(fraction, dtype=float)[..., None]
    dot = np.sum(q0 * q1, axis=-1, keepdims=True)
    q1 = np.where(dot < 0.0, -q1, q1)
    dot = np.abs(dot)
    theta = np.arccos(np.clip(dot, -1.0, 1.0))
    sin_theta = np.sin(theta)
    near = sin_theta < 1e-9
    safe = np.where(near, 1.0, sin_theta)
    w0 = np.where(near, 1.0 - s, np.sin((1.0 - s) * theta) / safe)
    w1 = np.where(near, s, np.sin(s * theta) / safe)
    q = w0 * q0 + w1 * q1
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def combined_inertia(
    parts: Sequence[tuple[float, ArrayLike, ArrayLike]],
) -> tuple[Vector, np.ndarray]:
    """Centre of mass and inertia of rigidly joined bodies (the parallel-axis theorem).

    Parameters
    ----------
    parts : sequence of (float, array_like (3,), array_like (3, 3))
        Each body's mass (kg), centre of mass (m) and inertia about it (kg·m²), all in
        one frame.

    Returns
    -------
    centre : ndarray (3,)
        The whole's centre of mass, m, same frame.
    inertia : ndarray (3, 3)
        The whole's inertia about ``centre``, kg·m², same frame's axes.
    """
    masses = np.array([m for m, _, _ in parts], dtype=float)
    centres = np.array([c for _, c, _ in parts], dtype=float)
    centre = masses @ centres / masses.sum()
    inertia = np.array([i for _, _, i in parts], dtype=float).sum(axis=0)
    for mass, offset in zip(masses, centres - centre, strict=True):
        inertia += mass * (offset @ offset * np.eye(3) - np.outer(offset, offset))
    return centre, inertia


def attitude_error(
    attitude: Sequence[float] | np.ndarray, reference: Sequence[float] | np.ndarray
) -> float:
    """Angle of the rotation from ``attitude`` to ``reference``, rad in ``[0, π]``.

    The angle of ``reference ⊗ attitude⁻¹`` from its vector and scalar parts (with
    ``atan2``, exact near zero), in scalar arithmetic: it is evaluated every tick.

    Parameters
    ----------
    attitude, reference : sequence of float or ndarray (4,)
        Unit quaternions ``[x, y, z, w]``.
    """
    x, y, z, w = (float(v) for v in attitude)
    a, b, c, d = (float(v) for v in reference)
    vector = (
        w * a - d * x - (b * z - c * y),
        w * b - d * y - (c * x - a * z),
        w * c - d * z - (a * y - b * x),
    )
    scalar = d * w + a * x + b * y + c * z
    return 2.0 * math.atan2(math.hypot(*vector), abs(scalar))
