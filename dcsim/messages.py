"""The messages plugins exchange with the framework: immutable values in SI units.

They follow the topics of the source thesis (Objects, Beacons, Location, Plan, Move)
and the contracts of the four plugin kinds. Vectors are read-only float numpy arrays
in the world frame; times are scenario seconds; quaternions are ``[x, y, z, w]``.
Two messages are equal when all their fields are (arrays compared element-wise).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from dcsim.geometry import Vector, clip_norm, rotate, unit
from dcsim.motion import LinearMotion, MotionModel


def array_field(shape: tuple[int, ...] = (3,), default: ArrayLike | None = None) -> Any:
    """Declare a message field holding a read-only float array.

    Parameters
    ----------
    shape : tuple of int
        Required shape; ``-1`` accepts any length along that axis.
    default : array_like, optional
        Default value; omit for a required field.
    """
    metadata = {"shape": shape}
    if default is None:
        return field(metadata=metadata)
    frozen = tuple(np.asarray(default, dtype=float).ravel())
    return field(default_factory=lambda: np.array(frozen).reshape(shape), metadata=metadata)


_ARRAY_FIELDS: dict[type, tuple[tuple[str, tuple[int, ...]], ...]] = {}


def _array_fields(cls: type) -> tuple[tuple[str, tuple[int, ...]], ...]:
    """Names and shapes of a message class's array fields (cached per class)."""
    found = _ARRAY_FIELDS.get(cls)
    if found is None:
        found = tuple((f.name, f.metadata["shape"]) for f in fields(cls) if "shape" in f.metadata)
        _ARRAY_FIELDS[cls] = found
    return found


class Message:
    """Base of every message: converts array fields and compares by value."""

    def __post_init__(self) -> None:
        for name, shape in _array_fields(type(self)):
            value = np.array(getattr(self, name), dtype=float)
            if value.ndim != len(shape) or any(
                want not in (-1, got) for want, got in zip(shape, value.shape, strict=True)
            ):
                raise ValueError(
                    f"{type(self).__name__}.{name} must have shape {shape}, got {value.shape}"
                )
            value.setflags(write=False)
            object.__setattr__(self, name, value)

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        for f in fields(self):  # type: ignore[arg-type]
            a, b = getattr(self, f.name), getattr(other, f.name)
            if isinstance(a, np.ndarray):
                if not np.array_equal(a, b):
                    return False
            elif a != b:
                return False
        return True

    __hash__ = None  # type: ignore[assignment]


def _message(cls: type) -> type:
    return dataclass(frozen=True, eq=False)(cls)


class ObjectKind(enum.StrEnum):
    """What a space object is to the collector."""

    TARGET = "target"
    OBSTACLE = "obstacle"


@_message
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
        Radius of the object's bounding sphere, m.
    motion : MotionModel or None
        The object's motion parameters, for prediction; None if unknown, in which case
        prediction assumes constant velocity.
    """

    id: int
    kind: ObjectKind
    time: float
    position: Vector = array_field()
    velocity: Vector = array_field()
    mass: float = 0.0
    radius: float = 0.0
    motion: MotionModel | None = None

    def predict(self, t: ArrayLike) -> tuple[Vector, Vector]:
        """Predicted ``(position, velocity)`` at time(s) ``t`` (s), shape ``(..., 3)``."""
        model = self.motion or LinearMotion(self.position, self.velocity, epoch=self.time)
        return model.state_at(t)


@_message
class BeaconRange(Message):
    """A measured range to a localisation beacon (the thesis's Beacon topic).

    Attributes
    ----------
    beacon_id : int
        Index of the beacon in the scenario.
    beacon_position : ndarray (3,)
        Known beacon position, m.
    range : float
        Measured distance from the collector to the beacon, m (noisy).
    sigma : float
        Standard deviation of the range noise, m.
    """

    beacon_id: int
    beacon_position: Vector = array_field()
    range: float = 0.0
    sigma: float = 0.0


@_message
class MotionInput(Message):
    """What the collector was commanded to do over the last interval.

    Attributes
    ----------
    acceleration : ndarray (3,)
        Commanded linear acceleration actually applied (force after limits divided by
        the collector's mass), world frame, m/s².
    """

    acceleration: Vector = array_field(default=(0.0, 0.0, 0.0))


@_message
class LocationEstimate(Message):
    """A localiser's belief about the collector (the thesis's Location topic).

    Attributes
    ----------
    time : float
        Time of the estimate, s.
    position, velocity : ndarray (3,)
        Estimated state, m and m/s.
    heading : ndarray (3,)
        Unit vector of the estimated heading.
    covariance : ndarray (6, 6)
        Covariance of ``[position, velocity]``, m² and (m/s)² blocks.
    converged : bool
        True once the localiser trusts its estimate (the thesis publishes only then).
    """

    time: float
    position: Vector = array_field()
    velocity: Vector = array_field(default=(0.0, 0.0, 0.0))
    heading: Vector = array_field(default=(1.0, 0.0, 0.0))
    covariance: Vector = array_field(shape=(6, 6), default=np.eye(6))
    converged: bool = False


@_message
class Prior(Message):
    """The initial belief a localiser is reset with.

    Attributes
    ----------
    position : ndarray (3,)
        Expected position, m.
    position_sigma : float
        Standard deviation of the position about ``position`` per axis, m.
    velocity : ndarray (3,)
        Expected velocity, m/s.
    velocity_sigma : float
        Standard deviation of the velocity per axis, m/s.
    """

    position: Vector = array_field()
    position_sigma: float = 1.0
    velocity: Vector = array_field(default=(0.0, 0.0, 0.0))
    velocity_sigma: float = 0.1


@_message
class DropPoint(Message):
    """Where collected targets are delivered.

    Attributes
    ----------
    motion : MotionModel
        The drop point's motion (static for a fixed point).
    tolerance : float
        Distance within which the collector counts as at the drop point, m.
    """

    motion: MotionModel
    tolerance: float

    def state_at(self, t: ArrayLike) -> tuple[Vector, Vector]:
        """Position and velocity of the drop point at time(s) ``t`` (s)."""
        return self.motion.state_at(t)


@_message
class RobotSpec(Message):
    """The collector's physical limits, as planners and controllers need them.

    Attributes
    ----------
    mass : float
        Current mass, kg.
    radius : float
        Radius of a sphere about the collector's centre that holds it and any cargo, m.
    max_force : float
        Largest thrust magnitude, N.
    max_torque : float
        Largest torque magnitude, N·m.
    max_speed : float
        Speed the collector must not exceed, m/s.
    """

    mass: float
    radius: float
    max_force: float
    max_torque: float
    max_speed: float


@_message
class TaskRequest(Message):
    """What a task planner is asked to plan.

    Attributes
    ----------
    time : float
        Current time, s; every pickup must be later.
    robot : LocationEstimate
        Where the collector believes it is.
    targets : tuple of ObjectTrack
        Targets currently tracked; only these may be planned.
    drop_point : DropPoint
        Where to deliver.
    capacity : int
        Targets the collector can carry at once.
    carried : int
        Targets already on board.
    max_speed : float
        Speed limit of the collector, m/s.
    max_acceleration : float
        Acceleration the collector can count on, m/s² (``inf`` for impulsive burns).
    time_budget : float
        Wall time the planner may spend, s.
    """

    time: float
    robot: LocationEstimate
    targets: tuple[ObjectTrack, ...]
    drop_point: DropPoint
    capacity: int
    carried: int = 0
    max_speed: float = 1.0
    max_acceleration: float = float("inf")
    time_budget: float = 1.0


@_message
class PlanTask(Message):
    """One pickup in a plan (the thesis's PlanTask message).

    Attributes
    ----------
    target_id : int
        Target to grab.
    pickup_time : float
        When to grab it, s.
    pickup_point : ndarray (3,)
        Where the target will be then, m.
    pickup_velocity : ndarray (3,)
        The target's velocity then, m/s.
    """

    target_id: int
    pickup_time: float
    pickup_point: Vector = array_field()
    pickup_velocity: Vector = array_field(default=(0.0, 0.0, 0.0))


@_message
class DropVisit(Message):
    """A visit to the drop point inside a plan.

    Attributes
    ----------
    after_task : int
        Index (in ``Plan.tasks``) of the pickup after which the visit happens.
    time : float
        Planned arrival at the drop point, s.
    point : ndarray (3,)
        Where the drop point will be then, m.
    """

    after_task: int
    time: float
    point: Vector = array_field()


@_message
class Plan(Message):
    """An ordered plan of pickups and drop visits (the thesis's Plan topic).

    Attributes
    ----------
    tasks : tuple of PlanTask
        Pickups in order, with strictly increasing pickup times.
    drop_visits : tuple of DropVisit
        Visits to the drop point, ordered; the last pickup is always followed by one.
    cost : float
        The planner's cost of the plan (see the planner's documentation for units).
    """

    tasks: tuple[PlanTask, ...] = ()
    drop_visits: tuple[DropVisit, ...] = ()
    cost: float = 0.0


@_message
class PathState(Message):
    """A time-stamped kinematic state.

    Attributes
    ----------
    time : float
        s.
    position, velocity : ndarray (3,)
        m and m/s.
    """

    time: float
    position: Vector = array_field()
    velocity: Vector = array_field(default=(0.0, 0.0, 0.0))


@_message
class GoalRegion(Message):
    """Where a path must end.

    Attributes
    ----------
    position : ndarray (3,)
        Centre of the goal region, m.
    tolerance : float
        Radius of the goal region, m.
    velocity : ndarray (3,)
        Velocity to match on arrival (e.g. a target's), m/s.
    time : float or None
        Required arrival time, s, or None for "as soon as allowed".
    """

    position: Vector = array_field()
    tolerance: float = 0.0
    velocity: Vector = array_field(default=(0.0, 0.0, 0.0))
    time: float | None = None


@_message
class Bounds(Message):
    """An axis-aligned box the path must stay in.

    Attributes
    ----------
    lower, upper : ndarray (3,)
        Corners of the box, m.
    """

    lower: Vector = array_field()
    upper: Vector = array_field()

    def contains(self, points: ArrayLike) -> np.ndarray:
        """Whether each point of ``points`` (shape ``(..., 3)``, m) lies in the box."""
        p = np.asarray(points, dtype=float)
        return np.all((p >= self.lower) & (p <= self.upper), axis=-1)


@_message
class CostWeights(Message):
    """Weights of a path's cost ``J = w_dv Δv + w_L L + w_T T``.

    Attributes
    ----------
    delta_v : float
        Weight on total delta-v, per m/s.
    length : float
        Weight on path length, per m.
    time : float
        Weight on duration, per s.
    """

    delta_v: float = 1.0
    length: float = 0.0
    time: float = 0.0


@_message
class PathProblem(Message):
    """What a path planner is asked to solve.

    Attributes
    ----------
    start : PathState
        Initial state.
    goal : GoalRegion
        Region (and optionally velocity and time) to reach.
    obstacles : tuple of ObjectTrack
        Obstacles with their predicted motion.
    robot_radius : float
        Radius of the collector's bounding sphere, m.
    max_speed : float
        Speed limit, m/s.
    max_acceleration : float
        Acceleration the collector can count on, m/s² (``inf`` for impulsive burns).
    max_delta_v : float
        Largest total delta-v the path may use, m/s (``inf`` for none).
    bounds : Bounds or None
        Box the path must stay in, or None.
    weights : CostWeights
        Cost weights.
    time_budget : float
        Wall time the planner may spend, s.
    """

    start: PathState
    goal: GoalRegion
    obstacles: tuple[ObjectTrack, ...] = ()
    robot_radius: float = 0.0
    max_speed: float = 1.0
    max_acceleration: float = float("inf")
    max_delta_v: float = float("inf")
    bounds: Bounds | None = None
    weights: CostWeights = field(default_factory=CostWeights)
    time_budget: float = 1.0


@_message
class Trajectory(Message):
    """A time-stamped reference trajectory, position and velocity linear between samples.

    Attributes
    ----------
    times : ndarray (N,)
        Strictly increasing sample times, s.
    positions, velocities : ndarray (N, 3)
        States at the samples, m and m/s.
    delta_v : float
        Total delta-v the trajectory needs, including matching the start and goal
        velocities, m/s.
    length : float
        Path length, m.
    duration : float
        ``times[-1] - times[0]``, s.
    """

    times: Vector = array_field(shape=(-1,))
    positions: Vector = array_field(shape=(-1, 3))
    velocities: Vector = array_field(shape=(-1, 3))
    delta_v: float = 0.0
    length: float = 0.0
    duration: float = 0.0

    def sample(self, t: float) -> tuple[Vector, Vector]:
        """Reference ``(position, velocity)`` at time ``t`` (s), held at the ends."""
        position = np.array([np.interp(t, self.times, self.positions[:, k]) for k in range(3)])
        velocity = np.array([np.interp(t, self.times, self.velocities[:, k]) for k in range(3)])
        return position, velocity


@_message
class NoPath(Message):
    """A path planner's answer when it finds no path.

    Attributes
    ----------
    reason : str
        Why, in words a user can act on.
    """

    reason: str


@_message
class Reference(Message):
    """What a controller should track at one instant.

    Attributes
    ----------
    time : float
        s.
    position, velocity : ndarray (3,)
        Reference state, m and m/s.
    acceleration : ndarray (3,)
        Feed-forward acceleration, m/s².
    max_speed : float
        Speed not to exceed on this leg, m/s (``inf``: the robot's own limit applies); the
        mission lowers it on the way to the drop point (the thesis's DROP_SPEED).
    """

    time: float
    position: Vector = array_field()
    velocity: Vector = array_field(default=(0.0, 0.0, 0.0))
    acceleration: Vector = array_field(default=(0.0, 0.0, 0.0))
    max_speed: float = float("inf")


@_message
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


@_message
class Command(Message):
    """Force and torque on the collector for one control period.

    Attributes
    ----------
    force : ndarray (3,)
        Thrust, world frame, N.
    torque : ndarray (3,)
        Torque, world frame, N·m.
    """

    force: Vector = array_field(default=(0.0, 0.0, 0.0))
    torque: Vector = array_field(default=(0.0, 0.0, 0.0))


@_message
class MoveCommand(Message):
    """The thesis's Move message: turn the heading by a rotation, then fly at a speed.

    Attributes
    ----------
    rotation : ndarray (4,)
        Unit quaternion ``[x, y, z, w]`` taking the current heading onto the commanded
        direction of flight.
    speed : float
        Commanded speed along that direction, m/s.
    """

    rotation: Vector = array_field(shape=(4,))
    speed: float = 0.0

    def desired_velocity(self, heading: ArrayLike) -> Vector:
        """The commanded velocity (m/s) for a collector whose heading is ``heading``."""
        return self.speed * unit(rotate(self.rotation, unit(heading)))

    def to_command(
        self,
        heading: ArrayLike,
        velocity: ArrayLike,
        mass: float,
        max_force: float,
        response_time: float,
    ) -> Command:
        """Convert to the force that reaches the commanded velocity.

        Parameters
        ----------
        heading : array_like (3,)
            Current heading (direction the rotation starts from).
        velocity : array_like (3,)
            Current velocity, m/s.
        mass : float
            Current mass, kg.
        max_force : float
            Thrust limit, N; the force is scaled down to it.
        response_time : float
            Time constant of the velocity loop, s.

        Returns
        -------
        Command
            ``F = m (v_cmd − v) / response_time``, limited to ``max_force``; no torque.
        """
        force = mass * (self.desired_velocity(heading) - np.asarray(velocity)) / response_time
        return Command(force=clip_norm(force, max_force))
