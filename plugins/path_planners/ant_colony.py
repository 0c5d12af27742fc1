"""``ant-colony`` path planner: ants choose one point on each of m cross-sections (source 003).

The planner of the ant colony collision-avoidance paper (LI Hua-Zhong and Liang
Yong-Sheng, source 003), for a free flyer among obstacles.

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
    same number of nodes).
Clearance of a node (eqs 7, 9)
    ``d_min``: the distance from the robot's sphere, grown by ``clearance``, to the
    surface of the nearest obstacle's TRUE shape (sphere, turned box or cylinder), that
    is the surface distance of the point minus ``robot_radius + clearance``. A node with
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
    the true least distance, so the test is conservative). Nodes from which the goal
    cannot be reached are then pruned, so no ant is ever stuck.
Objective (eq. 8)
    ``F = L + δ Σᵢ 1/d_min,i`` over the m − 1 chosen points: ``L`` the path's length, δ
    the obstacle-avoidance coefficient (``delta``, m²; larger keeps further away). The
    balance depends on the problem's scale and on m: on a 6 m transfer with clearances
    near 1 m, δ = 2 makes the safety term most of F, and the best path keeps to the
    edge of the cross-sections.
Ants (:func:`solve_colony`, eqs 10–13)
    All ``ants`` start at S each cycle and advance layer by layer together. From node p
    an ant moves to node q of the next layer with probability
    ``τ_pq^α η_pq^β / Σ_q' τ_pq'^α η_pq'^β`` over the allowed q (eq. 11), η being 0 for
    a blocked segment: one numpy pass per layer for all ants spins every roulette wheel
    at once (cumulative sums of the weights and one uniform draw per ant from the
    plugin's generator). After a cycle every segment's pheromone becomes
    ``ρ τ + Σ_k Q/F_k`` over the ants k that used it (eqs 12–13; ``persistence`` is the
    paper's ρ, ``1 − ρ`` evaporates), starting from ``initial_pheromone`` (C). The colony
    stops when every ant took the same path (converged), when the best path found has
    not improved for ``stall_cycles`` cycles (converged), after ``max_cycles`` cycles, or
    at the time budget. The answer is the best path found in any cycle.
Departures from the paper (each a parameter; the defaults use them)
    The paper's constants are the defaults (α = 1, β = 5, ρ = 0.526, Q = 320, 30 ants,
    m = 40, 242 cycles, δ = 2), but its colony, scored against the exact optimum of the
    same graph (``dcsim.bench.layered_optimum``), stops far above it: with β = 5 and
    ``η = 1/d_pq`` the ants hardly ever step sideways before an obstacle forces them to,
    so the δ term, which the visibility does not see, is left to the pheromone, and the
    pheromone of the first cycles' paths (Q/F against C) fixes the colony on one of
    them within a few dozen cycles. Four changes bring it to the optimum:
    ``visibility: objective`` uses ``η = 1/(d_pq + δ/d_min,q)``, the reciprocal of what
    the step adds to F (``length`` is the paper's ``1/d_pq``); ``local_search`` moves
    single points of every ant's path to the best node of their layer given their
    neighbours while F falls (:func:`descend`), before the pheromone is laid;
    ``deposit_by: best`` lets only the cycle's best ant lay pheromone (``all``: the
    paper); ``pheromone_floor`` keeps every segment's pheromone at least that share of
    the most one can hold (``k Q / (F_best (1 − ρ))``, k the ants that lay), so the
    colony keeps exploring (0: the paper). With ``visibility: length``,
    ``local_search: false``, ``deposit_by: all`` and ``pheromone_floor: 0`` the colony
    is the paper's.
Moving obstacles (an extension; the paper's are at rest)
    Layer i is taken to be crossed when a nominal flight along the straight segment SG
    reaches it: the trapezoid of the ``straight-line`` planner at ``speed_fraction`` of
    the speed limit, or arriving at the goal's time when it sets one. ``d_min`` of a node
    uses the obstacles' predicted places at its layer's time. A segment from layer i to
    i + 1 is tested in the obstacle's frame: the robot is taken to move uniformly along
    it from ``t_i`` to ``t_(i+1)`` while the obstacle moves from its place at ``t_i`` to
    its place at ``t_(i+1)``, so the relative motion is again a segment (exact for
    obstacles in straight-line motion, a chord of the arc otherwise). The flown timing
    differs from the nominal one; the timed trajectory is therefore checked again
    (below) and the answer is "no path" if that check fails.
Trajectory
    The best path is reduced to fewer vertices: from each kept vertex the next kept one
    is the farthest whose chord is clear (the segment test above, at the nominal times)
    and passes within ``simplify_tolerance`` of every vertex it skips. The polyline is
    flown at one cruise speed with parabolic corner blends: at each vertex the velocity
    turns from ``v u_j`` to ``v u_(j+1)`` at the acceleration limit over
    ``v |u_(j+1) − u_j| / a`` seconds centred on the vertex (the path cuts the corner by
    ``v² |Δu|² / 8a``; speed never exceeds v), and it accelerates from rest at S and
    brakes to rest at G on the first and last pieces. The duration is ``L/v + v/a``; v is
    ``speed_fraction`` of the speed limit, lowered until every piece holds its ramps and
    half-blends, or chosen to arrive exactly at the goal's time when it sets one (no path
    if even the fastest admissible v is late). A start that moves first brakes to rest
    along its velocity. The timed trajectory is checked with dcsim's swept clearance
    (``path_clearance``) against the obstacles' predicted motion and must keep half of
    ``clearance``; if the blends cut too close it is flown again with half the cruise
    speed (when there is no goal time), then rest to rest at every vertex (the polyline
    exactly; waiting at the goal for its time), and "no path" if none passes. The goal
    is arrived at at rest (a goal velocity beyond its tolerance is "no path"); the
    attitude is left free (the transfer mission holds the goal's or the start's). The
    frame's free motion is not used: straight pieces are flown with thrust.

Statistics: ``cycles`` (cycles run), ``ants``, ``best_cost`` (F of the answer),
``converged`` (1 if the colony converged before ``max_cycles`` and the budget),
``nodes`` (usable candidate points), ``waypoints`` (vertices flown). The best cost of
every cycle is in :class:`ColonyResult`. A benchmark reaches both halves through the
registered class, without importing this module: ``planner.candidate_graph(problem)``
is the graph :meth:`~AntColonyPlanner.plan` searches (its ``lengths`` and
``node_cost`` are what ``dcsim.bench.layered_optimum`` minimises exactly) and
``planner.colony(graph)`` runs the colony on it with the planner's generator.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Literal

import numpy as np
from dcsim_plugins.path_planners.obstacle_field import (
    ObstacleField,
    endpoint_refusal,
    free_goal_point,
)
from dcsim_plugins.path_planners.straight_line import Profile

from dcsim.api import (
    NoPath,
    ObjectTrack,
    PathPlanner,
    PathProblem,
    PluginParams,
    ShapeKind,
    Trajectory,
    body_surface_distance,
    cruise_speed,
    hookimpl,
    path_clearance,
    quantity,
    quaternion_conjugate,
    rest_to_rest_time,
    rotate,
)

PAPER_PARTS = 40
"""The paper's number of equal parts m."""
_SHORTEST = 1e-6  # m: shorter polyline pieces are dropped
_BLEND_SAMPLES = 8  # trajectory samples per corner blend or ramp
_RESERVE = 0.1  # share of the time budget kept for timing and checking the path
_DEFAULT_POINTS = {"line": 10, "grid": 4}
_BELOW_ONE = 1.0 - 2.0**-30  # largest roulette draw: p + draw < p + 1 for any node p


class AntColonyParams(PluginParams):
    """Parameters of :class:`AntColonyPlanner`; the defaults are the paper's where it
    gives them (α, β, ρ, Q, ants, m, cycles, δ)."""

    cross_section: Literal["line", "grid"] = quantity(
        "line",
        description="Candidate points on a line across each cross-section (the paper), "
        "or on a square grid in its plane.",
    )
    parts: int = quantity(
        PAPER_PARTS, ge=2, le=10_000, description="Equal parts m of the start-goal segment."
    )
    points: int | None = quantity(
        None,
        ge=1,
        le=1000,
        description="n: 2n+1 points per line, (2n+1)^2 per grid (unset: 10 for a line, 4 "
        "for a grid).",
    )
    half_width: float | None = quantity(
        None,
        unit="m",
        gt=0,
        description="Distance from a cross-section's centre to its outermost point along "
        "an axis (unset: half the start-goal distance).",
    )
    line_axis: tuple[float, float, float] | None = quantity(
        None,
        description="Direction of the line (first grid axis), projected onto the "
        "cross-section (unset: the world axis least aligned with the start-goal segment).",
    )
    ants: int = quantity(30, ge=1, le=100_000, description="Ants per cycle (the paper's M_h).")
    max_cycles: int = quantity(242, ge=1, le=1_000_000, description="Largest number of cycles.")
    stall_cycles: int = quantity(
        30,
        ge=1,
        le=1_000_000,
        description="The colony has converged when its best path has not improved for this "
        "many cycles.",
    )
    visibility: Literal["objective", "length"] = quantity(
        "objective",
        description="Visibility of a segment: 1/(its length + the next point's δ/d_min), "
        "or the paper's 1/length.",
    )
    local_search: bool = quantity(
        True,
        description="Improve every ant's path by moving single points while that lowers F, "
        "before the pheromone is laid (not in the paper).",
    )
    deposit_by: Literal["all", "best"] = quantity(
        "best",
        description="Ants that lay pheromone: every ant (the paper) or only the cycle's best.",
    )
    pheromone_floor: float = quantity(
        0.1,
        ge=0,
        le=1,
        description="Least pheromone as a share of the most a segment can hold, "
        "k Q / (F_best (1 - ρ)) with k the ants that lay (0: none, the paper).",
    )
    alpha: float = quantity(1.0, ge=0, le=20, description="Weight α of the pheromone.")
    beta: float = quantity(5.0, ge=0, le=20, description="Weight β of the visibility 1/d.")
    persistence: float = quantity(
        0.526,
        gt=0,
        lt=1,
        description="Share ρ of the pheromone kept from one cycle to the next.",
    )
    deposit: float = quantity(
        320.0, gt=0, description="Pheromone Q an ant lays, divided by its path's objective F."
    )
    initial_pheromone: float = quantity(
        1.0, gt=0, description="Pheromone C on every segment at the start."
    )
    delta: float = quantity(
        2.0,
        unit="m^2",
        ge=0,
        description="Obstacle-avoidance coefficient δ of the objective L + δ Σ 1/d_min.",
    )
    clearance: float = quantity(
        0.05, unit="m", ge=0, description="Margin kept beyond the robot radius."
    )
    check_spacing: float = quantity(
        0.05,
        unit="m",
        gt=0,
        description="Largest spacing of exact distance tests along a segment near a box or "
        "cylinder.",
    )
    simplify_tolerance: float | None = quantity(
        None,
        unit="m",
        ge=0,
        description="Largest distance of a dropped vertex from the chord that replaces it "
        "(unset: one cross-section step).",
    )
    speed_fraction: float = quantity(
        0.8, gt=0, le=1, description="Fraction of the speed limit cruised at."
    )


# ---------------------------------------------------------------------------- graph


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
        Start, goal, obstacles (true shapes, predicted motion), robot radius, bounds.
    params : AntColonyParams
        Cross-section, parts, points, half-width, δ, clearance, check spacing.

    Returns
    -------
    LayeredGraph
        Also when no path exists (:attr:`LayeredGraph.has_path` is then False).
    """
    ends = _endpoints(problem, params)
    if isinstance(ends, NoPath):
        raise ValueError(f"no candidate graph: {ends.reason}")
    return _graph(problem, params, ends)


@dataclass(frozen=True)
class _Ends:
    """Where the graph starts and ends, and the braking piece before it."""

    start: np.ndarray
    start_time: float
    goal: np.ndarray
    braking: tuple[np.ndarray, np.ndarray, np.ndarray]


def _endpoints(problem: PathProblem, params: AntColonyParams) -> _Ends | NoPath:
    field = ObstacleField(problem, params.clearance)
    refusal = endpoint_refusal(problem, field)
    if refusal is not None:
        return refusal
    goal = free_goal_point(problem, field)
    if goal is None:
        return NoPath("no point of the goal region is clear of the obstacles")
    braking = _braking(problem.start.position, problem.start.velocity, problem.max_acceleration)
    return _Ends(braking[1][-1], problem.start.time + float(braking[0][-1]), goal, braking)


def _braking(
    position: np.ndarray, velocity: np.ndarray, acceleration: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Times since the start (s), positions (m) and velocities (m/s) of braking to rest
    along ``velocity`` at ``acceleration``; one sample when at rest."""
    position, velocity = np.asarray(position, float), np.asarray(velocity, float)
    speed = float(np.linalg.norm(velocity))
    if speed == 0.0 or math.isinf(acceleration):
        return np.zeros(1), position[None], np.zeros((1, 3))
    return _constant_acceleration(
        position, velocity, -velocity / speed * acceleration, speed / acceleration
    )


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


def _graph(problem: PathProblem, params: AntColonyParams, ends: _Ends) -> LayeredGraph:
    m = params.parts
    n = params.points if params.points is not None else _DEFAULT_POINTS[params.cross_section]
    start, goal = ends.start, ends.goal
    span = float(np.linalg.norm(goal - start))
    if span < _SHORTEST:
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
    times = nominal_times(problem, params, along, span, ends.start_time)
    usable = np.ones((m + 1, count), dtype=bool)
    usable[0, 1:] = usable[m, 1:] = False
    if problem.bounds is not None:
        usable[1:m] &= problem.bounds.contains(points[1:m])
    reach = problem.robot_radius + params.clearance
    gaps = np.full((m + 1, count), np.inf)
    blocked = np.zeros((m, count, count), dtype=bool)
    for track in problem.obstacles:
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


def _to_body(track: ObjectTrack) -> np.ndarray:
    """World-to-body rotation matrix of an obstacle's shape."""
    return rotate(quaternion_conjugate(track.shape.orientation), np.eye(3)).T


def _point_gaps(track: ObjectTrack, offsets: np.ndarray) -> np.ndarray:
    """Surface distance of an obstacle from points at ``offsets`` from its centre
    (world frame, (..., 3) m), m."""
    if track.shape.kind is ShapeKind.SPHERE:
        return np.linalg.norm(offsets, axis=-1) - track.shape.radius
    body = offsets.reshape(-1, 3) @ _to_body(track).T
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
        body = samples.reshape(-1, 3) @ _to_body(track).T
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


# ---------------------------------------------------------------------------- colony


def visibility(graph: LayeredGraph, beta: float, kind: str = "objective") -> np.ndarray:
    """``η^β`` of every segment (0 for a blocked one), (m, P, P).

    Parameters
    ----------
    graph : LayeredGraph
        Its segment lengths and node terms.
    beta : float
        β.
    kind : {"length", "objective"}
        ``length``: the paper's ``η = 1/d_pq``. ``objective``: ``η = 1/(d_pq + δ/d_min,q)``,
        the reciprocal of what the step adds to F.
    """
    steps = graph.lengths
    if kind == "objective":
        steps = steps + graph.node_cost[1:, None, :]
    finite = np.isfinite(steps)
    safe = np.where(finite & (steps > 0), steps, 1.0)
    return np.where(finite, safe**-beta, 0.0)


def transition_weights(pheromone: np.ndarray, eta_beta: np.ndarray, alpha: float) -> np.ndarray:
    """``τ^α η^β`` of every segment, the numerator of eq. 11."""
    if alpha == 1.0:
        return pheromone * eta_beta
    return pheromone**alpha * eta_beta


def transition_probabilities(weights: np.ndarray) -> np.ndarray:
    """Eq. 11: each row of ``weights`` (m, P, P) divided by its sum (rows of unusable
    nodes, which sum to 0, stay 0)."""
    totals = weights.sum(axis=-1, keepdims=True)
    return np.divide(weights, totals, out=np.zeros_like(weights), where=totals > 0)


def walk(weights: np.ndarray, draws: np.ndarray) -> np.ndarray:
    """Paths of a colony through the layers by roulette wheel (Steps 2–3).

    Parameters
    ----------
    weights : ndarray (m, P, P)
        ``τ^α η^β`` of every segment (0 for a segment never to be taken).
    draws : ndarray (m, A)
        Uniform numbers in [0, 1), one per ant and layer.

    Returns
    -------
    ndarray (A, m + 1) of int
        Each ant's node in each layer, starting at node 0 of layer 0.
    """
    m, ants = draws.shape
    count = weights.shape[2]
    wheels = np.cumsum(weights, axis=2)
    totals = wheels[:, :, -1:]
    # Each row's wheel scaled to [0, 1] and shifted by its node index, so that one
    # sorted search per layer spins every ant's wheel: row p spans [p, p + 1].
    wheels = np.divide(wheels, totals, out=np.ones_like(wheels), where=totals > 0)
    wheels += np.arange(count)[:, None]
    wheels = wheels.reshape(m, count * count)
    # A draw just below 1 must stay below p + 1 after the shift (zero-weight segments
    # then are never chosen: the first wheel value above a draw ends a positive weight).
    shifted = np.minimum(draws, _BELOW_ONE)
    paths = np.zeros((ants, m + 1), dtype=np.intp)
    here = paths[:, 0]
    for i in range(m):
        here = np.searchsorted(wheels[i], here + shifted[i], side="right") - here * count
        paths[:, i + 1] = here
    return paths


def lay_pheromone(
    pheromone: np.ndarray,
    paths: np.ndarray,
    costs: np.ndarray,
    persistence: float,
    deposit: float,
) -> np.ndarray:
    """Eqs 12–13: ``ρ τ + Σ_k Q/F_k`` over the ants k that used each segment.

    Parameters
    ----------
    pheromone : ndarray (m, P, P)
        τ before the update.
    paths : ndarray (A, m + 1) of int
        The ants' paths this cycle.
    costs : ndarray (A,)
        Their objectives F.
    persistence, deposit : float
        ρ and Q.

    Returns
    -------
    ndarray (m, P, P)
        τ after the update (a new array).
    """
    m, count, _ = pheromone.shape
    flat = (np.arange(m) * count + paths[:, :-1]) * count + paths[:, 1:]
    share = np.repeat(deposit / costs, m)
    laid = np.bincount(flat.ravel(), weights=share, minlength=pheromone.size)
    return persistence * pheromone + laid.reshape(pheromone.shape)


def descend(graph: LayeredGraph, paths: np.ndarray, sweeps: int = 10) -> np.ndarray:
    """Paths improved by moving one point at a time to the best node of its layer given
    its neighbours, while that lowers F (local search; not in the paper).

    Odd and even cross-sections are moved in turn, so every move of a half-sweep is one
    numpy pass over all ants and layers.

    Parameters
    ----------
    graph : LayeredGraph
        Segment lengths and node terms.
    paths : ndarray (A, m + 1) of int
        Paths to improve.
    sweeps : int
        Largest number of sweeps over the cross-sections.

    Returns
    -------
    ndarray (A, m + 1) of int
        Improved paths (a new array); F of each is at most that of the path it came from.
    """
    m = graph.lengths.shape[0]
    paths = paths.copy()
    for _ in range(sweeps):
        moved = False
        for first in (1, 2):
            layers = np.arange(first, m, 2)
            if not len(layers):
                continue
            costs = (
                graph.lengths[layers[None, :] - 1, paths[:, layers - 1], :]
                + graph.node_cost[layers][None]
                + graph.lengths[layers[None, :], :, paths[:, layers + 1]]
            )
            best = np.argmin(costs, axis=2)
            now = np.take_along_axis(costs, paths[:, layers][..., None], axis=2)[..., 0]
            lowest = np.take_along_axis(costs, best[..., None], axis=2)[..., 0]
            better = lowest < now - 1e-12 * np.abs(now)
            if better.any():
                moved = True
                paths[:, layers] = np.where(better, best, paths[:, layers])
        if not moved:
            break
    return paths


@dataclass(frozen=True)
class ColonyResult:
    """What a colony found, and how it got there.

    Attributes
    ----------
    path : ndarray (m + 1,) of int
        The best path found (node per layer).
    cost : float
        Its objective F.
    history : ndarray (cycles,)
        The best F found up to each cycle.
    cycle_best : ndarray (cycles,)
        The best F of each cycle's ants.
    cycles : int
        Cycles run.
    converged : bool
        Whether the colony stopped because every ant took one path or the best stalled.
    stop : str
        ``"one path"``, ``"stalled"``, ``"max cycles"`` or ``"budget"``.
    pheromone : ndarray (m, P, P)
        τ after the last cycle.
    """

    path: np.ndarray
    cost: float
    history: np.ndarray
    cycle_best: np.ndarray
    cycles: int
    converged: bool
    stop: str
    pheromone: np.ndarray


def solve_colony(
    graph: LayeredGraph,
    params: AntColonyParams,
    rng: np.random.Generator,
    deadline: float = math.inf,
) -> ColonyResult:
    """Run the colony on a graph until it converges, runs out of cycles or of time.

    Parameters
    ----------
    graph : LayeredGraph
        With a path (:attr:`LayeredGraph.has_path`).
    params : AntColonyParams
        α, β, ρ, Q, C, ants, max and stall cycles.
    rng : numpy.random.Generator
        Source of every roulette draw.
    deadline : float
        ``time.monotonic()`` after which no new cycle starts.

    Returns
    -------
    ColonyResult
    """
    if not graph.has_path:
        raise ValueError("the graph has no path from the start to the goal")
    m = graph.lengths.shape[0]
    eta_beta = visibility(graph, params.beta, params.visibility)
    pheromone = np.full(graph.lengths.shape, params.initial_pheromone)
    best_cost, best_path, improved = math.inf, np.zeros(m + 1, dtype=np.intp), 0
    history, cycle_best = [], []
    stop = "max cycles"
    for cycle in range(1, params.max_cycles + 1):
        weights = transition_weights(pheromone, eta_beta, params.alpha)
        paths = walk(weights, rng.random((m, params.ants)))
        if params.local_search:
            paths = descend(graph, paths)
        costs = graph.costs(paths)
        k = int(np.argmin(costs))
        cycle_best.append(float(costs[k]))
        if costs[k] < best_cost:
            best_cost, best_path, improved = float(costs[k]), paths[k].copy(), cycle
        history.append(best_cost)
        layers = slice(k, k + 1) if params.deposit_by == "best" else slice(None)
        pheromone = lay_pheromone(
            pheromone, paths[layers], costs[layers], params.persistence, params.deposit
        )
        if params.pheromone_floor > 0:
            layers_by = 1 if params.deposit_by == "best" else params.ants
            most = layers_by * params.deposit / (best_cost * (1.0 - params.persistence))
            np.maximum(pheromone, params.pheromone_floor * most, out=pheromone)
        if (paths == paths[0]).all():
            stop = "one path"
            break
        if cycle - improved >= params.stall_cycles:
            stop = "stalled"
            break
        if time.monotonic() > deadline:
            stop = "budget" if cycle < params.max_cycles else stop
            break
    return ColonyResult(
        path=best_path,
        cost=best_cost,
        history=np.array(history),
        cycle_best=np.array(cycle_best),
        cycles=len(history),
        converged=stop in ("one path", "stalled"),
        stop=stop,
        pheromone=pheromone,
    )


# ---------------------------------------------------------------------------- path


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
    reach = problem.robot_radius + params.clearance
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


Samples = tuple[np.ndarray, np.ndarray, np.ndarray]
"""Times (s), positions (m) and velocities (m/s) of a piece of trajectory."""


def _constant_acceleration(
    position: np.ndarray, velocity: np.ndarray, acceleration: np.ndarray, duration: float
) -> Samples:
    """Samples of a piece flown at a constant acceleration, from its start."""
    tau = np.linspace(0.0, duration, _BLEND_SAMPLES + 1)
    positions = position + np.outer(tau, velocity) + 0.5 * np.outer(tau**2, acceleration)
    return tau, positions, velocity + np.outer(tau, acceleration)


def blend_speed_limit(vertices: np.ndarray, acceleration: float) -> float:
    """Largest cruise speed at which every piece of the polyline holds its ramps and
    half-blends, m/s (``inf`` for impulsive acceleration)."""
    if math.isinf(acceleration):
        return math.inf
    pieces = np.diff(vertices, axis=0)
    lengths = np.linalg.norm(pieces, axis=1)
    directions = pieces / lengths[:, None]
    turns = np.linalg.norm(np.diff(directions, axis=0), axis=1)
    ends = np.concatenate([[1.0], turns, [1.0]]) / (2.0 * acceleration)  # × v² = length used
    demand = ends[:-1] + ends[1:]
    return float(np.sqrt(np.min(lengths / demand)))


def blended(vertices: np.ndarray, speed: float, acceleration: float) -> Samples:
    """A polyline flown at cruise ``speed`` (m/s) with parabolic corner blends at
    ``acceleration`` (m/s²), from rest to rest; times from the start. With impulsive
    acceleration (``inf``) the polyline is flown rest to rest instead."""
    if math.isinf(acceleration):
        return rest_to_rest(vertices, speed, acceleration)
    pieces = np.diff(vertices, axis=0)
    directions = pieces / np.linalg.norm(pieces, axis=1)[:, None]
    ramp = speed / acceleration
    parts = [_constant_acceleration(vertices[0], np.zeros(3), acceleration * directions[0], ramp)]
    last = len(directions) - 1
    for j, direction in enumerate(directions):
        position, velocity = parts[-1][1][-1], parts[-1][2][-1]
        if j < last:
            turn = speed * (directions[j + 1] - direction)
            duration = float(np.linalg.norm(turn)) / acceleration
            change = turn / duration if duration > 0 else np.zeros(3)
        else:
            duration, change = ramp, -acceleration * direction
        entry = vertices[j + 1] - direction * (0.5 * speed * duration)  # half-blend or ramp
        cruise = float(np.dot(entry - position, direction)) / speed
        if cruise > 0:
            parts.append(
                (
                    np.array([0.0, cruise]),
                    np.vstack([position, entry]),
                    np.vstack([velocity, velocity]),
                )
            )
            position = entry
        if duration > 0:
            parts.append(_constant_acceleration(position, velocity, change, duration))
        else:
            parts.append((np.zeros(1), position[None], velocity[None]))
    times, positions, velocities = _chain(parts, 0.0)
    positions[-1], velocities[-1] = vertices[-1], 0.0
    return times, positions, velocities


def rest_to_rest(vertices: np.ndarray, speed: float, acceleration: float) -> Samples:
    """A polyline flown rest to rest on every piece with the trapezoid of cruise
    ``speed`` (m/s) and ``acceleration`` (m/s²); times from the start."""
    parts = []
    for a, b in zip(vertices[:-1], vertices[1:], strict=True):
        length = float(np.linalg.norm(b - a))
        duration = float(rest_to_rest_time(length, speed, acceleration))
        cruise = speed if math.isinf(acceleration) else min(speed, math.sqrt(acceleration * length))
        profile = Profile(length, duration, cruise, acceleration)
        tau = profile.sample_times()
        distance, velocity = profile(tau)
        direction = (b - a) / length
        parts.append((tau, a + np.outer(distance, direction), np.outer(velocity, direction)))
    return _chain(parts, 0.0)


def _chain(parts: list[Samples], t0: float) -> Samples:
    """Consecutive pieces joined end to start, from time ``t0``; samples closer than a
    microsecond merged."""
    times, positions, velocities = [np.array([t0])], [parts[0][1][:1]], [parts[0][2][:1]]
    clock = t0
    for tau, p, v in parts:
        times.append(clock + tau[1:])
        positions.append(p[1:])
        velocities.append(v[1:])
        clock += float(tau[-1])
    t, p, v = np.concatenate(times), np.vstack(positions), np.vstack(velocities)
    keep = np.append(True, np.diff(t) > 1e-6)
    return t[keep], p[keep], v[keep]


class AntColonyPlanner(PathPlanner):
    """Ant colony over points on cross-sections of the start-goal segment (source 003)."""

    name = "ant-colony"
    summary = (
        "Ant colony choosing one point per cross-section of the start-goal segment, "
        "objective length + δ Σ 1/clearance; corner-blended timing (ant colony paper)"
    )
    Params = AntColonyParams
    params: AntColonyParams
    handles_moving_obstacles = True

    def candidate_graph(self, problem: PathProblem) -> LayeredGraph:
        """The graph :meth:`plan` searches for ``problem`` (:func:`build_graph` with this
        planner's parameters), for scoring the colony against the exact optimum of the
        same graph (``dcsim.bench.layered_optimum``) without importing this module.

        Raises
        ------
        ValueError
            When the problem has no graph (the start or the goal inside an obstacle or
            outside the bounds, or the start at the goal).
        """
        return build_graph(problem, self.params)

    def colony(self, graph: LayeredGraph, deadline: float = math.inf) -> ColonyResult:
        """Run this planner's colony on ``graph`` with its generator (:func:`solve_colony`):
        the best path, its objective and the best objective of every cycle."""
        return solve_colony(graph, self.params, self.rng, deadline)

    def plan(self, problem: PathProblem) -> Trajectory | NoPath:
        """Build the graph, run the colony, simplify and time the best path."""
        started = time.monotonic()
        goal = problem.goal
        if np.linalg.norm(goal.velocity) > goal.velocity_tolerance:
            return NoPath(
                f"the goal asks to arrive at {goal.velocity} m/s; this planner arrives at rest"
            )
        ends = _endpoints(problem, self.params)
        if isinstance(ends, NoPath):
            return ends
        if np.linalg.norm(ends.goal - ends.start) < _SHORTEST:
            return self._timed(problem, ends, ends.start[None], {"cycles": 0.0})
        graph = _graph(problem, self.params, ends)
        if not graph.has_path:
            return NoPath(
                f"every path across the {self.params.parts - 1} cross-sections meets an "
                "obstacle or leaves the bounds (widen half_width or add points)"
            )
        deadline = started + (1.0 - _RESERVE) * problem.time_budget
        colony = self.colony(graph, deadline)
        vertices, _ = simplify(problem, graph, colony.path, self.params)
        statistics = {
            "cycles": float(colony.cycles),
            "ants": float(self.params.ants),
            "best_cost": colony.cost,
            "converged": float(colony.converged),
            "nodes": float(graph.usable_nodes),
            "waypoints": float(len(vertices)),
        }
        return self._timed(problem, ends, vertices, statistics)

    def _timed(
        self,
        problem: PathProblem,
        ends: _Ends,
        vertices: np.ndarray,
        statistics: dict[str, float],
    ) -> Trajectory | NoPath:
        """The polyline flown with blends (or rest to rest), checked; see the module
        docstring."""
        keep = np.append(True, np.linalg.norm(np.diff(vertices, axis=0), axis=1) > _SHORTEST)
        vertices = vertices[keep]
        accel, goal = problem.max_acceleration, problem.goal
        cruise = self.params.speed_fraction * problem.max_speed
        available = None if goal.time is None else goal.time - ends.start_time
        if len(vertices) < 2:  # already there: hold, until the goal's time if it sets one
            hold = max(available or 0.0, 1e-3)
            samples = (np.array([0.0, hold]), np.vstack([vertices, vertices]), np.zeros((2, 3)))
            return self._checked(problem, ends, samples, statistics)
        length = float(np.linalg.norm(np.diff(vertices, axis=0), axis=1).sum())
        fastest = min(problem.max_speed, blend_speed_limit(vertices, accel))
        attempts: list[Samples] = []
        reason = ""
        if available is None:
            speed = min(cruise, fastest)
            attempts += [blended(vertices, speed, accel), blended(vertices, speed / 2, accel)]
        else:
            needed = cruise_speed(length, max(available, 1e-9), accel)
            if needed <= fastest * (1 + 1e-9) and available > 0:
                attempts.append(blended(vertices, min(needed, fastest), accel))
            else:
                best = length / fastest + (0.0 if math.isinf(accel) else fastest / accel)
                reason = (
                    f"the {length:.3g} m path needs {best:.4g} s at the speed and acceleration "
                    f"limits; the goal's time leaves {available:.4g} s"
                )
        attempts.append(rest_to_rest(vertices, min(cruise, problem.max_speed), accel))
        for samples in attempts:
            if available is not None:
                late = samples[0][-1] - available
                if late > goal.time_tolerance:
                    reason = reason or (
                        f"the path arrives {late:.3g} s after the goal's time {goal.time:g} s"
                    )
                    continue
                if late < 0:
                    t, p, v = samples
                    samples = (
                        np.append(t, available),
                        np.vstack([p, p[-1]]),
                        np.vstack([v, 0 * v[-1]]),
                    )
            answer = self._checked(problem, ends, samples, statistics)
            if isinstance(answer, Trajectory):
                return answer
            reason = answer.reason
        return NoPath(reason)

    def _checked(
        self,
        problem: PathProblem,
        ends: _Ends,
        samples: Samples,
        statistics: dict[str, float],
    ) -> Trajectory | NoPath:
        """The trajectory of the braking piece and ``samples``, if it keeps half the
        clearance from every obstacle, stays in bounds and within the delta-v limit."""
        braking = ends.braking
        parts = [braking, samples] if len(braking[0]) > 1 else [samples]
        times, positions, velocities = _chain(parts, problem.start.time)
        if problem.bounds is not None and not problem.bounds.contains(positions).all():
            return NoPath("the timed path leaves the bounds")
        changes = np.diff(np.vstack([problem.start.velocity, velocities]), axis=0)
        delta_v = float(np.linalg.norm(changes, axis=1).sum())
        if delta_v > problem.max_delta_v:
            return NoPath(
                f"the path needs {delta_v:.3g} m/s of delta-v, above {problem.max_delta_v:g}"
            )
        trajectory = Trajectory(
            times=times,
            positions=positions,
            velocities=velocities,
            delta_v=delta_v,
            length=float(np.linalg.norm(np.diff(positions, axis=0), axis=1).sum()),
            duration=float(times[-1] - times[0]),
            statistics=statistics,
        )
        if problem.obstacles:
            closest = path_clearance(trajectory, problem)
            if closest.distance < 0.5 * self.params.clearance:
                return NoPath(
                    f"the timed path passes {closest.distance:.3g} m from obstacle "
                    f"{closest.obstacle_id} at t = {closest.time:.1f} s (needs "
                    f"{0.5 * self.params.clearance:.3g} m)"
                )
        return trajectory


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the ant colony path planner."""
    return [AntColonyPlanner]
