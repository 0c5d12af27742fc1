"""Messages about what the robot senses: space objects, beacon ranges, its own attitude.

They follow the source thesis's topics (Objects, Beacons). Vectors are read-only float
arrays in the world frame unless a field says otherwise; times are scenario seconds;
quaternions are ``[x, y, z, w]``. A sensor model (:class:`~dcsim.api.SensorModel`) reads
a :class:`SensedTruth` and gives readings (:class:`BeaconRange`, :class:`AttitudeReading`,
:class:`RateReading`, :class:`Detection`); a tracker turns detections into
:class:`ObjectTrack` s; the robot's plugins see them gathered in :class:`Observations`.
"""

from __future__ import annotations

import enum
from dataclasses import field

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
        Radius of the object's bounding sphere, m (from ``shape`` when given as 0): the
        sphere to keep clear of, ``shape_margin`` included.
    motion : MotionModel or None
        The motion :meth:`predict` follows: under ideal sensing the object's own motion;
        from a tracker, the frame's free dynamics from the track's state; None if unknown,
        in which case prediction assumes constant velocity.
    shape : Shape
        The object's shape as known: its true shape under ideal sensing or from a
        sensor that sees shapes, else a bounding sphere; given as None (the default), a
        sphere of ``radius``.
    covariance : ndarray (6, 6) or None
        Covariance of the state ``[position, velocity]`` at ``time``, m² and m²/s², m²/s
        off the diagonal blocks; None when the state is exact (ideal sensing).
    attitude : ndarray (4,) or None
        Body-to-world rotation ``[x, y, z, w]`` at ``time`` of an object whose rotation
        is tracked (a tumbling body); None otherwise.
    angular_velocity : ndarray (3,) or None
        Its angular velocity at ``time``, world frame, rad/s; None when not tracked.
    inertia : ndarray (3, 3) or None
        Its inertia tensor about the centre of mass, body axes, kg·m², when known (it
        predicts the torque-free tumble); None otherwise.
    shape_margin : float
        How far a tracker widened the sensed extent for a shape its sensor does not see,
        m (0 when the shape is known): ``radius - shape_margin`` is the best estimate of
        the object's bounding radius (:attr:`sensed_radius`), the figure to judge a
        reach by, while ``radius`` is the one to keep clear of.

    Raises
    ------
    ValueError
        If ``shape_margin`` is negative, not a number or more than ``radius``.
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
    covariance: Vector | None = array_field(shape=(6, 6), default=None, optional=True)
    attitude: Vector | None = array_field(shape=(4,), default=None, optional=True)
    angular_velocity: Vector | None = array_field(shape=(3,), default=None, optional=True)
    inertia: Vector | None = array_field(shape=(3, 3), default=None, optional=True)
    shape_margin: float = 0.0

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.shape is None:
            object.__setattr__(self, "shape", Shape(ShapeKind.SPHERE, radius=self.radius))
        elif self.radius == 0.0:
            object.__setattr__(self, "radius", self.shape.bounding_radius)
        if self.shape_margin != 0.0 and not 0.0 < self.shape_margin <= self.radius:
            raise ValueError(
                f"ObjectTrack.shape_margin must be 0 m or more and at most the radius "
                f"{self.radius!r} m, got {self.shape_margin!r}"
            )

    @property
    def sensed_radius(self) -> float:
        """The best estimate of the object's bounding radius, m: ``radius`` without the
        tracker's ``shape_margin``."""
        return self.radius - self.shape_margin

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
class AttitudeReading(Message):
    """The star tracker's measured attitude.

    Attributes
    ----------
    time : float
        Time of the measurement, s.
    attitude : ndarray (4,)
        Measured body-to-world rotation ``[x, y, z, w]`` (a unit quaternion).
    sigma : ndarray (3,)
        Standard deviation of the error about each body axis, rad.
    """

    time: float
    attitude: Vector = array_field(shape=(4,))
    sigma: Vector = array_field(default=(0.0, 0.0, 0.0))


@message
class RateReading(Message):
    """The gyros' measured angular velocity.

    Attributes
    ----------
    time : float
        Time of the measurement, s.
    angular_velocity : ndarray (3,)
        Measured angular velocity of the base, body frame, rad/s.
    sigma : float
        Standard deviation of one reading's white noise per axis, rad/s (the angle random
        walk over the sampling interval; the bias is not included).
    """

    time: float
    angular_velocity: Vector = array_field()
    sigma: float = 0.0


@message
class Detection(Message):
    """One object as an object sensor (lidar or camera) sees it at one instant.

    The sensor recognises what it sees (each object carries its catalogue identity, kind
    and mass), so a tracker associates detections by ``id``; its position is measured
    relative to the robot.

    Attributes
    ----------
    time : float
        Time of the measurement, s.
    id : int
        The object's identifier.
    kind : ObjectKind
        Target or obstacle.
    relative_position : ndarray (3,)
        Measured position of the object's centre relative to the robot's base, along the
        world frame's axes, m.
    covariance : ndarray (3, 3)
        Covariance of ``relative_position``'s error, m².
    radius : float
        Radius of the object's bounding sphere as the sensor sizes it, m.
    mass : float
        The object's catalogue mass, kg.
    shape : Shape or None
        The object's shape when the sensor sees shapes; None otherwise.
    attitude : ndarray (4,) or None
        Measured body-to-world rotation ``[x, y, z, w]`` of an object whose rotation the
        sensor measures (a tumbling body, by a sensor with an attitude noise); None
        otherwise.
    attitude_covariance : ndarray (3, 3) or None
        Covariance of ``attitude``'s error, a small rotation about the world axes, rad²;
        None without an attitude.
    inertia : ndarray (3, 3) or None
        The object's catalogue inertia tensor about its centre of mass, body axes,
        kg·m², for an object whose rotation the world models; None otherwise.
    """

    time: float
    id: int
    kind: ObjectKind
    relative_position: Vector = array_field()
    covariance: Vector = array_field(shape=(3, 3))
    radius: float = 0.0
    mass: float = 0.0
    shape: Shape | None = None
    attitude: Vector | None = array_field(shape=(4,), default=None, optional=True)
    attitude_covariance: Vector | None = array_field(shape=(3, 3), default=None, optional=True)
    inertia: Vector | None = array_field(shape=(3, 3), default=None, optional=True)


@message
class KnownObject(Message):
    """A space object as the world knows it, for sensor models (not seen by plugins).

    Attributes
    ----------
    id : int
        The object's identifier.
    kind : ObjectKind
        Target or obstacle.
    mass : float
        kg.
    shape : Shape
        Its true collision shape.
    inertia : ndarray (3, 3) or None
        Its inertia tensor about its centre of mass, body axes, kg·m², for an object
        whose rotation the world models (a tumbling body); None otherwise.
    """

    id: int
    kind: ObjectKind
    mass: float
    shape: Shape
    inertia: Vector | None = array_field(shape=(3, 3), default=None, optional=True)


@message
class SensorSetup(Message):
    """What a sensor model is told before a run.

    Attributes
    ----------
    control_period : float
        Time between two calls of the model's ``measure``, s (the control period).
    beacons : ndarray (B, 3)
        Beacon positions, world frame, m.
    beacon_noise : float
        Standard deviation of the white range noise (``beacons.noise_sigma``), m.
    beacon_max_range : float
        Beacons farther away give no range (``beacons.max_range``; inf for none), m.
    beacon_report_nearest : int
        Ranges reported at most per reading (``beacons.report_nearest``).
    object_range : float
        Reach of the object sensor (``robot.sensor_range``), m.
    objects : tuple of KnownObject
        The world's objects, in the order of :class:`SensedTruth`'s object arrays.
    """

    control_period: float
    beacons: Vector = array_field(shape=(-1, 3), default=np.zeros((0, 3)))
    beacon_noise: float = 0.0
    beacon_max_range: float = np.inf
    beacon_report_nearest: int = 1
    object_range: float = np.inf
    objects: tuple[KnownObject, ...] = ()


_NONE_FREE = np.zeros(0, dtype=bool)
_NONE_FREE.setflags(write=False)


@message
class SensedTruth(Message):
    """The true state a sensor model measures at one instant (for sensor models only).

    Attributes
    ----------
    time : float
        s.
    position, velocity : ndarray (3,)
        The robot base's position (m) and velocity (m/s), world frame.
    attitude : ndarray (4,)
        The base's body-to-world rotation ``[x, y, z, w]``.
    angular_velocity : ndarray (3,)
        The base's angular velocity, world frame, rad/s.
    object_positions, object_velocities : ndarray (N, 3)
        Every object's position (m) and velocity (m/s), world frame, in the order of
        :attr:`SensorSetup.objects`; empty (0, 3) unless the scenario has an object
        sensor model.
    free : ndarray of bool (N,)
        Whether each object is free (not held by the robot, not delivered): a sensor
        sees only free objects.
    object_attitudes : ndarray (N, 4)
        Every object's body-to-world rotation ``[x, y, z, w]`` when the world models
        some object's rotation (a tumbling body), NaN rows for the objects whose
        rotation it does not model; empty (0, 4) when it models none.
    """

    time: float
    position: Vector = array_field()
    velocity: Vector = array_field()
    attitude: Vector = array_field(shape=(4,))
    angular_velocity: Vector = array_field()
    object_positions: Vector = array_field(shape=(-1, 3), default=np.zeros((0, 3)))
    object_velocities: Vector = array_field(shape=(-1, 3), default=np.zeros((0, 3)))
    free: np.ndarray = field(default_factory=lambda: _NONE_FREE)
    object_attitudes: Vector = array_field(shape=(-1, 4), default=np.zeros((0, 4)))


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
        Objects within sensor range: the truth under ideal object sensing, else the
        tracker's tracks.
    attitude : ndarray (4,)
        Base attitude as the star tracker gives it, ``[x, y, z, w]``: the truth under
        ideal sensing, else its latest reading.
    angular_velocity : ndarray (3,)
        Base angular velocity as the gyros give it, world frame, rad/s: the truth under
        ideal sensing, else their latest reading turned into the world frame by
        ``attitude``.
    joint_positions, joint_velocities : ndarray (n,)
        Joint encoder readings; empty for a free flyer.
    detections : tuple of Detection
        The object sensor's detections now (empty under ideal object sensing, or when
        it gives no reading now).
    star_tracker : AttitudeReading or None
        The star tracker's reading now; None under ideal sensing or between readings.
    gyros : RateReading or None
        The gyros' reading now; None under ideal sensing or between readings.
    """

    time: float
    ranges: tuple[BeaconRange, ...] = ()
    tracks: tuple[ObjectTrack, ...] = ()
    attitude: Vector = array_field(shape=(4,), default=(0.0, 0.0, 0.0, 1.0))
    angular_velocity: Vector = array_field(default=(0.0, 0.0, 0.0))
    joint_positions: Vector = array_field(shape=(-1,), default=())
    joint_velocities: Vector = array_field(shape=(-1,), default=())
    detections: tuple[Detection, ...] = ()
    star_tracker: AttitudeReading | None = None
    gyros: RateReading | None = None

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
