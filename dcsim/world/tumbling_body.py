"""A free rigid body that tumbles torque-free until the gripper holds it (a capture target).

The body is a PyBullet multibody of its mass and full inertia: its shape (box or
cylinder) and its grapple bar are one compound collision shape that collides with the
gripper only. While nothing touches it, its rotation is dcsim's own torque-free
propagation (:class:`~dcsim.torque_free.TorqueFreeRotation`, fourth-order accurate;
PyBullet's first-order integrator drifts far beyond the 1e-6 rad over 60 s that
``tests/world/test_capture_world.py`` holds the world to) and its
centre of mass moves in a straight line; the PyBullet body is put on that state before
every physics step. From the first physics step in which the gripper touches it,
PyBullet integrates it with the contact forces, and does so for the rest of the run.

PyBullet keeps a body's frame at its principal axes of inertia: the body frame of the
scenario (the shape's axes) is turned from it by a fixed rotation, which this module
applies both ways, so everything it reports is in the scenario's body frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dcsim.geometry import quaternion_between, quaternion_from_matrix, unit
from dcsim.robots.kinematics import rotation_matrix
from dcsim.scenario.model import TumblingBodySpec
from dcsim.torque_free import TorqueFreeRotation
from dcsim.world.gripper import ARM_GROUP, GRIPPER_GROUP, TUMBLING_GROUP
from dcsim.world.pybullet_client import MAX_SPEED, pb
from dcsim.world.vector3 import compose


@dataclass(frozen=True)
class BodyState:
    """A tumbling body's true state at one instant (world frame, SI).

    Attributes
    ----------
    position, velocity : ndarray (3,)
        Centre of mass, m and m/s.
    attitude : ndarray (4,)
        Body-to-world rotation ``[x, y, z, w]``.
    angular_velocity : ndarray (3,)
        rad/s.
    fixture : ndarray (3,)
        The grapple bar's centre, m.
    fixture_velocity : ndarray (3,)
        Its velocity, m/s.
    approach_axis, bar_axis : ndarray (3,)
        The fixture's unit axes now.
    """

    position: np.ndarray
    velocity: np.ndarray
    attitude: np.ndarray
    angular_velocity: np.ndarray
    fixture: np.ndarray
    fixture_velocity: np.ndarray
    approach_axis: np.ndarray
    bar_axis: np.ndarray


class TumblingBody:
    """A tumbling body in a PyBullet world.

    Parameters
    ----------
    client : int
        PyBullet client id.
    spec : TumblingBodySpec
        The scenario's body; it starts at its state at t = 0.
    physics_step : float
        The world's physics step, s.

    Attributes
    ----------
    body : int
        The PyBullet body id.
    free : bool
        Whether the body still follows its torque-free motion (nothing has touched it).
    mass : float
        kg.
    inertia : ndarray (3, 3)
        Inertia tensor about the centre of mass, body axes, kg·m².
    """

    def __init__(self, client: int, spec: TumblingBodySpec, physics_step: float) -> None:
        self._client, self.spec, self._dt = client, spec, physics_step
        self.mass = spec.mass
        self.inertia = spec.inertia_tensor()
        moments, axes = np.linalg.eigh(self.inertia)
        if np.linalg.det(axes) < 0:
            axes[:, 2] = -axes[:, 2]
        self._principal = axes  # principal frame to body frame
        x, y, z, w = quaternion_from_matrix(axes).tolist()
        self._principal_turn = (x, y, z, w)
        attitude = spec.unit_attitude()
        rotation = rotation_matrix(attitude)
        omega = rotation @ np.radians(np.array(spec.angular_velocity_deg_s))
        self.rotation = TorqueFreeRotation(self.inertia, attitude, omega)
        self._position = np.array(spec.position, dtype=float)
        self._velocity = np.array(spec.velocity, dtype=float)
        self._time = 0.0
        self.body = self._create(moments)
        self.free = True
        self._place()

    def _create(self, moments: np.ndarray) -> int:
        """The PyBullet body, its frame on the principal axes, colliding with the gripper."""
        client, spec = self._client, self.spec
        to_principal = self._principal.T
        shape = spec.shape
        fixture = spec.fixture
        bar_rotation = _bar_rotation(np.array(fixture.bar_axis, dtype=float))
        if shape.type == "box":
            kind, radius, half_extents, length = pb.GEOM_BOX, 0.0, list(shape.half_extents), 0.0
        else:
            kind, radius, half_extents, length = (
                pb.GEOM_CYLINDER,
                shape.radius,
                [0.0] * 3,
                shape.height,
            )
        collision = pb.createCollisionShapeArray(
            shapeTypes=[kind, pb.GEOM_CYLINDER],
            radii=[radius, fixture.radius],
            halfExtents=[half_extents, [0.0, 0.0, 0.0]],
            lengths=[length, fixture.length],
            collisionFramePositions=[
                [0.0, 0.0, 0.0],
                (to_principal @ np.array(fixture.position)).tolist(),
            ],
            collisionFrameOrientations=[
                quaternion_from_matrix(to_principal).tolist(),
                quaternion_from_matrix(to_principal @ bar_rotation).tolist(),
            ],
            physicsClientId=client,
        )
        body = pb.createMultiBody(
            baseMass=self.mass, baseCollisionShapeIndex=collision, physicsClientId=client
        )
        pb.changeDynamics(
            body,
            -1,
            linearDamping=0.0,
            angularDamping=0.0,
            localInertiaDiagonal=moments.tolist(),
            maxJointVelocity=MAX_SPEED,
            physicsClientId=client,
        )
        pb.setCollisionFilterGroupMask(
            body, -1, TUMBLING_GROUP, GRIPPER_GROUP | ARM_GROUP, physicsClientId=client
        )
        return body

    # ------------------------------------------------------------------ stepping
    def _place(self) -> None:
        """Put the PyBullet body on the torque-free state now."""
        client = self._client
        attitude = compose(self.rotation.attitude, self._principal_turn)
        pb.resetBasePositionAndOrientation(
            self.body, self._position.tolist(), attitude, physicsClientId=client
        )
        pb.resetBaseVelocity(
            self.body,
            self._velocity.tolist(),
            list(self.rotation.angular_velocity),
            physicsClientId=client,
        )

    def after_step(self, touched: bool) -> None:
        """Follow one physics step: while free and untouched, move on the torque-free
        motion (PyBullet's own step of the body is replaced); once ``touched``, leave the
        body to PyBullet from now on."""
        if not self.free:
            return
        if touched:
            self.free = False
            return
        self._time += self._dt
        self._position = self._position + self._dt * self._velocity
        self.rotation.advance(self._dt)
        self._place()

    # ------------------------------------------------------------------ state
    def state(self) -> BodyState:
        """The body's true state now."""
        client = self._client
        position, principal = pb.getBasePositionAndOrientation(self.body, physicsClientId=client)
        velocity, angular = pb.getBaseVelocity(self.body, physicsClientId=client)
        rotation = rotation_matrix(principal) @ self._principal.T
        omega = np.array(angular)
        fixture = self.spec.fixture
        offset = rotation @ np.array(fixture.position)
        return BodyState(
            position=np.array(position),
            velocity=np.array(velocity),
            attitude=quaternion_from_matrix(rotation),
            angular_velocity=omega,
            fixture=np.array(position) + offset,
            fixture_velocity=np.array(velocity) + np.cross(omega, offset),
            approach_axis=unit(rotation @ np.array(fixture.approach_axis)),
            bar_axis=unit(rotation @ np.array(fixture.bar_axis)),
        )


def _bar_rotation(axis: np.ndarray) -> np.ndarray:
    """A rotation taking z (a PyBullet cylinder's axis) onto ``axis``."""
    return rotation_matrix(quaternion_between([0.0, 0.0, 1.0], axis))
