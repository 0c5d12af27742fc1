"""PyBullet bodies of a world's objects: static while free, dynamic once carried.

Each body has its object's true shape: a sphere, a box (``GEOM_BOX``, half extents) or
a cylinder (``GEOM_CYLINDER``, its axis the body z axis), turned by the shape's fixed
orientation wherever it is placed. :func:`create_body` makes the free flyer's sphere
too.

Every body has collision filtering off: contacts are detected by closest-point queries
(:func:`surface_gap`), never resolved, so bodies pass through each other. Free objects
of one shape (kind and dimensions) share one static body, moved to an object's model
pose only when a query about that object needs it (:meth:`ObjectBodies.place`): a
PyBullet step costs about 50 ns for every body in the world, even a static one that
collides with nothing, so a field of a thousand spheres of one size steps as fast as one
of a single sphere. A grabbed target gets a dynamic body of its own, of its mass.
"""

from __future__ import annotations

import numpy as np

from dcsim.messages import Shape, ShapeKind
from dcsim.world.objects import ObjectField
from dcsim.world.pybullet_client import MAX_SPEED, pb


def create_body(client: int, shape: Shape, mass: float, position: np.ndarray, maximal: bool) -> int:
    """A body of ``shape`` without collision response.

    Parameters
    ----------
    client : int
        PyBullet client id.
    shape : Shape
        Sphere, box or cylinder; its orientation is the body's initial orientation.
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
    body = pb.createMultiBody(
        baseMass=mass,
        baseCollisionShapeIndex=_collision_shape(client, shape),
        basePosition=position.tolist(),
        baseOrientation=shape.orientation.tolist(),
        useMaximalCoordinates=maximal,
        physicsClientId=client,
    )
    pb.setCollisionFilterGroupMask(body, -1, 0, 0, physicsClientId=client)
    if shape.kind is not ShapeKind.SPHERE:
        # Bullet rounds a box's or a cylinder's edges by its collision margin (1 mm by
        # default); without it their closest points are exact (to ~1e-7 m on curved faces).
        pb.changeDynamics(body, -1, collisionMargin=0.0, physicsClientId=client)
    if mass > 0:
        pb.changeDynamics(
            body,
            -1,
            linearDamping=0,
            angularDamping=0,
            maxJointVelocity=MAX_SPEED,
            physicsClientId=client,
        )
    return body


def _collision_shape(client: int, shape: Shape) -> int:
    """PyBullet collision shape of ``shape`` (a cylinder's axis is its local z)."""
    if shape.kind is ShapeKind.BOX:
        return pb.createCollisionShape(
            pb.GEOM_BOX, halfExtents=shape.half_extents.tolist(), physicsClientId=client
        )
    if shape.kind is ShapeKind.CYLINDER:
        return pb.createCollisionShape(
            pb.GEOM_CYLINDER, radius=shape.radius, height=shape.height, physicsClientId=client
        )
    return pb.createCollisionShape(pb.GEOM_SPHERE, radius=shape.radius, physicsClientId=client)


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
    """The PyBullet body each space object is queried with, by the object's index in the
    field.

    Parameters
    ----------
    client : int
        PyBullet client id.
    field : ObjectField
        The objects; those of one shape share a static body.

    Attributes
    ----------
    ids : list of int
        Body id of each object: the static body of its shape, or a carried target's own
        dynamic body once grabbed.
    """

    def __init__(self, client: int, field: ObjectField) -> None:
        self._client = client
        self._field = field
        self._orientations = [obj.shape.orientation.tolist() for obj in field.objects]
        shared: dict[tuple[object, ...], int] = {}
        self.ids = [self._shape_body(shared, obj.shape) for obj in field.objects]

    def _shape_body(self, shared: dict[tuple[object, ...], int], shape: Shape) -> int:
        """The static body ``shared`` holds for ``shape``'s kind and dimensions, created
        on first use."""
        key = (shape.kind, shape.radius, shape.height, *shape.half_extents.tolist())
        if key not in shared:
            shared[key] = create_body(self._client, shape, 0.0, np.zeros(3), True)
        return shared[key]

    def place(self, index: int, time: float) -> int:
        """Move free object ``index``'s static body to its model pose at ``time`` (s), for
        a query about that object (another of its shape may be placed there next).

        Returns
        -------
        int
            The body id.
        """
        body = self.ids[index]
        position = self._field.objects[index].motion.state_at(time)[0]
        pb.resetBasePositionAndOrientation(
            body, position.tolist(), self._orientations[index], physicsClientId=self._client
        )
        return body

    def make_dynamic(self, index: int, position: np.ndarray, velocity: np.ndarray) -> int:
        """Give object ``index`` a dynamic body of its own, of its mass and shape, in place
        of its shape's static one.

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
        obj = self._field.objects[index]
        body = create_body(self._client, obj.shape, obj.mass, position, False)
        pb.resetBaseVelocity(body, velocity.tolist(), [0, 0, 0], physicsClientId=self._client)
        self.ids[index] = body
        return body
