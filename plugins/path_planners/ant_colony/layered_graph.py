"""The candidate graph of ``ant-colony``: one point on each of m cross-sections of the
start-goal segment (eqs 4–9 of the ant colony paper).

Not a plugin itself; :mod:`ant_colony` builds it (:func:`build_graph`), :mod:`colony`
searches it and ``dcsim.api.layered_optimum`` solves it exactly.

Candidate graph (:func:`build_graph`, eqs 4–5)
    The segment from the start S to the goal G is cut into ``parts`` (m) equal parts of
    length ``Δd = |SG| / m`` (eq. 4). The plane perpendicular to SG at each of the m − 1
    division points is a cross-section. With ``cross_section: line`` (the paper) it holds
    the 2n + 1 points ``c_i + j s e₁`` (j = −n … n) along one axis ``e₁`` of that plane;
    with ``grid`` (the three-dimensional generalisation) the (2n + 1)² points
    ``c_i + j s e₁ + k s e₂``; ``s = half_width / n`` (``points`` is n). ``e₁`` is
    ``line_axis`` projected onto the plane, or, unset, the world axis least aligned with
    SG (the first of x, y, z on ties: y for a segment along x); ``e₂ = SG/|SG| × e₁``.
    A path is the start, one point of each cross-section in order, and the goal (eq. 5);
    it is stored as one node index per layer, layer 0 holding the start and layer m the
    goal (as node 0; their other nodes are unusable padding, so every layer has the
    same number of nodes). S is where the robot comes to rest when it moves, G the goal
    region's centre or its first clear probe point (:func:`endpoints`).
Clearance of a node (eqs 7, 9)
    ``d_min``: the distance from the robot's sphere, grown by the problem's
    ``safety_margin``, to the surface of the nearest obstacle's TRUE shape (sphere,
    turned box or cylinder), that is the surface distance of the point minus
    ``robot_radius + safety_margin``. A node with
    ``d_min ≤ 0`` or outside the problem's bounds is unusable.
Segments (eq. 6)
    A segment between consecutive layers has its Euclidean length, ``√(Δd² + |Δz'|²)``
    with ``Δz'`` the offset change across the plane, or infinite length when the robot's
    grown sphere, swept along it, touches an obstacle (the paper: "intersected or
    tangent"); such segments are never chosen. The test is vectorised over every
    candidate pair of every layer once per problem, obstacle by obstacle, for the layers
    the obstacle can reach along SG. Spheres: the exact least distance from the centre to
    the segment. Boxes and cylinders: a bounding-sphere test, then, where it is touched,
    exact surface distances (``body_surface_distance``) at points at most
    ``check_spacing`` apart along the segment, less half that spacing (a lower bound on
    the true least distance, so the test is conservative: :func:`segment_gaps`). Nodes
    from which the goal cannot be reached are then pruned, so no ant is ever stuck.
Objective (eq. 8)
    ``F = L + δ Σᵢ 1/d_min,i`` over the m − 1 chosen points: ``L`` the path's length, δ
    the obstacle-avoidance coefficient (``delta``, m²; larger keeps further away); the
    graph holds its terms as segment ``lengths`` and ``node_cost`` (``δ/d_min``).
Moving obstacles (an extension; the paper's are at rest)
    Layer i is taken to be crossed when a nominal flight along the straight segment SG
    reaches it (:func:`nominal_times`): the trapezoid of the ``straight-line`` planner at
    ``speed_fraction`` of the speed limit, or arriving at the goal's time when it sets
    one. ``d_min`` of a node uses the obstacles' predicted places at its layer's time. A
    segment from layer i to i + 1 is tested in the obstacle's frame: the robot is taken
    to move uniformly along it from ``t_i`` to ``t_(i+1)`` while the obstacle moves from
    its place at ``t_i`` to its place at ``t_(i+1)``, so the relative motion is again a
    segment (exact for obstacles in straight-line motion, a chord of the arc otherwise).
Fewer vertices (:func:`simplify`)
    A path found in the graph is reduced to fewer vertices before it is flown: from each
    kept vertex the next kept one is the farthest whose chord is clear (the segment test
    above, at the nominal times) and passes within ``simplify_tolerance`` of every
    vertex it skips.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from dcsim_plugins.path_planners.obstacle_field import (
    ObstacleField,
    goal_or_refusal,
    to_body,
)
from dcsim_plugins.path_planners.polyline_flight import SHORTEST, Departure, departure
from dcsim_plugins.path_planners.straight_line import Profile

from dcsim.api import (
    NoPath,
    ObjectTrack,
    PathProblem,
    ShapeKind,
    body_surface_distance,
    cruise_speed,
    rest_to_rest_time,
)

if TYPE_CHECKING:
    from dcsim_plugins.path_planners.ant_colony.planner import AntColonyParams

_DEFAULT_POINTS = {"line": 10, "grid": 4}


@dataclass(frozen=True)
class LayeredGraph:
    """The candidate points of one problem and the terms of the objective F.

    Layer 0 holds the start and layer m the goal, each as node 0 (their other nodes are
    unusable padding); layers 1 … m − 1 are the cross-sections.

    Attributes
    ----------
    points : ndarray (m + 1, P, 3)
        Candidate points, m.
    times : ndarray (m + 1,)
        When each layer is taken to be crossed (nominal straight flight), s.
    clearance : ndarray (m + 1, P)
        ``d_min`` of each point: surface distance to the nearest obstacle less the robot
        radius and the clearance, m (``inf`` without obstacles; ≤ 0 inside one).
    node_cost : ndarray (m + 1, P)
        ``δ / d_min`` of each cross-section point (0 at the start and the goal, ``inf``
        for unusable nodes).
    lengths : ndarray (m, P, P)
        ``lengths[i, p, q]``: length of the segment from node p of layer i to node q of
        layer i + 1, m; ``inf`` when it is blocked or leads to a node the goal cannot be
        reached from.
    step : float
        ``Δd``, the spacing of the layers along the start-goal segment, m.
    spacing : float
        ``s``, the spacing of the points across a cross-section, m.
    """

    points: np.ndarray
    times: np.ndarray
    clearance: np.ndarray
    node_cost: np.ndarray
    lengths: np.ndarray
    step: float
    spacing: float

    @property
    def has_path(self) -> bool:
        """Whether some path from the start reaches the goal."""
        return bool(np.isfinite(self.lengths[0, 0]).any())

    @property
    def usable_nodes(self) -> int:
        """Number of cross-section points some path from the start can pass through."""
        return int(np.isfinite(self.lengths[1:]).any(axis=2).sum())

    def path_lengths(self, paths: np.ndarray) -> np.ndarray:
        """Length L of each path (eq. 6), m.

        Parameters
        ----------
        paths : ndarray (A, m + 1) of int
            One node per layer for each of A paths.
        """
        layers = np.arange(self.lengths.shape[0])
        return self.lengths[layers, paths[:, :-1], paths[:, 1:]].sum(axis=1)

    def costs(self, paths: np.ndarray) -> np.ndarray:
        """Objective ``F = L + δ Σ 1/d_min`` of each path (eq. 8), (A,)."""
        layers = np.arange(self.node_cost.shape[0])
        return self.path_lengths(paths) + self.node_cost[layers, paths].sum(axis=1)

    def positions(self, path: np.ndarray) -> np.ndarray:
        """The points of one path, (m + 1, 3) m."""
        return self.points[np.arange(len(path)), path]


def build_graph(problem: PathProblem, params: AntColonyParams) -> LayeredGraph:
    """The candidate graph the colony searches (see the module docstring).

    The start is where the robot comes to rest when it moves (braking along its velocity
    at the acceleration limit), the goal the goal region's centre or, when that is inside
    an obstacle, the first clear point of the region (``free_goal_point``).

    Parameters
    ----------
    problem : PathProblem
        Start, goal, obstacles (true shapes, predicted motion), robot radius, safety
        margin, bounds.
    params : AntColonyParams
        Cross-section, parts, points, half-width, δ, check spacing.

    Returns
    -------
    LayeredGraph
        Also when no path exists (:attr:`LayeredGraph.has_path` is then False).
    """
    ends = endpoints(problem, params)
    if isinstance(ends, NoPath):
        raise ValueError(f"no candidate graph: {ends.reason}")
    return graph_between(problem, params, ends)


@dataclass(frozen=True)
class Ends:
    """Where the graph starts and ends, and the braking piece before it."""

    departure: Departure
    goal: np.ndarray

    @property
    def start(self) -> np.ndarray:
        """S: where the robot is at rest after braking, m."""
        return self.departure.position


def endpoints(problem: PathProblem, params: AntColonyParams) -> Ends | NoPath:
    """S and G of ``problem`` (see :func:`build_graph`), or why there are none."""
    goal = goal_or_refusal(problem, ObstacleField(problem))
    if isinstance(goal, NoPath):
        return goal
    return Ends(departure(problem), goal)


def _cross_axes(
    forward: np.ndarray, line_axis: tuple[float, float, float] | None
) -> tuple[np.ndarray, np.ndarray]:
    """The two unit axes ``e₁``, ``e₂`` of the planes perpendicular to ``forward``."""
    if line_axis is None:
        order = np.argsort(np.abs(forward), kind="stable")
        candidates = [np.eye(3)[order[0]]]
    else:
        candidates = [np.asarray(line_axis, dtype=float), *np.eye(3)[np.argsort(np.abs(forward))]]
    for axis in candidates:
        across = axis - axis.dot(forward) * forward
        size = float(np.linalg.norm(across))
        if size > 1e-9:
            first = across / size
            return first, np.cross(forward, first)
    raise ValueError("line_axis is parallel to the start-goal segment")


def _offsets(params: AntColonyParams, n: int, spacing: float, axes: tuple) -> np.ndarray:
    """Offsets of the points of one cross-section from its centre, (P, 3) m."""
    ticks = spacing * np.arange(-n, n + 1)
    first, second = axes
    if params.cross_section == "line":
        return np.outer(ticks, first)
    a, b = np.meshgrid(ticks, ticks, indexing="ij")
    return np.outer(a.ravel(), first) + np.outer(b.ravel(), second)


def nominal_times(
    problem: PathProblem,
    params: AntColonyParams,
    distances: np.ndarray,
    length: float,
    start_time: float,
) -> np.ndarray:
    """Times (s) at which a nominal straight flight of ``length`` (m) from rest at
    ``start_time`` (s) has covered ``distances`` (m): the straight-line planner's
    trapezoid at ``speed_fraction`` of the speed limit, or arriving at the goal's time
    when the limits allow it."""
    accel, limit = problem.max_acceleration, problem.max_speed
    speed = params.speed_fraction * limit
    if math.isfinite(accel):
        speed = min(speed, math.sqrt(accel * length))
    duration = float(rest_to_rest_time(length, speed, accel))
    goal_time = problem.goal.time
    if goal_time is not None and goal_time > start_time:
        available = goal_time - start_time
        needed = cruise_speed(length, available, accel)
        if needed <= limit:
            speed, duration = needed, available
    if length == 0.0 or speed <= 0.0:
        return np.full_like(distances, start_time)
    profile = Profile(length, duration, speed, accel)
    tau = np.linspace(0.0, duration, 4001)
    covered, _ = profile(tau)
    return start_time + np.interp(distances, covered, tau)


class GraphUnfinished(RuntimeError):
    """The candidate graph was not finished by its deadline."""


def graph_between(
    problem: PathProblem, params: AntColonyParams, ends: Ends, deadline: float = math.inf
) -> LayeredGraph:
    """The candidate graph from ``ends.start`` to ``ends.goal`` (see :func:`build_graph`).

    Raises
    ------
    GraphUnfinished
        If ``time.monotonic()`` passes ``deadline`` before every obstacle is tested.
    """
    m = params.parts
    n = params.points if params.points is not None else _DEFAULT_POINTS[params.cross_section]
    start, goal = ends.start, ends.goal
    span = float(np.linalg.norm(goal - start))
    if span < SHORTEST:
        raise ValueError("the start is at the goal: there is nothing to cross")
    forward = (goal - start) / span
    half_width = params.half_width if params.half_width is not None else 0.5 * span
    spacing = half_width / n
    offsets = _offsets(params, n, spacing, _cross_axes(forward, params.line_axis))
    count = len(offsets)
    step = span / m
    along = step * np.arange(m + 1)
    points = start + along[:, None, None] * forward + offsets[None]
    points[0], points[m] = start, goal
    times = nominal_times(problem, params, along, span, ends.departure.time)
    usable = np.ones((m + 1, count), dtype=bool)
    usable[0, 1:] = usable[m, 1:] = False
    if problem.bounds is not None:
        usable[1:m] &= problem.bounds.contains(points[1:m])
    reach = problem.robot_radius + problem.safety_margin
    gaps = np.full((m + 1, count), np.inf)
    blocked = np.zeros((m, count, count), dtype=bool)
    for done, track in enumerate(problem.obstacles):
        if time.monotonic() > deadline:
            raise GraphUnfinished(f"{done} of {len(problem.obstacles)} obstacles tested")
        centres = track.predict(times)[0]
        gaps = np.minimum(gaps, _point_gaps(track, points - centres[:, None, :]))
        _block_segments(track, points, centres, along, forward, start, reach, params, blocked)
    clearance = gaps - reach
    usable[1:m] &= clearance[1:m] > 0
    lengths = np.linalg.norm(points[1:, None, :, :] - points[:-1, :, None, :], axis=-1)
    blocked |= ~usable[:-1, :, None] | ~usable[1:, None, :]
    lengths[blocked] = np.inf
    _prune(lengths)
    node_cost = np.where(usable, 0.0, np.inf)
    if params.delta > 0:
        safe = np.where(usable[1:m], clearance[1:m], 1.0)
        node_cost[1:m] = np.where(usable[1:m], params.delta / safe, np.inf)
    return LayeredGraph(points, times, clearance, node_cost, lengths, step, spacing)


def _point_gaps(track: ObjectTrack, offsets: np.ndarray) -> np.ndarray:
    """Surface distance of an obstacle from points at ``offsets`` from its centre
    (world frame, (..., 3) m), m."""
    if track.shape.kind is ShapeKind.SPHERE:
        return np.linalg.norm(offsets, axis=-1) - track.shape.radius
    body = offsets.reshape(-1, 3) @ to_body(track).T
    return body_surface_distance(track.shape, body).reshape(offsets.shape[:-1])


def segment_gaps(
    track: ObjectTrack, first: np.ndarray, last: np.ndarray, reach: float, spacing: float
) -> np.ndarray:
    """Least surface distance of an obstacle from segments given relative to its centre.

    Parameters
    ----------
    track : ObjectTrack
        The obstacle (its true shape and orientation).
    first, last : ndarray (..., 3)
        Ends of each segment as offsets from the obstacle's centre, world frame, m (for a
        moving obstacle, each end relative to where the obstacle is then).
    reach : float
        Distances at or beyond this are not refined, m.
    spacing : float
        Largest spacing of the exact tests along a segment near a box or cylinder, m.

    Returns
    -------
    ndarray (...)
        m. Exact for a sphere. For a box or cylinder: the bounding sphere's distance where
        that is at least ``reach``, otherwise the least exact distance at points at most
        ``spacing`` apart less half their spacing (never more than the true distance).
    """
    first, last = np.broadcast_arrays(first, last)
    shape = first.shape[:-1]
    first, last = first.reshape(-1, 3), last.reshape(-1, 3)
    along = last - first
    squared = np.einsum("ij,ij->i", along, along)
    fraction = -np.einsum("ij,ij->i", first, along) / np.where(squared > 0, squared, 1.0)
    nearest = first + np.clip(fraction, 0.0, 1.0)[:, None] * along
    gaps = np.linalg.norm(nearest, axis=1) - track.radius
    if track.shape.kind is ShapeKind.SPHERE:
        return gaps.reshape(shape)
    near = np.flatnonzero(gaps < reach)
    if len(near):
        lengths = np.sqrt(squared[near])
        count = max(2, int(np.ceil(lengths.max() / spacing)) + 1)
        fractions = np.linspace(0.0, 1.0, count)
        samples = first[near, None, :] + fractions[None, :, None] * along[near, None, :]
        body = samples.reshape(-1, 3) @ to_body(track).T
        exact = body_surface_distance(track.shape, body).reshape(len(near), count)
        gaps[near] = exact.min(axis=1) - 0.5 * lengths / (count - 1)
    return gaps.reshape(shape)


def _block_segments(
    track: ObjectTrack,
    points: np.ndarray,
    centres: np.ndarray,
    along: np.ndarray,
    forward: np.ndarray,
    start: np.ndarray,
    reach: float,
    params: AntColonyParams,
    blocked: np.ndarray,
) -> None:
    """Mark in ``blocked`` (m, P, P) the segments the obstacle's moving shape touches,
    testing only the layers it can reach along the start-goal segment."""
    relative = along - (centres - start) @ forward  # along-track offset of each layer
    limit = track.radius + reach
    outside = ((relative[:-1] > limit) & (relative[1:] > limit)) | (
        (relative[:-1] < -limit) & (relative[1:] < -limit)
    )
    layers = np.flatnonzero(~outside)
    if not len(layers):
        return
    first = (points[layers] - centres[layers, None, :])[:, :, None, :]
    last = (points[layers + 1] - centres[layers + 1, None, :])[:, None, :, :]
    gaps = segment_gaps(track, first, last, reach, params.check_spacing)
    blocked[layers] |= gaps <= reach


def _prune(lengths: np.ndarray) -> None:
    """Make every segment into a node the goal cannot be reached from infinite, layer by
    layer from the goal back."""
    alive = np.zeros(lengths.shape[2], dtype=bool)
    alive[0] = True
    for i in range(lengths.shape[0] - 1, -1, -1):
        lengths[i][:, ~alive] = np.inf
        alive = np.isfinite(lengths[i]).any(axis=1)


def simplify(
    problem: PathProblem,
    graph: LayeredGraph,
    path: np.ndarray,
    params: AntColonyParams,
) -> tuple[np.ndarray, np.ndarray]:
    """The path's vertices reduced (see the module docstring): points (k, 3) m and their
    nominal times (k,) s."""
    points, times = graph.positions(path), graph.times
    tolerance = (
        params.simplify_tolerance if params.simplify_tolerance is not None else graph.spacing
    )
    reach = problem.robot_radius + problem.safety_margin
    kept = [0]
    while kept[-1] < len(points) - 1:
        i = kept[-1]
        ends = np.arange(i + 1, len(points))
        clear = _chords_clear(problem, points, times, i, ends, reach, params.check_spacing)
        near = _chords_near(points, i, ends, tolerance)
        good = np.flatnonzero(clear & near)
        kept.append(int(ends[good[-1]]) if len(good) else i + 1)
    return points[kept], times[kept]


def _chords_clear(
    problem: PathProblem,
    points: np.ndarray,
    times: np.ndarray,
    i: int,
    ends: np.ndarray,
    reach: float,
    spacing: float,
) -> np.ndarray:
    """Whether the chord from vertex ``i`` to each of ``ends`` keeps ``reach`` from every
    obstacle (moving from its place at ``times[i]`` to that at each end's time)."""
    clear = np.ones(len(ends), dtype=bool)  # the first chord is a segment of the graph
    for track in problem.obstacles:
        here = track.predict(times[i])[0]
        there = track.predict(times[ends])[0]
        gaps = segment_gaps(track, points[i] - here, points[ends] - there, reach, spacing)
        clear[1:] &= gaps[1:] > reach
    return clear


def _chords_near(points: np.ndarray, i: int, ends: np.ndarray, tolerance: float) -> np.ndarray:
    """Whether every vertex between ``i`` and each of ``ends`` lies within ``tolerance``
    of the chord from ``i`` to that end."""
    near = np.ones(len(ends), dtype=bool)
    inner = points[i + 1 : ends[-1]]
    if not len(inner):
        return near
    chord = points[ends] - points[i]  # (J, 3)
    offsets = inner - points[i]  # (K, 3)
    squared = np.maximum(np.einsum("ij,ij->i", chord, chord), 1e-300)
    fraction = np.clip(offsets @ chord.T / squared, 0.0, 1.0)  # (K, J)
    gaps = np.linalg.norm(offsets[:, None, :] - fraction[..., None] * chord[None], axis=-1)
    between = np.arange(i + 1, ends[-1])[:, None] < ends[None, :]
    far = (gaps > tolerance) & between
    return ~far.any(axis=0)
