"""Messages about what the robot senses: space objects, beacon ranges, its own attitude.

They follow the source thesis's topics (Objects, Beacons). Vectors are read-only float
arrays in the world frame; times are scenario seconds; quaternions are ``[x, y, z, w]``.
"""

from __future__ import annotations

import enum

import numpy as np
from numpy.typing import ArrayLike

from dcsim.geometry import Vector
from dcsim.messages.base import Message, array_field, message
from dcsim.motion import LinearMotion, MotionModel


class ObjectKind(enum.StrEnum):
    """What a space object is to the robot."""

    TARGET = "target"
    OBSTACLE = "obstacle"


class ShapeKind(enum.StrEnum):
    """The collision shapes an object may have."""

    SPHERE = "sphere"
    BOX = "box"
    CYLINDER = "cylinder"


@message
class Shape(Message):
    """An object's collision shape, centred on the object's position.

    Attributes
    ----------
    kind : ShapeKind
        Sphere, box or cylinder.
    radius : float
        Radius of a sphere or a cylinder, m.
    half_extents : ndarray (3,)
        Half side lengths of a box along its body axes, m.
    height : float
        Full length of a cylinder along its body z axis, m.
    orientation : ndarray (4,)
        Body-to-world rotation ``[x, y, z, w]`` (fixed while the object moves).
    """

    kind: ShapeKind = ShapeKind.SPHERE
    radius: float = 0.0
    half_extents: Vector = array_field(default=(0.0, 0.0, 0.0))
    height: float = 0.0
    orientation: Vector = array_field(shape=(4,), default=(0.0, 0.0, 0.0, 1.0))

    @property
    def bounding_radius(self) -> float:
        """Radius of the smallest sphere about the centre that holds the shape, m."""
        if self.kind is ShapeKind.BOX:
            return float(np.linalg.norm(self.half_extents))
        if self.kind is ShapeKind.CYLINDER:
            return float(np.hypot(self.radius, 0.5 * self.height))
        return float(self.radius)

    def moments_of_inertia(self, mass: float) -> np.ndarray:
        """Principal moments (3,) of a uniform solid of this shape and ``mass`` (kg) about
        its centre, along its body axes, kg·m² (a cylinder's axis is z)."""
        if self.kind is ShapeKind.BOX:
            squares = (2.0 * np.asarray(self.half_extents, dtype=float)) ** 2
            return mass / 12.0 * (squares.sum() - squares)
        if self.kind is ShapeKind.CYLINDER:
            r2 = self.radius**2
            across = mass * (3.0 * r2 + self.height**2) / 12.0
            return np.array([across, across, 0.5 * mass * r2])
        return np.full(3, 0.4 * mass * self.radius**2)


@message
class ObjectTrack(Message):
    """A space object as the object sensor reports it (the thesis's Objects topic).

    Attributes
    ----------
    id : int
        Unique object identifier.
    kind : ObjectKind
        Target (to collect) or obstacle (to avoid).
    time : float
        Time of the observation, s.
    position, velocity : ndarray (3,)
        Observed state at ``time``, m and m/s.
    mass : float
        Object mass, kg.
    radius : float
        Radius of the object's bounding sphere, m (from ``shape`` when given as 0).
    motion : MotionModel or None
        The object's motion parameters, for prediction; None if unknown, in which case
        prediction assumes constant velocity.
    shape : Shape
        The object's true shape; given as None (the default), a sphere of ``radius``.
    """

    id: int
    kind: ObjectKind
    time: float
    position: Vector = array_field()
    velocity: Vector = array_field()
    mass: float = 0.0
    radius: float = 0.0
    motion: MotionModel | None = None
    # None at construction means a sphere of ``radius``; __post_init__ replaces it, so the
    # attribute is always a Shape (mypy cannot type a field's converter).
    shape: Shape = None  # type: ignore[assignment]

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.shape is None:
            object.__setattr__(self, "shape", Shape(ShapeKind.SPHERE, radius=self.radius))
        elif self.radius == 0.0:
            object.__setattr__(self, "radius", self.shape.bounding_radius)

    def predict(self, t: ArrayLike) -> tuple[Vector, Vector]:
        """Predicted ``(position, velocity)`` at time(s) ``t`` (s), shape ``(..., 3)``."""
        model = self.motion or LinearMotion(self.position, self.velocity, epoch=self.time)
        return model.state_at(t)


@message
class BeaconRange(Message):
    """A measured range to a localisation beacon (the thesis's Beacon topic).

    Attributes
    ----------
    beacon_id : int
        Index of the beacon in the scenario.
    beacon_position : ndarray (3,)
        Known beacon position, m.
    range : float
        Measured distance from the robot to the beacon, m (noisy).
    sigma : float
        Standard deviation of the range noise, m.
    """

    beacon_id: int
    beacon_position: Vector = array_field()
    range: float = 0.0
    sigma: float = 0.0


@message
class Observations(Message):
    """Everything the robot's sensors report at one instant.

    Attributes
    ----------
    time : float
        s.
    ranges : tuple of BeaconRange
        Beacon ranges measured now (possibly none).
    tracks : tuple of ObjectTrack
        Objects within sensor range.
    attitude : ndarray (4,)
        Base attitude from the star tracker, ``[x, y, z, w]``.
    angular_velocity : ndarray (3,)
        Base angular velocity from the gyros, world frame, rad/s.
    joint_positions, joint_velocities : ndarray (n,)
        Joint encoder readings; empty for a free flyer.
    """

    time: float
    ranges: tuple[BeaconRange, ...] = ()
    tracks: tuple[ObjectTrack, ...] = ()
    attitude: Vector = array_field(shape=(4,), default=(0.0, 0.0, 0.0, 1.0))
    angular_velocity: Vector = array_field(default=(0.0, 0.0, 0.0))
    joint_positions: Vector = array_field(shape=(-1,), default=())
    joint_velocities: Vector = array_field(shape=(-1,), default=())

    def obstacles(self) -> tuple[ObjectTrack, ...]:
        """The tracks of obstacles."""
        return tuple(t for t in self.tracks if t.kind is ObjectKind.OBSTACLE)


@message
class Surroundings(Message):
    """What a controller knows about its neighbourhood.

    Attributes
    ----------
    obstacles : tuple of ObjectTrack
        Obstacles currently tracked.
    safety_distance : float
        Least surface gap to keep from any obstacle, m (the thesis's SAFETY_DISTANCE;
        0 if the scenario sets none).
    """

    obstacles: tuple[ObjectTrack, ...] = ()
    safety_distance: float = 0.0
