"""Standard problems the conformance suite poses to each plugin kind.

Each problem is built from a fixed seed, so every plugin is measured on exactly the same
inputs. They are small enough to run in well under a second per check.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from dcsim.geometry import quaternion_from_rotation_vector, quaternion_multiply
from dcsim.messages import (
    BeaconRange,
    Bounds,
    Detection,
    DropPoint,
    FrameDynamics,
    FrameKind,
    GoalRegion,
    KnownObject,
    MotionInput,
    ObjectKind,
    ObjectTrack,
    PathProblem,
    Prior,
    Reference,
    RobotSpec,
    RobotState,
    SensedTruth,
    SensorSetup,
    Shape,
    ShapeKind,
    StateEstimate,
    Surroundings,
    TaskRequest,
)
from dcsim.motion import ClohessyWiltshireMotion, LinearMotion, MotionSet, StaticMotion, mean_motion
from dcsim.registry.interfaces import Plugin
from dcsim.scenario.loader import packaged_scenario_path
from dcsim.testing.manipulator import thesis_robot

BEACONS = np.array(
    [
        [150.0, 150.0, 150.0],
        [150.0, -150.0, -150.0],
        [-150.0, 150.0, -150.0],
        [-150.0, -150.0, 150.0],
        [0.0, 0.0, -200.0],
    ]
)
"""Beacon positions of the standard beacon problem, m."""

ROBOT = RobotSpec(
    mass=100.0, inertia=10.0 * np.eye(3), radius=0.5, max_force=5.0, max_torque=0.5, max_speed=0.5
)
"""The collector of the controller and planner problems."""


@dataclass(frozen=True)
class BeaconStep:
    """One step of the standard beacon problem.

    Attributes
    ----------
    motion : MotionInput
        Commanded acceleration over the step.
    dt : float
        Step length, s.
    ranges : list of BeaconRange
        Ranges measured at the end of the step.
    truth : ndarray (3,)
        True position at the end of the step (for scoring only; never given to the plugin).
    """

    motion: MotionInput
    dt: float
    ranges: list[BeaconRange]
    truth: np.ndarray


@dataclass(frozen=True)
class BeaconProblem:
    """A manoeuvring collector ranging to fixed beacons, from a wide prior.

    Attributes
    ----------
    prior : Prior
        The initial belief: 40 m off the truth, with a 50 m standard deviation.
    start_time : float
        Time of the prior, s.
    steps : list of BeaconStep
        The measurements, in order.
    """

    prior: Prior
    start_time: float
    steps: list[BeaconStep]


def beacon_problem(
    seed: int = 0, steps: int = 240, sigma: float = 0.1, nearest: int = 4
) -> BeaconProblem:
    """The standard localisation problem: 120 s at 2 Hz, ranges to the nearest beacons.

    Parameters
    ----------
    seed : int
        Seed of the range noise.
    steps : int
        Number of predict/update steps (0.5 s each).
    sigma : float
        Range noise standard deviation, m.
    nearest : int
        Beacons reported per step.
    """
    rng = np.random.default_rng(seed)
    dt = 0.5
    position = np.array([10.0, -20.0, 5.0])
    velocity = np.array([0.2, 0.1, 0.0])
    prior = Prior(
        position=position + [30.0, -20.0, 20.0],
        position_sigma=50.0,
        velocity=np.zeros(3),
        velocity_sigma=0.5,
    )
    out = []
    for k in range(steps):
        acceleration = 0.01 * np.array([np.sin(0.05 * k), np.cos(0.03 * k), -np.sin(0.02 * k)])
        position = position + velocity * dt + 0.5 * acceleration * dt**2
        velocity = velocity + acceleration * dt
        distances = np.linalg.norm(BEACONS - position, axis=1)
        order = np.argsort(distances)[:nearest]
        measured = distances[order] + rng.normal(0.0, sigma, len(order))
        ranges = [
            BeaconRange(int(i), BEACONS[i], float(r), sigma)
            for i, r in zip(order, measured, strict=True)
        ]
        out.append(BeaconStep(MotionInput(acceleration), dt, ranges, position.copy()))
    return BeaconProblem(prior, 0.0, out)


def target_track(
    target_id: int, position, velocity=(0.0, 0.0, 0.0), time: float = 100.0
) -> ObjectTrack:
    """A target observed at ``time`` moving in a straight line."""
    motion = LinearMotion(position, velocity, epoch=time)
    return ObjectTrack(
        target_id, ObjectKind.TARGET, time, position, velocity, mass=5.0, radius=0.3, motion=motion
    )


def obstacle_track(
    obstacle_id: int,
    position,
    velocity=(0.0, 0.0, 0.0),
    radius: float = 1.0,
    time: float = 0.0,
    shape: Shape | None = None,
) -> ObjectTrack:
    """An obstacle observed at ``time`` moving in a straight line (a sphere of ``radius``
    unless ``shape`` is given)."""
    motion = LinearMotion(position, velocity, epoch=time)
    return ObjectTrack(
        obstacle_id,
        ObjectKind.OBSTACLE,
        time,
        position,
        velocity,
        mass=50.0,
        motion=motion,
        shape=Shape(ShapeKind.SPHERE, radius=radius) if shape is None else shape,
    )


def task_request(targets: int = 6, time_budget: float = 1.0, capacity: int = 2) -> TaskRequest:
    """The standard task-planning request: slow targets within 40 m, capacity 2.

    Every target is reachable well within an hour at the request's limits.
    """
    rng = np.random.default_rng(7)
    tracks = tuple(
        target_track(i + 1, rng.uniform(-40.0, 40.0, 3), rng.normal(0.0, 0.01, 3))
        for i in range(targets)
    )
    return TaskRequest(
        time=100.0,
        robot=StateEstimate(time=100.0, position=np.zeros(3), converged=True),
        targets=tracks,
        drop_point=DropPoint(StaticMotion((-5.0, 0.0, 0.0)), tolerance=1.5),
        capacity=capacity,
        carried=0,
        max_speed=ROBOT.max_speed,
        max_acceleration=0.025,
        time_budget=time_budget,
    )


GOAL = np.array([40.0, 5.0, 0.0])
"""Centre of the standard path problem's goal region, m."""

SAFETY_MARGIN = 0.2
"""Safety margin of the standard path problem, m."""

WIDE_MARGIN = 1.0
"""Safety margin of the margin problem (:func:`margin_problem`), m."""

DIRECT_GAP = 0.5
"""Surface gap between the robot's sphere and the margin problem's obstacle on the
direct line, m: less than :data:`WIDE_MARGIN`."""


def path_problem(time_budget: float = 1.0) -> PathProblem:
    """The standard path problem: 40 m across a box, obstacles near but off the direct line.

    Three spheres (two of them moving), a turned box and a turned cylinder; a safety
    margin of :data:`SAFETY_MARGIN`.
    """
    box = Shape(
        ShapeKind.BOX, half_extents=np.array([1.5, 1.0, 2.0]), orientation=_turn((0, 0, 1), 30)
    )
    cylinder = Shape(ShapeKind.CYLINDER, radius=1.0, height=3.0, orientation=_turn((1, 0, 0), 60))
    return PathProblem(
        start=RobotState(time=0.0, position=np.zeros(3)),
        goal=GoalRegion(position=GOAL, tolerance=1.0),
        obstacles=(
            obstacle_track(1, (20.0, 12.0, 0.0), radius=2.0),
            obstacle_track(2, (10.0, -8.0, 3.0), velocity=(0.0, -0.05, 0.0)),
            obstacle_track(3, (30.0, 3.0, 12.0), velocity=(0.0, 0.0, 0.1), radius=1.5),
            obstacle_track(4, (25.0, -4.0, 0.0), shape=box),
            obstacle_track(5, (12.0, 6.0, -3.0), shape=cylinder),
        ),
        robot_radius=ROBOT.radius,
        max_speed=ROBOT.max_speed,
        max_acceleration=0.025,
        max_delta_v=5.0,
        bounds=Bounds(lower=np.array([-10.0, -30.0, -30.0]), upper=np.array([60.0, 30.0, 30.0])),
        time_budget=time_budget,
        safety_margin=SAFETY_MARGIN,
    )


def margin_problem(time_budget: float = 1.0) -> PathProblem:
    """A 40 m transfer along x past one static sphere (radius 2 m) beside the direct line:
    flown straight, the robot's sphere passes :data:`DIRECT_GAP` from it, inside the
    problem's safety margin of :data:`WIDE_MARGIN`, so a path that keeps the margin
    bends away from the sphere. Otherwise as the standard problem."""
    side = ROBOT.radius + 2.0 + DIRECT_GAP
    return dataclasses.replace(
        path_problem(time_budget),
        goal=GoalRegion(position=np.array([40.0, 0.0, 0.0]), tolerance=1.0),
        obstacles=(obstacle_track(1, (20.0, side, 0.0), radius=2.0),),
        safety_margin=WIDE_MARGIN,
    )


def _turn(axis, degrees: float) -> np.ndarray:
    """The rotation ``[x, y, z, w]`` by ``degrees`` about the unit ``axis``."""
    half = np.radians(degrees) / 2
    return np.append(np.sin(half) * np.asarray(axis, dtype=float), np.cos(half))


def arrival_problem(time_budget: float = 1.0) -> PathProblem:
    """The standard path problem with a demanding goal: arrive at rest (within 0.01 m/s),
    turned a quarter about z (within 1°), at t = 150 s (within 1 s)."""
    problem = path_problem(time_budget)
    goal = GoalRegion(
        position=GOAL,
        tolerance=1.0,
        time=150.0,
        attitude=_turn((0, 0, 1), 90),
        attitude_tolerance=np.radians(1.0),
        velocity_tolerance=0.01,
        time_tolerance=1.0,
    )
    return dataclasses.replace(problem, goal=goal)


def impossible_path_problem(time_budget: float = 1.0) -> PathProblem:
    """The standard path problem with the goal inside a static obstacle."""
    problem = path_problem(time_budget)
    blocker = obstacle_track(9, GOAL, radius=3.0)
    return dataclasses.replace(problem, obstacles=(*problem.obstacles, blocker))


def blocked_start_problem(time_budget: float = 1.0) -> PathProblem:
    """The standard path problem with the start inside a static obstacle."""
    problem = path_problem(time_budget)
    blocker = obstacle_track(9, (0.0, 0.5, 0.0), radius=2.0)
    return dataclasses.replace(problem, obstacles=(*problem.obstacles, blocker))


def enclosed_goal_problem(time_budget: float = 1.0, shell: int = 60) -> PathProblem:
    """The standard path problem with the goal walled in: ``shell`` static spheres of
    radius 1.2 m, 4 m from the goal, leave no gap the robot (radius 0.5 m) fits through.

    Centres are spread evenly on the sphere (a Fibonacci lattice): 60 of them are under
    2 m apart, so every hole is narrower than the robot.
    """
    problem = path_problem(time_budget)
    k = np.arange(shell) + 0.5
    polar = np.arccos(1.0 - 2.0 * k / shell)
    azimuth = np.pi * (1.0 + np.sqrt(5.0)) * k
    directions = np.stack(
        [np.sin(polar) * np.cos(azimuth), np.sin(polar) * np.sin(azimuth), np.cos(polar)], axis=-1
    )
    wall = tuple(
        obstacle_track(100 + i, GOAL + 4.0 * d, radius=1.2) for i, d in enumerate(directions)
    )
    return dataclasses.replace(problem, obstacles=(*problem.obstacles, *wall))


def outside_bounds_problem(time_budget: float = 1.0) -> PathProblem:
    """The standard path problem with the goal beyond its bounds."""
    problem = path_problem(time_budget)
    goal = dataclasses.replace(problem.goal, position=np.array([80.0, 5.0, 0.0]))
    return dataclasses.replace(problem, goal=goal)


def held_still(problem: PathProblem) -> PathProblem:
    """``problem`` with every obstacle held at rest where it is at the start time."""
    t = problem.start.time
    still = []
    for track in problem.obstacles:
        position = track.predict(t)[0]
        still.append(
            dataclasses.replace(
                track,
                time=t,
                position=position,
                velocity=np.zeros(3),
                motion=StaticMotion(position),
            )
        )
    return dataclasses.replace(problem, obstacles=tuple(still))


def posed(plugin_class: type[Plugin], problem: PathProblem) -> PathProblem:
    """A path problem as the conformance suite poses it to ``plugin_class``: unchanged, or
    with its obstacles held still (:func:`held_still`) for a planner that declares it
    handles static obstacles only (``handles_moving_obstacles = False``)."""
    if getattr(plugin_class, "handles_moving_obstacles", True):
        return problem
    return held_still(problem)


def reach_problem(
    time_budget: float = 5.0, target: tuple[float, float, float] = (1.5, 0.7, -1.0)
) -> PathProblem:
    """The packaged reach scenario's problem (the thesis's robot and reach): the end
    effector from [1.4, 0.9, −0.8] m to ``target`` (m), arriving within 1 mm, at most
    0.1 m/s and 0.1 m/s², with ``time_budget`` (s) to plan."""
    from dcsim.robots.loading import load_reach_problem  # the missions load the world engine

    point = [float(v) for v in target]
    overrides = [f"mission.target={point!r}", f"mission.planning_budget={float(time_budget)!r}"]
    return load_reach_problem(
        packaged_scenario_path("space_manipulator_reach.yaml"), None, overrides
    )


MANIPULATOR_JOINTS = np.array([0.76, 0.6, -2.33, 3.08, -2.36, -0.6])
"""A configuration of the thesis's arm away from singularities, rad."""


def manipulator_robot() -> RobotSpec:
    """The thesis's manipulator with limits low enough for the standard ticks to reach
    them: 20 N of thrust, 5 N·m of base torque, 2 N·m per joint."""
    return thesis_robot(max_force=20.0, max_torque=5.0, joint_torque=2.0)


def manipulator_ticks(empty: bool = False) -> list:
    """The standard controller ticks for a manipulator controller: ``[robot, ticks]`` with
    20 ticks at 10 Hz of estimates and references scattered about
    :data:`MANIPULATOR_JOINTS` (base within decimetres and a few degrees of the origin),
    among the standard path problem's obstacles unless ``empty``."""
    rng = np.random.default_rng(5)
    obstacles = () if empty else path_problem().obstacles
    n = MANIPULATOR_JOINTS.size

    def state(time: float) -> dict:
        turn = quaternion_from_rotation_vector(rng.normal(0.0, 0.05, 3))
        return dict(
            time=time,
            position=rng.normal(0.0, 0.1, 3),
            attitude=turn,
            velocity=rng.normal(0.0, 0.02, 3),
            angular_velocity=rng.normal(0.0, 0.02, 3),
            joint_positions=MANIPULATOR_JOINTS + rng.normal(0.0, 0.2, n),
            joint_velocities=rng.normal(0.0, 0.05, n),
        )

    ticks = []
    for k in range(20):
        t = 0.1 * k
        estimate = StateEstimate(**state(t), converged=True)
        wanted = state(t)
        reference = Reference(
            **wanted,
            acceleration=rng.normal(0.0, 0.01, 3),
            angular_acceleration=rng.normal(0.0, 0.01, 3),
            joint_accelerations=rng.normal(0.0, 0.05, n),
        )
        ticks.append((t, estimate, reference, Surroundings(obstacles)))
    return [manipulator_robot(), ticks]


def hardware_scenario(
    duration: float, position: Sequence[float], attitude: Sequence[float]
) -> dict[str, Any]:
    """A free flyer with the packaged ``default_hardware`` scenario's robot (12 thrusters in
    six opposed couples, 4 wheels in a pyramid), alone in a frame without orbital forces,
    starting at rest at ``position`` (m) with ``attitude`` ``[x, y, z, w]``, under a
    ``hold`` mission of ``duration`` seconds."""
    import yaml  # imported here: only this problem reads a scenario file

    packaged = yaml.safe_load(packaged_scenario_path("default_hardware.yaml").read_text())
    robot = packaged["robot"]
    robot["initial"] = {"position": list(position), "attitude": list(attitude)}
    return {
        "name": "hardware",
        "world": {"frame": "geocentric", "duration": duration},
        "robot": robot,
        "mission": {"type": "hold"},
    }


# --------------------------------------------------------------------- sensing

SENSING_PERIOD = 0.1
"""Control period of the standard sensing problems, s."""

SENSED_OBJECTS = (
    KnownObject(3, ObjectKind.TARGET, 5.0, Shape(ShapeKind.SPHERE, radius=0.3)),
    KnownObject(
        8, ObjectKind.OBSTACLE, 80.0, Shape(ShapeKind.BOX, half_extents=np.array([1.0, 0.5, 0.4]))
    ),
    KnownObject(11, ObjectKind.OBSTACLE, 40.0, Shape(ShapeKind.CYLINDER, radius=0.4, height=2.0)),
    KnownObject(20, ObjectKind.TARGET, 8.0, Shape(ShapeKind.SPHERE, radius=0.5)),
    KnownObject(42, ObjectKind.OBSTACLE, 60.0, Shape(ShapeKind.SPHERE, radius=1.0)),
)
"""The objects of the standard sensing problem: the first four within the object
sensor's 30 m, the last 55 m off; object 20 is held by the robot (not free) after 10 s."""

_OBJECT_STARTS = np.array(
    [
        [12.0, -5.0, 3.0],
        [-8.0, 10.0, -4.0],
        [4.0, 15.0, 9.0],
        [-15.0, -6.0, 2.0],
        [45.0, 30.0, 10.0],
    ]
)
_OBJECT_VELOCITIES = np.array(
    [
        [-0.02, 0.01, 0.0],
        [0.03, -0.01, 0.005],
        [0.0, -0.02, 0.01],
        [0.01, 0.02, -0.01],
        [0.0, 0.0, 0.0],
    ]
)


def sensor_setup(empty: bool = False) -> SensorSetup:
    """What the standard sensing problem tells a sensor model: the five beacons of the
    beacon problem (5 cm noise, the nearest 3 reported) and :data:`SENSED_OBJECTS` within
    an object sensor's 30 m, at 10 Hz; with ``empty``, no beacons and no objects."""
    return SensorSetup(
        control_period=SENSING_PERIOD,
        beacons=np.zeros((0, 3)) if empty else BEACONS,
        beacon_noise=0.05,
        beacon_report_nearest=3,
        object_range=30.0,
        objects=() if empty else SENSED_OBJECTS,
    )


def sensed_truths(steps: int = 200, empty: bool = False) -> list[SensedTruth]:
    """The true states of the standard sensing problem, one per control tick (10 Hz): a
    robot drifting at 5 cm/s and turning at about 1.5 °/s, and the objects of
    :func:`sensor_setup` drifting in straight lines (none with ``empty``)."""
    rate = np.array([0.01, -0.02, 0.015])  # world frame, rad/s
    start = quaternion_from_rotation_vector([0.3, -0.2, 0.5])
    truths = []
    for k in range(steps):
        t = k * SENSING_PERIOD
        count = 0 if empty else len(SENSED_OBJECTS)
        free = np.ones(count, dtype=bool)
        if count:
            free[3] = t < 10.0
        truths.append(
            SensedTruth(
                time=t,
                position=np.array([5.0, -3.0, 2.0]) + np.array([0.05, 0.02, 0.0]) * t,
                velocity=np.array([0.05, 0.02, 0.0]),
                attitude=quaternion_multiply(quaternion_from_rotation_vector(rate * t), start),
                angular_velocity=rate,
                object_positions=(_OBJECT_STARTS + _OBJECT_VELOCITIES * t)[:count],
                object_velocities=_OBJECT_VELOCITIES[:count],
                free=free,
            )
        )
    return truths


@dataclass(frozen=True)
class TrackerTick:
    """One control tick of the standard tracking problem.

    Attributes
    ----------
    time : float
        s.
    detections : tuple of Detection
        The object sensor's detections now.
    robot : StateEstimate
        The robot's estimate (position within its covariance of the truth).
    truth : dict of int to ndarray (3,)
        The true position of every object detected now, by id (for scoring only).
    """

    time: float
    detections: tuple[Detection, ...]
    robot: StateEstimate
    truth: dict[int, np.ndarray]


@dataclass(frozen=True)
class TrackerProblem:
    """Detections of objects drifting in an orbit's LVLH frame, as a tracker gets them.

    Attributes
    ----------
    frame : FrameDynamics
        Clohessy–Wiltshire, 400 km circular orbit.
    start_time : float
        s.
    ticks : list of TrackerTick
        In order, at 10 Hz.
    """

    frame: FrameDynamics
    start_time: float
    ticks: list[TrackerTick]


TRACKED_IDS = (3, 8, 11, 20, 42)
"""Identities of the standard tracking problem's objects; 42 is seen for the first 15 s only."""


def tracker_problem(steps: int = 300, empty: bool = False, seed: int = 9) -> TrackerProblem:
    """The standard tracking problem: five objects on Clohessy–Wiltshire motions within
    40 m, detected at 10 Hz with 5 cm of Gaussian noise per axis by a robot whose
    position estimate errs by 2 cm per axis (its covariance says so); object 42 leaves
    view after 15 s. ``empty``: no detections at all."""
    rng = np.random.default_rng(seed)
    frame = FrameDynamics(kind=FrameKind.CLOHESSY_WILTSHIRE, mean_motion=mean_motion(6_778_137.0))
    objects = MotionSet(
        [
            ClohessyWiltshireMotion(p, v, frame.mean_motion)
            for p, v in zip(_OBJECT_STARTS * 0.8, _OBJECT_VELOCITIES, strict=True)
        ]
    )
    covariance = np.eye(3) * 0.05**2
    robot_covariance = np.diag([0.02, 0.02, 0.02, 0.001, 0.001, 0.001]) ** 2
    ticks = []
    for k in range(steps):
        t = k * SENSING_PERIOD
        robot = np.array([0.03 * t, 2.0 * np.sin(0.02 * t), -0.01 * t])
        estimate = StateEstimate(
            time=t,
            position=robot + rng.normal(0.0, 0.02, 3),
            covariance=robot_covariance,
            converged=True,
        )
        positions = objects.state_at(t)[0]
        seen = [] if empty else [i for i, n in enumerate(TRACKED_IDS) if n != 42 or t < 15.0]
        detections = tuple(
            Detection(
                time=t,
                id=TRACKED_IDS[i],
                kind=SENSED_OBJECTS[i].kind,
                relative_position=positions[i] - robot + rng.normal(0.0, 0.05, 3),
                covariance=covariance,
                radius=SENSED_OBJECTS[i].shape.bounding_radius,
                mass=SENSED_OBJECTS[i].mass,
            )
            for i in seen
        )
        truth = {TRACKED_IDS[i]: positions[i] for i in seen}
        ticks.append(TrackerTick(t, detections, estimate, truth))
    return TrackerProblem(frame, 0.0, ticks)
