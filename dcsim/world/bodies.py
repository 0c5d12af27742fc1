"""PyBullet bodies of a world: the collector, the objects' static bodies, carried targets.

Every body has collision filtering off: contacts are detected by closest-point queries
(:func:`surface_gap`), never resolved, so bodies pass through each other. A free
object's body is static and is moved to its motion model's position only when a query
needs it (:meth:`ObjectBodies.place`), so a large field costs little; a grabbed target
gets a dynamic body of its mass.
"""

from __future__ import annotations

import numpy as np

from dcsim.scenario.model import RobotSection, point_to_cartesian
from dcsim.world.objects import ObjectField
from dcsim.world.pybullet_client import pb


def create_sphere(
    client: int, radius: float, mass: float, position: np.ndarray, maximal: bool
) -> int:
    """A sphere body without collision response.

    Parameters
    ----------
    client : int
        PyBullet client id.
    radius : float
        m.
    mass : float
        kg; 0 for a static body. A dynamic body gets no damping.
    position : ndarray (3,)
        Initial position, world frame, m.
    maximal : bool
        Use maximal coordinates (cheaper for static bodies).

    Returns
    -------
    int
        The body id.
    """
    shape = pb.createCollisionShape(pb.GEOM_SPHERE, radius=radius, physicsClientId=client)
    body = pb.createMultiBody(
        baseMass=mass,
        baseCollisionShapeIndex=shape,
        basePosition=position.tolist(),
        useMaximalCoordinates=maximal,
        physicsClientId=client,
    )
    pb.setCollisionFilterGroupMask(body, -1, 0, 0, physicsClientId=client)
    if mass > 0:
        pb.changeDynamics(body, -1, linearDamping=0, angularDamping=0, physicsClientId=client)
    return body


def create_collector(client: int, robot: RobotSection) -> int:
    """The collector's sphere body at its initial state (position, attitude, velocities)."""
    initial = robot.initial
    body = create_sphere(
        client, robot.radius, robot.mass, point_to_cartesian(initial.position), False
    )
    attitude = np.asarray(initial.attitude) / np.linalg.norm(initial.attitude)
    pb.resetBasePositionAndOrientation(
        body,
        point_to_cartesian(initial.position).tolist(),
        attitude.tolist(),
        physicsClientId=client,
    )
    pb.resetBaseVelocity(
        body, list(initial.velocity), list(initial.angular_velocity), physicsClientId=client
    )
    return body


def surface_gap(client: int, body_a: int, body_b: int, within: float) -> float:
    """Smallest distance between the surfaces of two bodies, m (negative when they overlap).

    Parameters
    ----------
    client : int
        PyBullet client id.
    body_a, body_b : int
        The bodies, at their current poses.
    within : float
        Largest gap looked for, m.

    Returns
    -------
    float
        The gap, or ``inf`` if it exceeds ``within``.
    """
    points = pb.getClosestPoints(body_a, body_b, within, physicsClientId=client)
    return min((pt[8] for pt in points), default=float("inf"))


class ObjectBodies:
    """The PyBullet body of every space object, by the object's index in the field.

    Parameters
    ----------
    client : int
        PyBullet client id.
    field : ObjectField
        The objects; each gets a static body at its position at t = 0.

    Attributes
    ----------
    ids : list of int
        Body id of each object (a carried target's dynamic body once grabbed).
    """

    def __init__(self, client: int, field: ObjectField) -> None:
        self._client = client
        self._field = field
        self.ids = [
            create_sphere(client, obj.radius, 0.0, field.free_states(0.0)[0][index], True)
            for index, obj in enumerate(field.objects)
        ]

    def place(self, index: int, time: float) -> int:
        """Move free object ``index``'s static body to its model position at ``time`` (s).

        Returns
        -------
        int
            The body id.
        """
        body = self.ids[index]
        position = self._field.objects[index].motion.state_at(time)[0]
        pb.resetBasePositionAndOrientation(
            body, position.tolist(), [0, 0, 0, 1], physicsClientId=self._client
        )
        return body

    def make_dynamic(self, index: int, position: np.ndarray, velocity: np.ndarray) -> int:
        """Replace object ``index``'s static body by a dynamic one of its mass.

        Parameters
        ----------
        index : int
            The object's index in the field.
        position, velocity : ndarray (3,)
            The new body's state, world frame, m and m/s.

        Returns
        -------
        int
            The new body id.
        """
        pb.removeBody(self.ids[index], physicsClientId=self._client)
        obj = self._field.objects[index]
        body = create_sphere(self._client, obj.radius, obj.mass, position, False)
        pb.resetBaseVelocity(body, velocity.tolist(), [0, 0, 0], physicsClientId=self._client)
        self.ids[index] = body
        return body
