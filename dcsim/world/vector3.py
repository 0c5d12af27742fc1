"""3-vectors and rotations in plain floats, for the arithmetic of every physics step.

At this size a numpy call costs more than the sums it does: the reaction wheels' step
and the thrusters' per-step turn into the world frame use these instead (a wheel step
takes a quarter of the time its numpy form took).
"""

from __future__ import annotations

import math

Vec = tuple[float, float, float]
"""A 3-vector in plain floats."""

Matrix = tuple[float, ...]
"""A 3×3 rotation matrix as nine floats, row by row (PyBullet's
``getMatrixFromQuaternion``)."""


def turn(m: Matrix, v: Vec) -> Vec:
    """``M v``."""
    x, y, z = v
    return (
        m[0] * x + m[1] * y + m[2] * z,
        m[3] * x + m[4] * y + m[5] * z,
        m[6] * x + m[7] * y + m[8] * z,
    )


def turn_back(m: Matrix, v: Vec) -> Vec:
    """``Mᵀ v``."""
    x, y, z = v
    return (
        m[0] * x + m[3] * y + m[6] * z,
        m[1] * x + m[4] * y + m[7] * z,
        m[2] * x + m[5] * y + m[8] * z,
    )


def cross(a: Vec, b: Vec) -> Vec:
    """``a × b``."""
    ax, ay, az = a
    bx, by, bz = b
    return (ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx)


def rotated(rotation_vector: Vec, v: Vec) -> Vec:
    """``v`` turned by a rotation vector (axis times angle, rad), by Rodrigues' formula."""
    x, y, z = rotation_vector
    angle = math.sqrt(x * x + y * y + z * z)
    if angle == 0.0:
        return v
    k = (x / angle, y / angle, z / angle)
    c, s = math.cos(angle), math.sin(angle)
    across = cross(k, v)
    along = (k[0] * v[0] + k[1] * v[1] + k[2] * v[2]) * (1.0 - c)
    return (
        v[0] * c + across[0] * s + k[0] * along,
        v[1] * c + across[1] * s + k[1] * along,
        v[2] * c + across[2] * s + k[2] * along,
    )


Quaternion = tuple[float, float, float, float]
"""A quaternion ``[x, y, z, w]`` in plain floats."""


def compose(p: Quaternion, q: Quaternion) -> Quaternion:
    """The rotation ``q`` then ``p`` (the Hamilton product ``p ⊗ q``), in double precision
    (PyBullet's ``multiplyTransforms`` rounds to about 1e-7)."""
    px, py, pz, pw = p
    qx, qy, qz, qw = q
    return (
        pw * qx + px * qw + py * qz - pz * qy,
        pw * qy - px * qz + py * qw + pz * qx,
        pw * qz + px * qy - py * qx + pz * qw,
        pw * qw - px * qx - py * qy - pz * qz,
    )
