"""Messages of path planning: the problem a path planner solves and its answers.

Vectors are read-only float arrays in the world frame; times are scenario seconds;
quaternions are ``[x, y, z, w]``.
"""

from __future__ import annotations

import dataclasses
import enum
import time as wallclock
from collections.abc import Mapping
from dataclasses import field
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike

from dcsim.geometry import Vector, quaternion_conjugate, quaternion_multiply, rotation_vector, slerp
from dcsim.messages.base import Message, array_field, message
from dcsim.messages.sensing import ObjectTrack
from dcsim.messages.state import RobotState
from dcsim.robots.model import RobotModel, check_robot_model

_INF = float("inf")


@message
class GoalRegion(Message):
    """Where, and optionally how and when, a path must end.

    The position region is a sphere of radius ``tolerance`` about ``position``, or the
    box ``position ± half_extents`` when ``half_extents`` is given.

    Attributes
    ----------
    position : ndarray (3,)
        Centre of the goal region, m.
    tolerance : float
        Radius of a spherical goal region, m.
    velocity : ndarray (3,)
        Velocity to match on arrival (e.g. a target's), m/s.
    time : float or None
        Required arrival time, s, or None for "as soon as allowed".
    half_extents : ndarray (3,) or None
        Half side lengths of a box-shaped region (axis-aligned), m; None for a sphere.
    attitude : ndarray (4,) or None
        Attitude to arrive at, or None for any.
    attitude_tolerance : float
        Largest rotation angle from ``attitude`` that counts as arrived, rad.
    velocity_tolerance : float
        Largest difference from ``velocity`` that counts as arrived, m/s (``inf``: any).
    time_tolerance : float
        Largest difference from ``time`` that counts as arrived, s (``inf``: any).
    """

    position: Vector = array_field()
    tolerance: float = 0.0
    velocity: Vector = array_field(default=(0.0, 0.0, 0.0))
    time: float | None = None
    half_extents: Vector | None = array_field(default=None, optional=True)
    attitude: Vector | None = array_field(shape=(4,), default=None, optional=True)
    attitude_tolerance: float = _INF
    velocity_tolerance: float = _INF
    time_tolerance: float = _INF

    def contains(self, state: RobotState) -> bool:
        """Whether ``state`` is inside the region and within every tolerance."""
        offset = state.position - self.position
        if self.half_extents is None:
            inside = float(np.linalg.norm(offset)) <= self.tolerance
        else:
            inside = bool(np.all(np.abs(offset) <= self.half_extents))
        if not inside:
            return False
        if np.linalg.norm(state.velocity - self.velocity) > self.velocity_tolerance:
            return False
        if self.time is not None and abs(state.time - self.time) > self.time_tolerance:
            return False
        if self.attitude is not None:
            error = quaternion_multiply(state.attitude, quaternion_conjugate(self.attitude))
            return float(np.linalg.norm(rotation_vector(error))) <= self.attitude_tolerance
        return True


@message
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


@message
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


class FrameKind(enum.StrEnum):
    """The dynamics of the frame a path is planned in."""

    INERTIAL = "inertial"
    CLOHESSY_WILTSHIRE = "clohessy-wiltshire"


class OrbitModel(enum.StrEnum):
    """How bodies move relative to the chief of an LVLH frame."""

    CLOHESSY_WILTSHIRE = "cw"
    TWO_BODY = "two-body"
    J2 = "j2"


@message
class ChiefOrbit(Message):
    """The chief's orbit of an LVLH world, for planners that model it exactly.

    Attributes
    ----------
    model : OrbitModel
        The world's relative dynamics.
    semi_major_axis : float
        m.
    eccentricity : float
        In [0, 1).
    inclination, raan, argument_of_perigee, true_anomaly : float
        The chief's elements at t = 0, rad.
    mu : float
        Gravitational parameter, m³/s².
    j2 : float
        Second zonal harmonic (felt under ``OrbitModel.J2`` only).
    earth_radius : float
        J2's reference radius, m.
    """

    model: OrbitModel
    semi_major_axis: float
    eccentricity: float = 0.0
    inclination: float = 0.0
    raan: float = 0.0
    argument_of_perigee: float = 0.0
    true_anomaly: float = 0.0
    mu: float = 3.986004418e14
    j2: float = 0.0
    earth_radius: float = 6_378_137.0


@message
class FrameDynamics(Message):
    """The frame's free motion: force-free, or relative motion in an orbit's LVLH frame.

    In an LVLH world the frame's dynamics are always given as Clohessy–Wiltshire with
    the orbit's mean motion (every planner that models orbital motion knows them);
    ``orbit`` says when the world moves bodies by an exact model instead, so that a
    planner that knows it can use it and one that does not plans with the
    linearisation (and says so: :attr:`~dcsim.api.PathPlanner.orbit_models`).

    Attributes
    ----------
    kind : FrameKind
        Inertial (force-free straight lines) or Clohessy–Wiltshire (LVLH frame: x
        radial, y along-track, z orbit normal).
    mean_motion : float
        Mean motion of the reference orbit, rad/s (Clohessy–Wiltshire only).
    orbit : ChiefOrbit or None
        The chief's orbit when the world's model is ``two-body`` or ``j2``; None under
        Clohessy–Wiltshire and in an inertial frame.
    """

    kind: FrameKind = FrameKind.INERTIAL
    mean_motion: float = 0.0
    orbit: ChiefOrbit | None = None

    @property
    def model(self) -> OrbitModel | None:
        """The world's relative dynamics in an LVLH frame; None in an inertial one."""
        if self.kind is FrameKind.INERTIAL:
            return None
        return OrbitModel.CLOHESSY_WILTSHIRE if self.orbit is None else self.orbit.model


@message
class GraspGoal(Message):
    """A grapple fixture on a tumbling body, for a manipulator's end effector to meet.

    The fixture is a bar on the body; a gripper holds it when the gripper's grasp point
    (``tool_offset`` ahead of DH frame n along x_n) is on the bar's centre, x_n points
    along ``-approach_axis`` and z_n along ``bar_axis``, with the end effector moving as
    the fixture does.

    Attributes
    ----------
    target : ObjectTrack
        The body's track, with its attitude, angular velocity and inertia (its
        torque-free tumble predicts the fixture's motion).
    fixture : ndarray (3,)
        The bar's centre, body frame, m.
    approach_axis, bar_axis : ndarray (3,)
        Unit axes of the fixture, body frame.
    tool_offset : float
        Distance from DH frame n to the grasp point along x_n, m.
    """

    target: ObjectTrack
    fixture: Vector = array_field()
    approach_axis: Vector = array_field()
    bar_axis: Vector = array_field()
    tool_offset: float = 0.0

    def __post_init__(self) -> None:
        super().__post_init__()
        track = self.target
        if track.attitude is None or track.angular_velocity is None or track.inertia is None:
            raise ValueError(
                "GraspGoal.target must carry the body's attitude, angular velocity and inertia"
            )


@message
class PathProblem(Message):
    """What a path planner is asked to solve.

    For a free flyer the path is the robot's own. For a manipulator (``model`` set) it is
    its end effector's: ``start`` is the robot's full state (base and joints), while the
    goal region, the speed and acceleration limits and the returned trajectory's
    positions and velocities are the end effector's (world frame).

    Every planner keeps the same ``safety_margin`` and answers by the same clock: it
    reads :meth:`due` once when it starts and returns by then.

    Attributes
    ----------
    start : RobotState
        Initial state (its ``time`` is the start time).
    goal : GoalRegion
        Region (and optionally attitude, velocity and time) to reach.
    obstacles : tuple of ObjectTrack
        Obstacles with their shape and predicted motion.
    frame : FrameDynamics
        The free dynamics of the planning frame.
    robot_radius : float
        Radius of the robot's bounding sphere, m.
    robot_mass : float or None
        The robot's mass, kg, for planners that give feed-forward forces; None if unknown.
    max_speed : float
        Speed limit, m/s.
    max_acceleration : float
        Acceleration the robot can count on, m/s² (``inf`` for impulsive burns).
    max_delta_v : float
        Largest total delta-v the path may use, m/s (``inf`` for none).
    max_angular_rate : float
        Angular rate limit, rad/s (``inf`` for none).
    max_angular_acceleration : float
        Angular acceleration the robot can count on, rad/s² (``inf`` for none).
    bounds : Bounds or None
        Box the path must stay in, or None.
    weights : CostWeights
        Cost weights.
    time_budget : float
        Wall time the planner may spend from when it is called, s, unless ``deadline``
        is given (the mission's ``planning_budget``).
    model : RobotModel or None
        The robot's model (``RobotSpec.model``): for a manipulator, its
        :class:`~dcsim.robots.manipulator.ManipulatorModel`; None for a free flyer.
    safety_margin : float
        Least surface gap to keep between the robot's bounding sphere and every
        obstacle's shape, m, beyond both (the mission's ``safety_distance``); the same
        for every planner.
    deadline : float or None
        When the answer is due, in ``time.monotonic()`` seconds; None: ``time_budget``
        after the planner is called (see :meth:`due`).
    grasp : GraspGoal or None
        For a manipulator's end effector meeting a moving grapple fixture: the fixture
        and the body's track (``goal`` then gives the tolerance and the arrival time
        ``goal.time``, if any); None for every other problem.

    Raises
    ------
    ValueError
        If ``safety_margin`` is negative or not finite.
    TypeError
        If ``model`` is neither None nor a :class:`~dcsim.robots.model.RobotModel`.
    """

    start: RobotState
    goal: GoalRegion
    obstacles: tuple[ObjectTrack, ...] = ()
    frame: FrameDynamics = field(default_factory=FrameDynamics)
    robot_radius: float = 0.0
    robot_mass: float | None = None
    max_speed: float = 1.0
    max_acceleration: float = _INF
    max_delta_v: float = _INF
    max_angular_rate: float = _INF
    max_angular_acceleration: float = _INF
    bounds: Bounds | None = None
    weights: CostWeights = field(default_factory=CostWeights)
    time_budget: float = 1.0
    model: RobotModel | None = None
    safety_margin: float = 0.0
    deadline: float | None = None
    grasp: GraspGoal | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        if not 0.0 <= self.safety_margin < _INF:
            raise ValueError(
                f"PathProblem.safety_margin must be a finite gap of 0 m or more, "
                f"got {self.safety_margin!r}"
            )
        check_robot_model("PathProblem.model", self.model)

    def due(self) -> float:
        """When the answer is due, ``time.monotonic()`` seconds: ``deadline``, or
        ``time_budget`` from now when no deadline is given.

        A planner calls it once, when it starts, and measures all its work against it.
        """
        if self.deadline is not None:
            return self.deadline
        return wallclock.monotonic() + self.time_budget


@message
class Trajectory(Message):
    """A time-stamped reference trajectory.

    Position and velocity are linear between samples; attitude is interpolated by
    spherical linear interpolation (slerp) and angular velocity linearly.

    Attributes
    ----------
    times : ndarray (N,)
        Strictly increasing sample times, s.
    positions, velocities : ndarray (N, 3)
        States at the samples, m and m/s.
    attitudes : ndarray (N, 4) or None
        Attitudes at the samples ``[x, y, z, w]``; None leaves the attitude free.
    angular_velocities : ndarray (N, 3) or None
        Angular velocities at the samples, rad/s; None for zero.
    forces, torques : ndarray (N − 1, 3) or None
        Feed-forward force (N) and torque (N·m) held over each segment, if known.
    delta_v : float
        Total delta-v the trajectory needs, including matching the start and goal
        velocities, m/s.
    length : float
        Path length, m.
    duration : float
        ``times[-1] - times[0]``, s.
    statistics : mapping of str to float
        The planner's figures (e.g. ``nodes_expanded``, ``iterations``).
    """

    times: Vector = array_field(shape=(-1,))
    positions: Vector = array_field(shape=(-1, 3))
    velocities: Vector = array_field(shape=(-1, 3))
    attitudes: Vector | None = array_field(shape=(-1, 4), default=None, optional=True)
    angular_velocities: Vector | None = array_field(shape=(-1, 3), default=None, optional=True)
    forces: Vector | None = array_field(shape=(-1, 3), default=None, optional=True)
    torques: Vector | None = array_field(shape=(-1, 3), default=None, optional=True)
    delta_v: float = 0.0
    length: float = 0.0
    duration: float = 0.0
    statistics: Mapping[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        super().__post_init__()
        n = len(self.times)
        for name, rows in (
            ("positions", n),
            ("velocities", n),
            ("attitudes", n),
            ("angular_velocities", n),
            ("forces", n - 1),
            ("torques", n - 1),
        ):
            value = getattr(self, name)
            if value is not None and len(value) != rows:
                raise ValueError(
                    f"Trajectory.{name} has {len(value)} rows, expected {rows} for {n} times"
                )

    def sample(self, t: ArrayLike) -> tuple[Vector, Vector]:
        """Reference ``(position, velocity)`` at time(s) ``t`` (s), held at the ends.

        Returns
        -------
        position, velocity : ndarray, shape (..., 3)
            Linear between samples, m and m/s.
        """
        times, at = self.times, np.asarray(t, dtype=float)
        if at.ndim == 0 and times[0] < at < times[-1]:
            row = self._interpolate_inside(float(at))
            return row[:3], row[3:]
        table = self._sample_table
        position = np.stack([np.interp(at, times, table[:, k]) for k in range(3)], axis=-1)
        velocity = np.stack([np.interp(at, times, table[:, k]) for k in range(3, 6)], axis=-1)
        return position, velocity

    def _interpolate_inside(self, t: float) -> Vector:
        """Position and velocity (6,) at a time strictly inside the trajectory, s: the
        arithmetic of :func:`numpy.interp`, all six components at once."""
        times, table = self.times, self._sample_table
        j = int(np.searchsorted(times, t, side="right")) - 1
        if times[j] == t:
            return table[j].copy()
        slope = (table[j + 1] - table[j]) / (times[j + 1] - times[j])
        return slope * (t - times[j]) + table[j]

    @cached_property
    def _sample_table(self) -> Vector:
        """Positions and velocities side by side, (N, 6), made once per trajectory."""
        return np.hstack([self.positions, self.velocities])

    def state_at(self, t: float) -> RobotState:
        """The full reference state at time ``t`` (s), held at the ends."""
        position, velocity = self.sample(t)
        attitude = np.array([0.0, 0.0, 0.0, 1.0])
        angular = np.zeros(3)
        if self.attitudes is not None:
            attitude = self.attitude_at(t)
        if self.angular_velocities is not None:
            angular = np.array(
                [np.interp(t, self.times, self.angular_velocities[:, k]) for k in range(3)]
            )
        return RobotState(t, position, attitude, velocity, angular)

    def end_state(self, goal: GoalRegion | None = None) -> RobotState:
        """The state at the last sample, to judge arrival with ``goal.contains``.

        A trajectory that leaves the attitude free ends at ``goal``'s attitude when the
        goal sets one: the transfer mission holds the goal's attitude while it flies such
        a trajectory.
        """
        end = self.state_at(float(self.times[-1]))
        if self.attitudes is None and goal is not None and goal.attitude is not None:
            return dataclasses.replace(end, attitude=goal.attitude)
        return end

    def attitude_at(self, t: float) -> Vector:
        """Attitude at time ``t`` (s) by slerp between the samples, held at the ends.

        Raises
        ------
        ValueError
            If the trajectory has no attitudes.
        """
        if self.attitudes is None:
            raise ValueError("this trajectory leaves the attitude free")
        times = self.times
        if t <= times[0] or len(times) == 1:
            return self.attitudes[0].copy()
        if t >= times[-1]:
            return self.attitudes[-1].copy()
        i = int(np.searchsorted(times, t, side="right")) - 1
        fraction = (t - times[i]) / (times[i + 1] - times[i])
        return slerp(self.attitudes[i], self.attitudes[i + 1], fraction)


@message
class NoPath(Message):
    """A path planner's answer when it finds no path.

    Attributes
    ----------
    reason : str
        Why, in words a user can act on.
    """

    reason: str
