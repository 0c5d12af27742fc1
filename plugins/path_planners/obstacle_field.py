"""Obstacles of a path problem, for fast "is the robot clear here?" tests, and endpoint checks.

Not a plugin itself; the path planners of this package share it.

:class:`ObstacleField`
    Is a robot sphere at a point and time clear of every obstacle's true shape? A
    vectorised bounding-sphere test over all obstacles first, then the exact distance
    (``dcsim.api.body_surface_distance``, in the shape's frame) for the few boxes and
    cylinders whose bounding sphere is touched. Obstacles in straight-line or no motion
    (``StaticMotion``, ``LinearMotion`` or none) are predicted in closed form, others
    by ``predict``.
    For swept checks, :meth:`ObstacleField.clear_arcs` says which sampled arcs are
    clear and :meth:`ObstacleField.arc_overlaps` how deep each goes into an obstacle.
:func:`endpoint_refusal`
    "No path" with a reason when the start is outside the bounds or inside an obstacle,
    or when every probe point of the goal region is; :func:`goal_or_refusal` adds the
    first clear probe point of the goal region, for the planners that aim at one.
"""

from __future__ import annotations

import numpy as np

from dcsim.api import (
    LinearMotion,
    NoPath,
    ObjectTrack,
    PathProblem,
    ShapeKind,
    StaticMotion,
    Trajectory,
    body_surface_distance,
    quaternion_conjugate,
    rotate,
)


class ObstacleField:
    """The obstacles of a path problem, for fast "is this robot sphere clear?" tests.

    Parameters
    ----------
    problem : PathProblem
        Its obstacles (true shapes and predicted motion), ``robot_radius`` and
        ``safety_margin``: a sphere is clear when it keeps the margin beyond its radius.
    """

    def __init__(self, problem: PathProblem) -> None:
        self.tracks = problem.obstacles
        self.count = len(self.tracks)
        self.reach = problem.robot_radius + problem.safety_margin
        affine = [_is_affine(track.motion) for track in self.tracks]
        self.affine = np.flatnonzero(affine)
        self.curved = [i for i, ok in enumerate(affine) if not ok]
        start = [track.predict(0.0) for track in self.tracks]
        self.origin = np.array([p for p, _ in start], dtype=float).reshape(-1, 3)
        self.velocity = np.array([v for _, v in start], dtype=float).reshape(-1, 3)
        self.moving = bool(self.curved) or bool(np.any(self.velocity != 0.0))
        self.static_centres = self.origin.copy()
        self.bounding = np.array([t.radius for t in self.tracks], dtype=float)
        self.round = np.array([t.shape.kind is ShapeKind.SPHERE for t in self.tracks], dtype=bool)
        # world-to-body rotation matrices (fixed while the obstacles move)
        self.to_body = [to_body(t) for t in self.tracks]
        self.max_obstacle_speed = self._fastest(problem)

    def _fastest(self, problem: PathProblem) -> float:
        """Largest obstacle speed over the next hour from the start, m/s (sampled each
        second for curved motion)."""
        speeds = [0.0]
        if len(self.affine):
            speeds.append(float(np.linalg.norm(self.velocity[self.affine], axis=1).max()))
        times = problem.start.time + np.arange(0.0, 3600.0, 1.0)
        for i in self.curved:
            speeds.append(float(np.linalg.norm(self.tracks[i].predict(times)[1], axis=1).max()))
        return max(speeds)

    def centres(self, t: float) -> np.ndarray:
        """Obstacle centres at time ``t`` (s), (n, 3) m."""
        if not self.moving:
            return self.static_centres
        centres = self.velocity * t
        centres += self.origin
        for i in self.curved:
            centres[i] = self.tracks[i].predict(t)[0]
        return centres

    def clear(self, x: float, y: float, z: float, t: float, margin: float = 0.0) -> bool:
        """Whether the robot sphere at ``(x, y, z)`` (m) at time ``t`` (s), grown by
        ``margin`` (m), is clear of every obstacle."""
        return not self.count or self._first_hit(x, y, z, t, self.reach + margin) is None

    def _first_hit(self, x: float, y: float, z: float, t: float, reach: float) -> int | None:
        """Index of an obstacle whose surface is nearer than ``reach`` (m) to ``(x, y, z)``
        (m) at time ``t`` (s), or None."""
        offsets = self.centres(t) - (x, y, z)
        squares = offsets * offsets
        gaps = np.sqrt(np.add.reduce(squares, axis=1))
        gaps -= self.bounding
        if np.minimum.reduce(gaps) >= reach:
            return None
        for i in np.flatnonzero(gaps < reach):
            if self.round[i]:
                return int(i)
            body = self.to_body[i] @ -offsets[i]
            if body_surface_distance(self.tracks[i].shape, body[None])[0] < reach:
                return int(i)
        return None

    def clear_path(self, points: np.ndarray, times: np.ndarray, margins: np.ndarray) -> bool:
        """Whether the robot sphere is clear at every one of ``points`` (k, 3) m at
        ``times`` (k,) s, grown by ``margins`` (k,) m: bounding spheres of all obstacles
        at all times at once, then exact shapes where a bounding sphere is touched."""
        if not self.count:
            return True
        centres = self.origin[None] + self.velocity[None] * times[:, None, None]
        for i in self.curved:
            centres[:, i] = self.tracks[i].predict(times)[0]
        reach = self.reach + margins
        gaps = np.linalg.norm(centres - points[:, None], axis=2) - self.bounding
        near = gaps < reach[:, None]
        for j in np.flatnonzero(near.any(axis=0)):
            if self.round[j]:
                return False
            rows = near[:, j]
            body = (points[rows] - centres[rows, j]) @ self.to_body[j].T
            exact = body_surface_distance(self.tracks[j].shape, body)
            if np.any(exact < reach[rows]):
                return False
        return True

    @property
    def resting_indices(self) -> np.ndarray:
        """Indices of the obstacles at rest."""
        resting = np.zeros(self.count, dtype=bool)
        resting[self.affine] = ~np.any(self.velocity[self.affine] != 0.0, axis=1)
        return np.flatnonzero(resting)

    @property
    def moving_indices(self) -> np.ndarray:
        """Indices of the obstacles that move."""
        return np.setdiff1d(np.arange(self.count), self.resting_indices)

    def clear_arcs(
        self, points: np.ndarray, times: np.ndarray, margins: np.ndarray, which: np.ndarray
    ) -> np.ndarray:
        """Whether each arc is clear: the robot sphere at every sample of arc ``a``, grown
        by ``margins[a]``, against the obstacles ``which``.

        Parameters
        ----------
        points : ndarray (m, s, 3)
            ``s`` samples of each of ``m`` arcs, m.
        times : ndarray (m, s)
            Their times, s.
        margins : ndarray (m,)
            Growth of the robot's sphere on each arc, m.
        which : ndarray of int
            Indices of the obstacles to check (:attr:`resting_indices`, :attr:`moving_indices`).

        Returns
        -------
        ndarray of bool (m,)
        """
        return self.arc_overlaps(points, times, margins, which) <= 0.0

    def clear_trajectory(self, trajectory: Trajectory, spacing: float) -> bool:
        """Whether the robot sphere is clear along a whole trajectory (positions linear
        between its samples), checked at times over which robot and obstacles close by
        at most ``spacing`` (m), each check's sphere grown by half of that."""
        segments = np.linalg.norm(np.diff(trajectory.positions, axis=0), axis=1)
        speed = float((segments / np.diff(trajectory.times)).max(initial=0.0))
        closing = speed + self.max_obstacle_speed
        span = float(trajectory.times[-1] - trajectory.times[0])
        count = max(int(np.ceil(closing * span / spacing)), 1) + 1
        times = np.union1d(
            np.linspace(trajectory.times[0], trajectory.times[-1], count), trajectory.times
        )
        points, _ = trajectory.sample(times)
        return self.clear_path(points, times, np.full(len(times), 0.5 * spacing))

    def arc_overlaps(
        self, points: np.ndarray, times: np.ndarray, margins: np.ndarray, which: np.ndarray
    ) -> np.ndarray:
        """How deep each arc goes into an obstacle: the largest overlap of the robot
        sphere, grown by ``margins[a]``, with the true shape of any of the obstacles
        ``which``, over the samples of arc ``a``; 0 where it is clear (exactly where
        :meth:`clear_arcs` says so).

        Parameters
        ----------
        points : ndarray (m, s, 3)
            ``s`` samples of each of ``m`` arcs, m.
        times : ndarray (m, s)
            Their times, s.
        margins : ndarray (m,)
            Growth of the robot's sphere on each arc, m.
        which : ndarray of int
            Indices of the obstacles to check.

        Returns
        -------
        ndarray (m,)
            Largest overlap, m (robot reach plus margin minus the gap to the surface).
        """
        depth = np.zeros(len(points))
        if not len(which):
            return depth
        centres = self._arc_centres(times, which, points.shape)
        reach = (self.reach + margins)[:, None]
        offsets = points[:, :, None, :] - centres
        gaps = np.linalg.norm(offsets, axis=-1) - self.bounding[which]
        near = gaps < reach[..., None]
        for column in np.flatnonzero(near.any(axis=(0, 1))):
            i = which[column]
            arcs, samples = np.nonzero(near[:, :, column])
            if self.round[i]:
                exact = gaps[arcs, samples, column]
            else:
                body = offsets[arcs, samples, column] @ self.to_body[i].T
                exact = body_surface_distance(self.tracks[i].shape, body)
            np.maximum.at(depth, arcs, reach[arcs, 0] - exact)
        return depth

    def _arc_centres(
        self, times: np.ndarray, which: np.ndarray, shape: tuple[int, ...]
    ) -> np.ndarray:
        """Centres of the obstacles ``which`` at ``times`` (m, s), (m, s, len(which), 3) m;
        ``shape`` is that of the samples, (m, s, 3)."""
        centres = self.origin[which] + self.velocity[which] * times[..., None, None]
        for column, i in enumerate(which):
            if i in self.curved:
                centres[:, :, column] = self.tracks[i].predict(times.ravel())[0].reshape(shape)
        return centres

    def blocker(self, point: np.ndarray, t: float) -> int | None:
        """Id of an obstacle the robot sphere at ``point`` (m) at ``t`` (s) overlaps."""
        if not self.count:
            return None
        x, y, z = map(float, point)
        hit = self._first_hit(x, y, z, t, self.reach)
        return None if hit is None else self.tracks[hit].id


def to_body(track: ObjectTrack) -> np.ndarray:
    """World-to-body rotation matrix of an obstacle's shape."""
    return rotate(quaternion_conjugate(track.shape.orientation), np.eye(3)).T


def _is_affine(motion: object) -> bool:
    """Whether a motion model is a straight line at constant velocity (or rest)."""
    return motion is None or isinstance(motion, (StaticMotion, LinearMotion))


def goal_probes(problem: PathProblem) -> np.ndarray:
    """Points of the goal region: its centre, the ends of its axes and, for a box, its
    corners and the middles of its edges and faces, (k, 3) m."""
    goal = problem.goal
    if goal.half_extents is None:
        offsets = np.vstack([np.zeros(3), np.eye(3), -np.eye(3)]) * goal.tolerance
    else:
        grid = np.array(np.meshgrid([0, -1, 1], [0, -1, 1], [0, -1, 1], indexing="ij"))
        offsets = grid.reshape(3, -1).T * goal.half_extents
    return goal.position + offsets


def endpoint_refusal(problem: PathProblem, field: ObstacleField) -> NoPath | None:
    """NoPath if the start is outside the bounds or inside an obstacle, or if every probe
    point of the goal region (:func:`goal_probes`) is outside the bounds or inside an
    obstacle (at the goal's time, or the start's); None otherwise."""
    start, bounds = problem.start, problem.bounds
    if bounds is not None and not bool(bounds.contains(start.position)):
        return NoPath("the start is outside the bounds")
    hit = field.blocker(start.position, start.time)
    if hit is not None:
        return NoPath(
            f"the start is inside obstacle {hit} (robot radius and safety margin included)"
        )
    probes = goal_probes(problem)
    if bounds is not None:
        probes = probes[bounds.contains(probes)]
        if not len(probes):
            return NoPath("the goal region is outside the bounds")
    t = problem.goal.time if problem.goal.time is not None else start.time
    blockers = [field.blocker(p, t) for p in probes]
    if all(b is not None for b in blockers):
        return NoPath(f"the goal region is inside obstacle {blockers[0]}")
    return None


def free_goal_point(problem: PathProblem, field: ObstacleField) -> np.ndarray | None:
    """The first probe point of the goal region that is in bounds and clear, m."""
    t = problem.goal.time if problem.goal.time is not None else problem.start.time
    for point in goal_probes(problem):
        inside = problem.bounds is None or bool(problem.bounds.contains(point))
        if inside and field.blocker(point, t) is None:
            return point
    return None


def goal_or_refusal(problem: PathProblem, field: ObstacleField) -> NoPath | np.ndarray:
    """:func:`endpoint_refusal`, or "no path" when no probe point of the goal region is in
    bounds and clear, or else the first that is (:func:`free_goal_point`), m."""
    refusal = endpoint_refusal(problem, field)
    if refusal is not None:
        return refusal
    goal = free_goal_point(problem, field)
    if goal is None:
        return NoPath("no point of the goal region is clear of the obstacles")
    return goal
