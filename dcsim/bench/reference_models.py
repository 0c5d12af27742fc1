"""The space manipulator's model in PyBullet and in Pinocchio: two independent
implementations, both loading the URDF dcsim writes, with the maps between their
coordinates and dcsim's. The model's agreement tests and ``dcsim bench manipulator``
use them.

dcsim's velocity is ``qd = [v_b, ω_b, θ̇]``, world frame (DESIGN.md). PyBullet's is
``[ω_b, v_b, θ̇]`` in the base frame and its inverse dynamics return ``[F_b, M_b, τ]``
in that order and frame; Pinocchio's free flyer's is ``[v_b, ω_b, θ̇]`` in the base
frame. Both orders are ``T qd`` with :func:`bullet_velocity_map` or
:func:`pinocchio_velocity_map`, so a mass matrix maps as ``Tᵀ M T`` and a generalised
force as ``Tᵀ f``.

Pinocchio (the package ``pin``) is a test extra: :data:`pin` is None without it.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from dcsim.robots.kinematics import Array, rotation_matrix
from dcsim.robots.manipulator import ManipulatorModel
from dcsim.world.pybullet_client import connect_direct, load_urdf, pb

try:
    import pinocchio as pin
except ImportError:  # the test extra is not installed
    pin = None

END_EFFECTOR = "end_effector"
"""The name of the URDF's end-effector link and frame."""

Calls = dict[str, Callable[[], object]]
"""One implementation's calls at one state, by quantity, arguments already prepared."""


def random_state(rng: np.random.Generator, n_joints: int) -> tuple[Array, Array]:
    """A random state ``q`` (7 + n,) and velocity ``qd`` (6 + n,): base position and
    velocities standard normal (m, m/s, rad/s), attitude uniform, joints uniform in
    ``[−π, π)`` rad."""
    quaternion = rng.normal(size=4)
    quaternion /= np.linalg.norm(quaternion)
    q = np.concatenate([rng.normal(size=3), quaternion, rng.uniform(-np.pi, np.pi, n_joints)])
    return q, rng.normal(size=6 + n_joints)


def bullet_velocity_map(q: Array) -> Array:
    """``T`` (6 + n, 6 + n) with PyBullet's velocity = ``T qd`` at state ``q``."""
    rotation_t, n = rotation_matrix(q[3:7]).T, q.size - 7
    t = np.zeros((6 + n, 6 + n))
    t[:3, 3:6], t[3:6, :3], t[6:, 6:] = rotation_t, rotation_t, np.eye(n)
    return t


def pinocchio_velocity_map(q: Array) -> Array:
    """``T`` (6 + n, 6 + n) with Pinocchio's velocity = ``T qd`` at state ``q``."""
    rotation_t, n = rotation_matrix(q[3:7]).T, q.size - 7
    t = np.zeros((6 + n, 6 + n))
    t[:3, :3], t[3:6, 3:6], t[6:, 6:] = rotation_t, rotation_t, np.eye(n)
    return t


class BulletModel:
    """A manipulator's multibody in its own PyBullet DIRECT client, without gravity.

    Use it as a context manager (or call :meth:`close`). Its base pose stays the
    identity: PyBullet's mass matrix, inverse dynamics and Jacobian are in the base
    frame and take the joint angles (and the base's velocity) only.

    Parameters
    ----------
    model : ManipulatorModel
        Whose URDF is loaded.
    """

    def __init__(self, model: ManipulatorModel) -> None:
        self.n_joints = model.n_joints
        self.client = connect_direct()
        self.body = load_urdf(self.client, model.urdf())
        self.end_effector_link = pb.getNumJoints(self.body, physicsClientId=self.client) - 1

    def __enter__(self) -> BulletModel:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    def close(self) -> None:
        """Disconnect the client."""
        pb.disconnect(self.client)

    def mass_matrix(self, q: Array) -> Array:
        """``M(q)`` in dcsim's order (6 + n, 6 + n)."""
        theirs = np.array(self.calls(q, np.zeros(6 + self.n_joints))["mass matrix"]())
        t = bullet_velocity_map(q)
        return t.T @ theirs @ t

    def bias(self, q: Array, qd: Array) -> Array:
        """``C(q, q̇) q̇`` in dcsim's order (6 + n,): inverse dynamics at zero acceleration."""
        out = np.asarray(self.calls(q, qd)["bias"]())
        return bullet_velocity_map(q).T @ np.concatenate([out[3:6], out[:3], out[6:]])

    def jacobian(self, q: Array) -> Array:
        """The end effector's ``[v; ω]`` Jacobian in dcsim's frame and order (6, 6 + n)."""
        linear, angular = np.asarray(self.calls(q, np.zeros(6 + self.n_joints))["jacobian"]())
        rotation = rotation_matrix(q[3:7])
        theirs = np.vstack([rotation @ linear, rotation @ angular])
        return theirs @ bullet_velocity_map(q)

    def calls(self, q: Array, qd: Array) -> Calls:
        """PyBullet's own calls at state ``q``, ``qd``: forward kinematics (the state set,
        then the end effector's link state computed), the end effector's Jacobian, the
        mass matrix and the inverse dynamics at zero acceleration (``"bias"``); their
        results are in PyBullet's frames and orders."""
        client, body, n = self.client, self.body, self.n_joints
        angles, zeros, link = q[7:].tolist(), [0.0] * n, self.end_effector_link
        state, velocity = q.tolist(), (bullet_velocity_map(q) @ qd).tolist()
        joints, targets = list(range(n)), [[angle] for angle in angles]

        def forward_kinematics() -> object:
            pb.resetBasePositionAndOrientation(body, state[:3], state[3:7], physicsClientId=client)
            pb.resetJointStatesMultiDof(body, joints, targets, physicsClientId=client)
            return pb.getLinkState(body, link, computeForwardKinematics=1, physicsClientId=client)

        return {
            "forward kinematics": forward_kinematics,
            "jacobian": lambda: pb.calculateJacobian(
                body,
                self.end_effector_link,
                [0.0] * 3,
                angles,
                zeros,
                zeros,
                physicsClientId=client,
            ),
            "mass matrix": lambda: pb.calculateMassMatrix(body, angles, physicsClientId=client),
            "bias": lambda: pb.calculateInverseDynamics(
                body, state, velocity, [0.0] * (6 + n), physicsClientId=client
            ),
        }


class PinocchioModel:
    """A manipulator's model in Pinocchio: a free flyer carrying the URDF's arm, without
    gravity.

    Parameters
    ----------
    model : ManipulatorModel
        Whose URDF is built.

    Raises
    ------
    ModuleNotFoundError
        If Pinocchio is not installed (the ``pin`` package of the test extra).
    """

    def __init__(self, model: ManipulatorModel) -> None:
        if pin is None:
            raise ModuleNotFoundError(
                "Pinocchio is not installed: pip install 'dcsim[test]' (the package 'pin')"
            )
        self.model = pin.buildModelFromXML(model.urdf(), pin.JointModelFreeFlyer())
        self.model.gravity.setZero()
        self.data = self.model.createData()
        self.frame = self.model.getFrameId(END_EFFECTOR)

    def mass_matrix(self, q: Array) -> Array:
        """``M(q)`` in dcsim's order (6 + n, 6 + n) (Pinocchio fills the upper triangle)."""
        theirs = np.asarray(self.calls(q, np.zeros(self.model.nv))["mass matrix"]())
        theirs = np.triu(theirs) + np.triu(theirs, 1).T
        t = pinocchio_velocity_map(q)
        return t.T @ theirs @ t

    def bias(self, q: Array, qd: Array) -> Array:
        """``C(q, q̇) q̇`` in dcsim's order (6 + n,).

        Pinocchio's base velocity is in the turning base frame: zero world acceleration
        is its acceleration ``[−ω × v, 0, 0]`` (local), so ``C q̇`` is the inverse
        dynamics (RNEA) there.
        """
        return pinocchio_velocity_map(q).T @ np.asarray(self.calls(q, qd)["bias"]())

    def jacobian(self, q: Array) -> Array:
        """The end effector's ``[v; ω]`` Jacobian in dcsim's frame and order (6, 6 + n)."""
        theirs = np.asarray(self.calls(q, np.zeros(self.model.nv))["jacobian"]())
        return theirs @ pinocchio_velocity_map(q)

    def end_effector_pose(self, q: Array) -> tuple[Array, Array]:
        """The end effector's position (3,), m, and attitude (3, 3), world frame."""
        self.calls(q, np.zeros(self.model.nv))["forward kinematics"]()
        placement = self.data.oMf[self.frame]
        return placement.translation.copy(), placement.rotation.copy()

    def calls(self, q: Array, qd: Array) -> Calls:
        """Pinocchio's own calls at state ``q``, ``qd``: forward kinematics of every frame,
        the end effector's Jacobian (world-aligned, at the end effector), the mass matrix
        (CRBA), the Coriolis matrix and the velocity-dependent force (``"bias"``, RNEA as
        :meth:`bias` says); their results are in Pinocchio's orders."""
        model, data, frame = self.model, self.data, self.frame
        v = pinocchio_velocity_map(q) @ qd
        acceleration = np.zeros(model.nv)
        acceleration[:3] = -np.cross(v[3:6], v[:3])
        return {
            "forward kinematics": lambda: pin.framesForwardKinematics(model, data, q),
            "jacobian": lambda: pin.computeFrameJacobian(
                model, data, q, frame, pin.LOCAL_WORLD_ALIGNED
            ),
            "mass matrix": lambda: pin.crba(model, data, q),
            "coriolis matrix": lambda: pin.computeCoriolisMatrix(model, data, q, v),
            "bias": lambda: pin.rnea(model, data, q, v, acceleration),
        }
