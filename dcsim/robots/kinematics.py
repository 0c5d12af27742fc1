"""Kinematics of a DH space manipulator in the world frame: every frame, joint axis and
link centre of mass (the thesis's eqs 3.1–3.6 and 3.10), and the link Jacobians (eqs
4.18 and 4.20) the dynamics are built from.

State convention: ``q = [r_b (3), quaternion x, y, z, w (4), θ (n)]`` with ``r_b`` the
base's centre of mass in the world, m, the quaternion the base's attitude (base to
world) and ``θ`` the joint angles, rad.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dcsim.robots.dh import DHRobot

Array = NDArray[np.float64]


def skew(v: ArrayLike) -> Array:
    """Cross-product matrices ``[v×]`` (eq. 3.9) of vectors ``v`` (..., 3) → (..., 3, 3)."""
    v = np.asarray(v, dtype=float)
    out = np.zeros(v.shape + (3,))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


def cross(a: Array, b: Array) -> Array:
    """``a × b`` over the last axis, broadcasting (numpy's ``cross`` without its overhead)."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


def rotation_matrix(quaternion: ArrayLike) -> Array:
    """Rotation matrix (body to world) of a quaternion ``[x, y, z, w]``, normalised first."""
    x, y, z, w = np.asarray(quaternion, dtype=float) / np.linalg.norm(quaternion)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


@dataclass(frozen=True)
class DHArrays:
    """A :class:`DHRobot`'s numbers as arrays (n links), for vectorised kinematics."""

    a: Array
    alpha: Array
    d: Array
    theta_offset: Array
    masses: Array
    moments: Array  # (n, 3) principal moments in frame i, kg·m²
    mount: Array
    base_mass: float
    base_moments: Array
    lower: Array  # (n, n) True where link i moves with joint j (j ≤ i)

    @classmethod
    def of(cls, robot: DHRobot) -> DHArrays:
        """Arrays of ``robot``."""
        n = robot.n_joints
        return cls(
            a=robot.column("a"),
            alpha=robot.column("alpha"),
            d=robot.column("d"),
            theta_offset=robot.column("theta_offset"),
            masses=robot.column("mass"),
            moments=np.array([link.inertia for link in robot.links]),
            mount=np.array(robot.base.mount, dtype=float),
            base_mass=float(robot.base.mass),
            base_moments=np.array(robot.base.inertia, dtype=float),
            lower=np.tril(np.ones((n, n), dtype=bool)),
        )


@dataclass(frozen=True)
class Kinematics:
    """Every world-frame quantity of one configuration (n joints).

    Attributes
    ----------
    base_position : ndarray (3,)
        Base centre of mass ``r_b``, m.
    base_rotation : ndarray (3, 3)
        Base attitude, base to world.
    rotations : ndarray (n + 1, 3, 3)
        ``R_i``: DH frames 0 … n, frame to world.
    origins : ndarray (n + 1, 3)
        ``p_i``: origins of DH frames 0 … n, m; ``origins[n]`` is the end effector.
    axes : ndarray (n, 3)
        ``k̂_i``: unit axis of joint i (``z_{i−1}``).
    joint_points : ndarray (n, 3)
        A point on joint i's axis (the origin of frame ``i − 1``), m.
    coms : ndarray (n, 3)
        Link centres of mass, m.
    inertias : ndarray (n, 3, 3)
        Link inertia tensors about their centres of mass, world axes, kg·m².
    base_inertia : ndarray (3, 3)
        Base inertia tensor about its centre of mass, world axes, kg·m².
    """

    base_position: Array
    base_rotation: Array
    rotations: Array
    origins: Array
    axes: Array
    joint_points: Array
    coms: Array
    inertias: Array
    base_inertia: Array

    @property
    def end_effector(self) -> Array:
        """End-effector position (origin of frame n), m."""
        return self.origins[-1]


def dh_transforms(dh: DHArrays, theta: Array) -> tuple[Array, Array]:
    """Rotations ``R_i^{i−1}`` (n, 3, 3) and translations ``p_i^{i−1}`` (n, 3) of eq. 3.2."""
    angle = theta + dh.theta_offset
    ct, st, ca, sa = np.cos(angle), np.sin(angle), np.cos(dh.alpha), np.sin(dh.alpha)
    rot = np.empty((angle.size, 3, 3))
    rot[:, 0, 0], rot[:, 0, 1], rot[:, 0, 2] = ct, -st * ca, st * sa
    rot[:, 1, 0], rot[:, 1, 1], rot[:, 1, 2] = st, ct * ca, -ct * sa
    rot[:, 2, 0], rot[:, 2, 1], rot[:, 2, 2] = 0.0, sa, ca
    translation = np.empty((angle.size, 3))
    translation[:, 0], translation[:, 1], translation[:, 2] = dh.a * ct, dh.a * st, dh.d
    return rot, translation


def split_state(q: ArrayLike, n: int) -> tuple[Array, Array, Array]:
    """``(r_b, quaternion, θ)`` of a state ``q`` (7 + n,)."""
    q = np.asarray(q, dtype=float)
    if q.shape != (7 + n,):
        raise ValueError(f"q must have 7 + {n} = {7 + n} entries, got shape {q.shape}")
    return q[:3], q[3:7], q[7:]


def kinematics(dh: DHArrays, q: ArrayLike) -> Kinematics:
    """World-frame kinematics of state ``q`` (eqs 3.1–3.6, 3.10)."""
    n = dh.a.size
    r_b, quaternion, theta = split_state(q, n)
    base_rotation = rotation_matrix(quaternion)
    local_rot, local_p = dh_transforms(dh, theta)
    rotations = np.empty((n + 1, 3, 3))
    origins = np.empty((n + 1, 3))
    rotations[0], origins[0] = base_rotation, r_b + base_rotation @ dh.mount
    for i in range(n):
        origins[i + 1] = origins[i] + rotations[i] @ local_p[i]
        rotations[i + 1] = rotations[i] @ local_rot[i]
    inertias = np.einsum("iab,ib,icb->iac", rotations[1:], dh.moments, rotations[1:])
    return Kinematics(
        base_position=r_b,
        base_rotation=base_rotation,
        rotations=rotations,
        origins=origins,
        axes=rotations[:-1, :, 2],
        joint_points=origins[:-1],
        coms=0.5 * (origins[:-1] + origins[1:]),
        inertias=inertias,
        base_inertia=(base_rotation * dh.base_moments) @ base_rotation.T,
    )


def point_jacobians(kin: Kinematics, points: Array, lower: Array) -> Array:
    """Translational Jacobians ``J_T`` (eq. 4.18) of points fixed on links: (m, 3, n).

    ``points`` (m, 3) lies on the links whose rows of ``lower`` (m, n) say which joints
    move them.
    """
    arms = points[:, None, :] - kin.joint_points[None, :, :]
    columns = cross(kin.axes[None, :, :], arms) * lower[:, :, None]
    return columns.transpose(0, 2, 1)


def rotation_jacobians(kin: Kinematics, lower: Array) -> Array:
    """Rotational Jacobians ``J_R`` (eq. 4.20) of the links: (n, 3, n)."""
    return (kin.axes[None, :, :] * lower[:, :, None]).transpose(0, 2, 1)
