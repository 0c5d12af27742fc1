"""The payload: space objects held rigidly by the robot.

An object attached to the robot gets a dynamic body of its mass and shape, held where it
is by a fixed constraint, and moves with the robot; it feels orbital forces and
collides as part of the robot's assembly. The world keeps the payload; missions decide
when an object is attached and when the payload leaves the world (the debris mission's
grab and release, :mod:`dcsim.missions.debris.services`).
"""

from __future__ import annotations

import numpy as np

from dcsim.world.bodies import ObjectBodies
from dcsim.world.objects import ObjectField, ObjectStatus
from dcsim.world.pybullet_client import pb

_CONSTRAINT_FORCE = 1e9  # N; an attached object must not slip


class Payload:
    """The objects the robot holds.

    Parameters
    ----------
    client : int
        PyBullet client id.
    robot_body : int
        The robot's body id (objects are fixed to its base).
    robot_radius : float
        Radius of the robot's bounding sphere, m.
    field : ObjectField
        The world's objects (their status changes here).
    bodies : ObjectBodies
        The objects' bodies (an attached object's becomes dynamic).

    Attributes
    ----------
    held : dict of int to (int, int)
        Object index of each object held to its body and constraint ids.
    protrusion : float
        How far the held objects' bounding spheres reach beyond the robot's bounding
        sphere, m (0 if none).
    changes : int
        Attachments and removals so far (each changes the robot's mass and shape).
    """

    def __init__(
        self,
        client: int,
        robot_body: int,
        robot_radius: float,
        field: ObjectField,
        bodies: ObjectBodies,
    ) -> None:
        self._client = client
        self._robot_body = robot_body
        self._radius = robot_radius
        self._field = field
        self._bodies = bodies
        self.held: dict[int, tuple[int, int]] = {}
        self.protrusion = 0.0
        self.changes = 0

    @property
    def mass(self) -> float:
        """Mass of the objects held, kg."""
        return sum(self._field.objects[i].mass for i in self.held)

    def spheres(self) -> list[tuple[np.ndarray, float]]:
        """Centre (m, world frame) and bounding-sphere radius (m) of every object held."""
        spheres = []
        for index, (body, _) in self.held.items():
            p, _ = pb.getBasePositionAndOrientation(body, physicsClientId=self._client)
            spheres.append((np.array(p), self._field.objects[index].radius))
        return spheres

    def parts(self) -> list[tuple[float, np.ndarray, np.ndarray]]:
        """Every object held as a uniform solid of its shape: mass (kg), centre (3,) and
        inertia (3, 3) about that centre, world frame, m and kg·m²."""
        parts = []
        for index, (body, _) in self.held.items():
            obj = self._field.objects[index]
            p, q = pb.getBasePositionAndOrientation(body, physicsClientId=self._client)
            # the body's attitude is its shape's (bodies.create_body)
            rotation = np.reshape(pb.getMatrixFromQuaternion(q), (3, 3))
            inertia = rotation @ np.diag(obj.shape.moments_of_inertia(obj.mass)) @ rotation.T
            parts.append((obj.mass, np.array(p), inertia))
        return parts

    def remove_all(self) -> tuple[int, ...]:
        """Take every object held out of the world (its status becomes removed).

        Returns
        -------
        tuple of int
            Ids of the objects removed, in the order they were attached.
        """
        removed = []
        for index, (body, constraint) in self.held.items():
            pb.removeConstraint(constraint, physicsClientId=self._client)
            pb.removeBody(body, physicsClientId=self._client)
            self._field.set_status(index, ObjectStatus.REMOVED)
            removed.append(self._field.objects[index].id)
        self.held.clear()
        self.protrusion = 0.0
        self.changes += 1
        return tuple(removed)

    def attach(self, index: int, time: float, position: np.ndarray, attitude: np.ndarray) -> None:
        """Hold free object ``index`` as it is at ``time`` (s), fixed to the robot's base.

        Parameters
        ----------
        index : int
            The object's index in the field.
        time : float
            Now, s.
        position, attitude : ndarray
            The robot base's position (m) and attitude ``[x, y, z, w]`` now, world frame.
        """
        obj = self._field.objects[index]
        at, velocity = (a.copy() for a in obj.motion.state_at(time))
        body = self._bodies.make_dynamic(index, at, velocity)
        inverse = pb.invertTransform(position.tolist(), attitude.tolist())
        local_position, local_attitude = pb.multiplyTransforms(
            inverse[0], inverse[1], at.tolist(), obj.shape.orientation.tolist()
        )
        constraint = pb.createConstraint(
            self._robot_body,
            -1,
            body,
            -1,
            pb.JOINT_FIXED,
            [0, 0, 0],
            parentFramePosition=local_position,
            childFramePosition=[0, 0, 0],
            parentFrameOrientation=local_attitude,
            physicsClientId=self._client,
        )
        pb.changeConstraint(constraint, maxForce=_CONSTRAINT_FORCE, physicsClientId=self._client)
        self.held[index] = (body, constraint)
        self.protrusion = self._measure_protrusion(position)
        self.changes += 1
        self._field.set_status(index, ObjectStatus.CARRIED)

    def _measure_protrusion(self, centre: np.ndarray) -> float:
        radius = self._radius
        return max(
            (float(np.linalg.norm(c - centre)) + r - radius for c, r in self.spheres()), default=0.0
        )
