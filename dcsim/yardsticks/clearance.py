"""The swept clearance of a trajectory: the yardstick of path planners.

An independent check of a planned trajectory against the obstacles' true shapes
(spheres, and boxes and cylinders with their orientation, ``ObjectTrack.shape``), as the
obstacles move by their motion models (``ObjectTrack.predict``). The robot is the sphere
of ``robot_radius`` about the trajectory's position, interpolated as
:meth:`Trajectory.sample` does. Exact point-to-shape distances in numpy, vectorised over
the time samples; no PyBullet, so it checks the world's collision geometry rather than
sharing it.

The trajectory is sampled every ``step`` seconds and at each of its own samples. Between
two time samples the robot and an obstacle move apart or together by at most their
relative displacement over the step, so the sampled minimum overestimates the true one
by at most half of it: choose ``step`` so that this is small against the clearance that
matters (:func:`resolution_step` does; :func:`path_clearance` puts the two together for a
planner's answer to a :class:`PathProblem`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from dcsim.geometry import Vector, quaternion_conjugate, rotate
from dcsim.messages import ObjectTrack, PathProblem, Shape, ShapeKind, Trajectory

RESOLUTION = 0.1
"""Default largest change of a gap between two samples of :func:`path_clearance`, in robot
radii (at least :data:`MIN_RESOLUTION`)."""

MIN_RESOLUTION = 0.01
"""Least resolution of :func:`path_clearance`, m (for a robot of radius 0)."""


@dataclass(frozen=True)
class Clearance:
    """The closest approach of a robot flying a trajectory to a set of obstacles.

    Attributes
    ----------
    distance : float
        Smallest surface gap between the robot's sphere and any obstacle, m; negative
        is a penetration depth; ``inf`` without obstacles.
    time : float
        When it occurs, s.
    position : ndarray (3,)
        The robot's centre then, m.
    obstacle_id : int or None
        The obstacle it is closest to (None without obstacles).
    collides : bool
        Whether any time sample has a negative gap (the world counts contact there).
    samples : int
        Number of time samples checked.
    """

    distance: float
    time: float
    position: Vector
    obstacle_id: int | None
    collides: bool
    samples: int


def surface_distance(shape: Shape, centres: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Signed distance from each point to the surface of the shape placed at each centre.

    Parameters
    ----------
    shape : Shape
        Sphere, or box or cylinder turned by ``shape.orientation`` (body to world).
    centres, points : ndarray (N, 3)
        The shape's centre and the point at each sample, m.

    Returns
    -------
    ndarray (N,)
        Distance to the surface, m; negative inside the shape.
    """
    offsets = np.asarray(points, dtype=float) - np.asarray(centres, dtype=float)
    if shape.kind is ShapeKind.SPHERE:
        return np.linalg.norm(offsets, axis=-1) - shape.radius
    return body_surface_distance(shape, rotate(quaternion_conjugate(shape.orientation), offsets))


def body_surface_distance(shape: Shape, offsets: np.ndarray) -> np.ndarray:
    """Signed distance to the surface of a shape from points given in its body frame.

    Parameters
    ----------
    shape : Shape
        Sphere, box or cylinder (its orientation is not used: the offsets are already
        in its body frame).
    offsets : ndarray (N, 3)
        Points relative to the shape's centre, along its body axes, m.

    Returns
    -------
    ndarray (N,)
        Distance to the surface, m; negative inside the shape.
    """
    body = np.asarray(offsets, dtype=float)
    if shape.kind is ShapeKind.SPHERE:
        return np.linalg.norm(body, axis=-1) - shape.radius
    if shape.kind is ShapeKind.BOX:
        excess = np.abs(body) - shape.half_extents
    else:
        excess = np.stack(
            [
                np.hypot(body[:, 0], body[:, 1]) - shape.radius,
                np.abs(body[:, 2]) - 0.5 * shape.height,
            ],
            axis=-1,
        )
    return _box_distance(excess)


def _box_distance(excess: np.ndarray) -> np.ndarray:
    """Signed distance to an axis-aligned box (or a cylinder's (radial, axial) rectangle)
    from the amounts ``|x| - half extent`` by which each coordinate exceeds it."""
    outside = np.linalg.norm(np.maximum(excess, 0.0), axis=-1)
    inside = np.minimum(excess.max(axis=-1), 0.0)
    return outside + inside


def sample_times(trajectory: Trajectory, step: float) -> np.ndarray:
    """Every ``step`` s from the trajectory's start to its end, and its own sample times, s.

    Raises
    ------
    ValueError
        If ``step`` is not positive.
    """
    if not step > 0:
        raise ValueError(f"the time step must be positive, got {step}")
    start, end = trajectory.times[0], trajectory.times[-1]
    return np.union1d(np.arange(start, end, step), trajectory.times)


def min_clearance(
    trajectory: Trajectory,
    obstacles: Sequence[ObjectTrack],
    robot_radius: float,
    step: float,
) -> Clearance:
    """The smallest surface gap between the robot's sphere and every obstacle's true shape.

    Parameters
    ----------
    trajectory : Trajectory
        The robot's path; positions are interpolated linearly between its samples.
    obstacles : sequence of ObjectTrack
        Obstacles with their shape and motion model (``predict``).
    robot_radius : float
        Radius of the robot's sphere, m.
    step : float
        Time between samples, s (the trajectory's own samples are checked as well).

    Returns
    -------
    Clearance
        The gap, where and when it occurs, and whether any sample collides.
    """
    times = sample_times(trajectory, step)
    positions, _ = trajectory.sample(times)
    distance, where, nearest, collides = np.inf, 0, None, False
    for obstacle in obstacles:
        centres, _ = obstacle.predict(times)
        assert obstacle.shape is not None  # a track without one is given its radius's sphere
        gaps = surface_distance(obstacle.shape, centres, positions) - robot_radius
        i = int(np.argmin(gaps))
        collides = collides or bool(gaps[i] < 0.0)
        if gaps[i] < distance:
            distance, where, nearest = float(gaps[i]), i, obstacle.id
    return Clearance(distance, float(times[where]), positions[where], nearest, collides, len(times))


def resolution_step(
    trajectory: Trajectory, obstacles: Sequence[ObjectTrack], resolution: float
) -> float:
    """A time step over which no robot-obstacle pair closes by more than ``resolution``.

    The bound is the trajectory's fastest segment (its positions are linear between
    samples) plus the fastest obstacle at the trajectory's sample times (exact for
    obstacles in straight-line motion; for curved motion, as exact as those samples
    resolve its speed).

    Parameters
    ----------
    trajectory : Trajectory
        The robot's path.
    obstacles : sequence of ObjectTrack
        The obstacles.
    resolution : float
        Largest change of a gap between two time samples, m (> 0).

    Returns
    -------
    float
        The step, s: positive, and at most the trajectory's duration.
    """
    duration = max(float(trajectory.times[-1] - trajectory.times[0]), 1e-9)
    segments = np.linalg.norm(np.diff(trajectory.positions, axis=0), axis=1)
    robot = float((segments / np.diff(trajectory.times)).max(initial=0.0))
    obstacle = max(
        (float(np.linalg.norm(o.predict(trajectory.times)[1], axis=1).max()) for o in obstacles),
        default=0.0,
    )
    closing = robot + obstacle
    return duration if closing == 0 else min(duration, resolution / closing)


def path_clearance(
    trajectory: Trajectory, problem: PathProblem, resolution: float = RESOLUTION
) -> Clearance:
    """The swept clearance of a planned trajectory against its problem's obstacles.

    Parameters
    ----------
    trajectory : Trajectory
        A path planner's answer to ``problem``.
    problem : PathProblem
        Its obstacles and robot radius.
    resolution : float
        Largest change of a gap between two samples, in robot radii; at least
        :data:`MIN_RESOLUTION` m.

    Returns
    -------
    Clearance
        As :func:`min_clearance`, at the step :func:`resolution_step` gives.
    """
    metres = max(resolution * problem.robot_radius, MIN_RESOLUTION)
    step = resolution_step(trajectory, problem.obstacles, metres)
    return min_clearance(trajectory, problem.obstacles, problem.robot_radius, step)
