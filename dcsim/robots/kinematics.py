"""Kinematics of a DH space manipulator in the world frame: every frame, joint axis and
body centre of mass (the thesis's eqs 3.1–3.6 and 3.10), and the Jacobians of the bodies
(eqs 4.18 and 4.20) and of the end effector (eq. 3.8), computed in one compiled pass
(:mod:`dcsim.robots.kernels`, whose docstring gives the formulas).

State convention: ``q = [r_b (3), quaternion x, y, z, w (4), θ (n)]`` with ``r_b`` the
base's centre of mass in the world, m, the quaternion the base's attitude (base to
world) and ``θ`` the joint angles, rad. Velocities: ``qd = [v_b, ω_b, θ̇]`` (eq. 4.4).
Bodies are numbered base first: body 0 is the base, body ``i`` link ``i``.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import ModuleType

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dcsim.robots.dh import DHRobot

Array = NDArray[np.float64]


def compiled() -> ModuleType:
    """:mod:`dcsim.robots.kernels`, imported on first use: loading numba takes a third of
    a second, which commands that never touch a manipulator should not pay."""
    from dcsim.robots import kernels

    return kernels


def rotation_matrix(quaternion: ArrayLike) -> Array:
    """Rotation matrix (body to world) of a quaternion ``[x, y, z, w]``, normalised first."""
    out = np.empty((3, 3))
    compiled().quaternion_rotation(np.array(quaternion, dtype=float), out)
    return out


@dataclass(frozen=True)
class DHArrays:
    """A :class:`DHRobot`'s numbers as the arrays :mod:`dcsim.robots.kernels` reads.

    Attributes
    ----------
    links : ndarray (n, 5)
        Per link: ``a`` (m), ``d`` (m), ``cos α``, ``sin α``, ``θ`` offset (rad).
    bodies : ndarray (n + 1, 4)
        Per body, base first: mass (kg), then the principal moments of inertia (kg·m²)
        along the base's axes (the base) or frame ``i``'s (link ``i``).
    mount : ndarray (3,)
        ``r_q``: origin of frame 0 from the base's centre of mass, base frame, m.
    """

    links: Array
    bodies: Array
    mount: Array

    @classmethod
    def of(cls, robot: DHRobot) -> DHArrays:
        """Arrays of ``robot``."""
        alpha = robot.column("alpha")
        links = np.column_stack(
            [
                robot.column("a"),
                robot.column("d"),
                np.cos(alpha),
                np.sin(alpha),
                robot.column("theta_offset"),
            ]
        )
        masses = [robot.base.mass, *robot.column("mass")]
        moments = [robot.base.inertia, *(link.inertia for link in robot.links)]
        bodies = np.column_stack([masses, moments])
        return cls(links=links, bodies=bodies, mount=np.array(robot.base.mount, dtype=float))

    @property
    def n_joints(self) -> int:
        """Number of joints ``n``."""
        return self.links.shape[0]


@dataclass(frozen=True)
class Kinematics:
    """Every world-frame quantity of one configuration (n joints, bodies base first).

    Attributes
    ----------
    base_position : ndarray (3,)
        Base centre of mass ``r_b``, m.
    rotations : ndarray (n + 1, 3, 3)
        ``R_i``: DH frames 0 … n, frame to world; frame 0 has the base's axes.
    origins : ndarray (n + 1, 3)
        ``p_i``: origins of DH frames 0 … n, m; ``origins[n]`` is the end effector.
    body_coms : ndarray (n + 1, 3)
        Centres of mass of the base (``r_b``) and of the links, m.
    body_inertias : ndarray (n + 1, 3, 3)
        Inertia tensors of the base and the links about their centres of mass, world
        axes, kg·m².
    turn_axes : ndarray (3 + n, 3)
        Unit axis of each turning column of ``qd`` (``ω_b``'s and the joints',
        :mod:`dcsim.robots.kernels`): the world axes, then ``k̂_i``.
    pivots : ndarray (3 + n, 3)
        A point on each of those axes: ``r_b`` three times, then the origins of frames
        0 … n − 1, m.
    body_jacobians : ndarray (n + 1, 6, 6 + n)
        ``[v_i; ω_i] = body_jacobians[i] qd``: centre-of-mass velocity (m/s) and angular
        velocity (rad/s) of each body; the thesis's natural orthogonal complement ``𝒩``
        (eqs 4.27–4.33) with the linear rows first.
    jacobian : ndarray (6, 6 + n)
        The end effector's ``[v_ee; ω_ee] = J qd`` (eq. 3.8).
    """

    base_position: Array
    rotations: Array
    origins: Array
    body_coms: Array
    body_inertias: Array
    turn_axes: Array
    pivots: Array
    body_jacobians: Array
    jacobian: Array

    @property
    def axes(self) -> Array:
        """``k̂_i``: unit axis of joint i, ``z_{i−1}`` (n, 3)."""
        return self.turn_axes[3:]

    @property
    def joint_points(self) -> Array:
        """A point on joint i's axis, the origin of frame ``i − 1`` (n, 3), m."""
        return self.pivots[3:]

    @property
    def coms(self) -> Array:
        """Centres of mass of the links (n, 3), m."""
        return self.body_coms[1:]

    @property
    def end_effector(self) -> Array:
        """End-effector position, the origin of frame n (3,), m."""
        return self.origins[-1]


def state_vector(q: ArrayLike, n: int) -> Array:
    """``q`` (7 + n,) as a new float array.

    Raises
    ------
    ValueError
        If ``q`` does not have ``7 + n`` entries.
    """
    q = np.array(q, dtype=float)
    if q.shape != (7 + n,):
        raise ValueError(f"q must have 7 + {n} = {7 + n} entries, got shape {q.shape}")
    return q


def kinematics(dh: DHArrays, q: ArrayLike) -> Kinematics:
    """World-frame kinematics of state ``q`` (7 + n,) (eqs 3.1–3.6, 3.8, 3.10, 4.18, 4.20)."""
    q = state_vector(q, dh.n_joints)
    return Kinematics(q[:3], *compiled().world_kinematics(q, dh.links, dh.bodies, dh.mount))
