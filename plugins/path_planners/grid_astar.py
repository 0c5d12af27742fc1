"""``grid-astar`` path planner: A* on a space-time grid with delta-v cost (Boeing paper).

The planner of the Boeing guidance paper (§4–§5) for a free flyer in an
inertial or a Clohessy–Wiltshire (LVLH) frame.

Grid
    Points ``start + d (i, j, k)`` at times ``t₀ + m t`` (``distance_resolution`` d,
    ``time_resolution`` t), anchored at the start. A search state is a grid point with
    the velocity it arrives with (the paper's 7-D point: position, incoming velocity,
    time). The velocity follows from the move that reached the point, so two states are
    the same when they share the point, the time step and the move; the time step is
    left out of that comparison when no obstacle moves and the goal has no time (the
    frame's free motion does not depend on time, so nothing else would).
Moves (the paper's two neighbour sets)
    Offsets ``δ`` reached after one time step at any distance, and offsets ``|δ| < 2``
    (in units of d) after any number of steps up to ``max_leg_steps``; in both, the mean
    speed ``|δ| d / Δt`` lies within ``[min_speed, problem.max_speed]``.
    A move is one impulsive burn at its start onto the free arc that reaches the
    neighbour after Δt (``FreeMotion.single_burn``: closed-form Clohessy–Wiltshire
    transition); the arc gives the velocity at the neighbour. A burn larger than
    ``max_burn`` is not allowed.
Goal
    From every state the goal's centre is tried as one more neighbour (set 1 or set 2
    distance), then a last burn matches the goal's velocity; both burns are within
    ``max_burn``. The goal has no time: arrival after whole time steps, within both
    speed limits; the goal has a time: arrival then, within the speed limit (the least
    speed would make some goal times unreachable).
Cost
    Of a move, ``w_dv |Δv| + w_L |δ| d + w_T Δt`` with the problem's weights (straight-
    line distance, as in the paper); the last burn is added to the arrival.
Heuristic (``heuristic``)
    ``two-burn``: the direct two-burn transfer to the goal state, arriving at the goal's
    time (the paper's first variant) or, when the goal has none, after the distance
    divided by the state's speed (its second variant; speeds clipped to the limits,
    durations to the frame's longest single arc). Not admissible: A* may return a plan
    dearer than the grid's best. ``lower-bound``: ``w_dv |v_goal − v| + w_L |r_goal − r|
    + w_T |r_goal − r| / max_speed``, a lower bound on the remaining cost in an inertial
    frame (burns add up to at least the velocity change), so A* returns the grid's
    cheapest plan there; about an orbit the free motion changes velocity too and the
    bound is approximate.
Collisions (``collision``)
    ``swept``: every arc sampled at most ``check_spacing`` of closing distance apart,
    the robot's sphere (``robot_radius`` + the problem's ``safety_margin``, grown by
    half the largest closing between samples and by ``max_burn² / 2a``, the most the
    path flown with finite burns strays from the impulsive arcs) clear of every
    obstacle's true shape where the obstacle is at each sample's time; the trajectory
    flown is checked again at the end. ``grid-points``: the paper's test, at the grid
    points alone, so an arc between two clear points may cross an obstacle. Tests
    against obstacles at rest are done once per grid point and move.

Statistics: ``points_searched`` (states taken off the open list and expanded, the
paper's measure; also reported as ``nodes_expanded``), ``nodes_generated`` (states
put on the open list), ``open_peak`` (the open list's largest size), ``burns``.
The answer is the plan's arcs sampled every ``sample_step`` with each burn flown at the
problem's acceleration (``BurnPlan.trajectory``); forces are given when the problem
carries the robot's mass.
"""

from __future__ import annotations

import heapq
import itertools
import math
import time
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from dcsim_plugins.path_planners.obstacle_field import ObstacleField, endpoint_refusal
from dcsim_plugins.path_planners.relative_motion import (
    BurnPlan,
    FreeMotion,
    SpeedLimits,
    swept_arcs,
)

from dcsim.api import (
    NoPath,
    PathPlanner,
    PathPlannerParams,
    PathProblem,
    Trajectory,
    hookimpl,
    quantity,
)

FOOT = 0.3048
"""One foot, m: the paper's unit."""

PAPER_STEPS_PER_CELL = 0.19 * 60.0 / 6.0
"""The paper's largest speed times its time step over its grid spacing (1.9)."""
BURN_SHARE = 0.45
"""Share of a derived time step that the burn from rest onto the slowest one-step move
may take."""


class GridAStarParams(PathPlannerParams):
    """Parameters of :class:`GridAStarPlanner`.

    Left unset, the grid follows the paper's Table 2 scaled to the problem's speed limit
    ``v``: least speed ``0.09/0.19 v``, largest burn ``0.2/0.19 v`` (but at most what
    the problem's acceleration gives in half a time step, so that burns flown with
    finite thrust never overlap), grid spacing 6 ft and the time step that makes
    ``v t = 1.9 d`` (the paper's 60 s at 0.19 ft/s). Where the burn from rest onto the
    slowest one-step move (speed ``v / 1.9``) would take more than :data:`BURN_SHARE` of
    that step, the step grows until it does not, and the spacing with it
    (``d = v t / 1.9``). At the paper's 0.19 ft/s this gives exactly its 6 ft, 60 s,
    0.09 ft/s and 0.2 ft/s.
    """

    distance_resolution: float | None = quantity(
        None, unit="m", gt=0, description="Grid spacing d (unset: see the class docstring)."
    )
    time_resolution: float | None = quantity(
        None, unit="s", gt=0, description="Time step t (unset: see the class docstring)."
    )
    min_speed: float | None = quantity(
        None,
        unit="m/s",
        ge=0,
        description="Least mean speed of a move (unset: 0.09/0.19 of the speed limit); "
        "the largest is the problem's speed limit.",
    )
    max_burn: float | None = quantity(
        None,
        unit="m/s",
        gt=0,
        description="Largest single delta-v (unset: 0.2/0.19 of the speed limit, at most "
        "half a time step of thrust).",
    )
    max_leg_steps: int = quantity(
        10, ge=1, le=1000, description="Longest move of the second neighbour set, in time steps."
    )
    heuristic: Literal["two-burn", "lower-bound"] = quantity(
        "two-burn",
        description="The paper's two-burn estimate, or a lower bound (admissible in an "
        "inertial frame).",
    )
    collision: Literal["swept", "grid-points"] = quantity(
        "swept", description="Check whole arcs, or only grid points as the paper did."
    )
    check_spacing: float = quantity(
        0.1,
        unit="m",
        gt=0,
        description="Largest closing of robot and obstacle between two swept samples.",
    )
    sample_step: float = quantity(
        5.0, unit="s", gt=0, description="Time between samples of the returned trajectory."
    )


@dataclass(frozen=True)
class GridSettings:
    """The grid of one problem: the parameters with every unset value derived.

    Attributes
    ----------
    distance_resolution, time_resolution : float
        d (m) and t (s).
    min_speed, max_speed : float
        Limits on a move's mean speed, m/s.
    max_burn : float
        Largest single delta-v, m/s.
    """

    distance_resolution: float
    time_resolution: float
    min_speed: float
    max_speed: float
    max_burn: float

    @classmethod
    def derive(cls, params: GridAStarParams, problem: PathProblem) -> GridSettings:
        """Fill the unset parameters from the problem (see :class:`GridAStarParams`)."""
        v, a = problem.max_speed, problem.max_acceleration
        limits = SpeedLimits.derive(params.min_speed, params.max_burn, v)
        d, t = params.distance_resolution, params.time_resolution
        if t is None:
            d = d if d is not None else 6 * FOOT
            t = PAPER_STEPS_PER_CELL * d / v
            slowest_step = v / PAPER_STEPS_PER_CELL  # speed of a one-cell, one-step move
            if params.distance_resolution is None and slowest_step / (BURN_SHARE * a) > t:
                t = slowest_step / (BURN_SHARE * a)
                d = v * t / PAPER_STEPS_PER_CELL
        elif d is None:
            d = v * t / PAPER_STEPS_PER_CELL
        max_burn = limits.max_burn
        if params.max_burn is None:
            max_burn = min(max_burn, 0.5 * a * t)
        return cls(d, t, limits.min_speed, v, max_burn)


@dataclass(frozen=True)
class MoveTable:
    """Every move of the grid: offset, duration and the free-motion blocks for it.

    Attributes
    ----------
    offsets : ndarray (M, 3) of int
        Grid offsets δ.
    steps : ndarray (M,) of int
        Durations in time steps.
    displacement : ndarray (M, 3)
        ``δ d``, m.
    distance, duration : ndarray (M,)
        ``|δ| d`` (m) and ``steps t`` (s).
    position_blocks, inverse_rv, vr, vv : ndarray (M, 3, 3)
        ``Φ_rr``, ``Φ_rv⁻¹``, ``Φ_vr`` and ``Φ_vv`` over each duration.
    """

    offsets: np.ndarray
    steps: np.ndarray
    displacement: np.ndarray
    distance: np.ndarray
    duration: np.ndarray
    position_blocks: np.ndarray
    inverse_rv: np.ndarray
    vr: np.ndarray
    vv: np.ndarray

    def departures(self, position: np.ndarray) -> np.ndarray:
        """Velocity after the burn at ``position`` (m) for every move, (M, 3) m/s."""
        gap = self.displacement + position - np.einsum("mij,j->mi", self.position_blocks, position)
        return np.einsum("mij,mj->mi", self.inverse_rv, gap)

    def arrivals(
        self, position: np.ndarray, departures: np.ndarray, rows: np.ndarray
    ) -> np.ndarray:
        """Velocity at the neighbour for the moves ``rows``, given their departures, (r, 3) m/s."""
        return np.einsum("mij,j->mi", self.vr[rows], position) + np.einsum(
            "mij,mj->mi", self.vv[rows], departures
        )


def neighbour_moves(
    distance_resolution: float,
    time_resolution: float,
    min_speed: float,
    max_speed: float,
    max_leg_steps: int,
    longest_duration: float = math.inf,
) -> tuple[np.ndarray, np.ndarray]:
    """The paper's neighbour sets: offsets and durations (in steps) of every move.

    Set 1: one time step away, any distance; set 2: less than two grid spacings away,
    up to ``max_leg_steps`` steps. In both the mean speed is within the limits.

    Parameters
    ----------
    distance_resolution, time_resolution : float
        d (m) and t (s).
    min_speed, max_speed : float
        Limits on the mean speed of a move, m/s.
    max_leg_steps : int
        Longest move of set 2, in steps.
    longest_duration : float
        Longest move allowed by the frame, s.

    Returns
    -------
    offsets : ndarray (M, 3) of int
    steps : ndarray (M,) of int
    """
    d, t = distance_resolution, time_resolution
    reach = int(np.floor(max_speed * t / d + 1e-9))
    span = np.arange(-max(reach, 1), max(reach, 1) + 1)
    cube = np.array(np.meshgrid(span, span, span, indexing="ij")).reshape(3, -1).T
    lengths = np.linalg.norm(cube, axis=1)
    moves: set[tuple[tuple[int, ...], int]] = set()
    for steps in range(1, max_leg_steps + 1):
        if steps * t > longest_duration:
            break
        speed = lengths * d / (steps * t)
        allowed = (lengths > 0) & (speed >= min_speed - 1e-12) & (speed <= max_speed + 1e-12)
        if steps > 1:
            allowed &= lengths < 2
        moves.update((tuple(o), steps) for o in cube[allowed])
    ordered = sorted(moves, key=lambda m: (m[1], m[0]))
    offsets = np.array([m[0] for m in ordered], dtype=int).reshape(-1, 3)
    return offsets, np.array([m[1] for m in ordered], dtype=int)


def move_table(
    motion: FreeMotion, offsets: np.ndarray, steps: np.ndarray, d: float, t: float
) -> MoveTable:
    """The :class:`MoveTable` of the given moves."""
    duration = steps * t
    rr, rv, vr, vv = motion.blocks(duration)
    return MoveTable(
        offsets=offsets,
        steps=steps,
        displacement=offsets * d,
        distance=np.linalg.norm(offsets, axis=1) * d,
        duration=duration,
        position_blocks=rr,
        inverse_rv=np.linalg.inv(rv),
        vr=vr,
        vv=vv,
    )


@dataclass
class SearchState:
    """One state of the search: a grid point reached by a move, with its velocity.

    An arrival at the goal (``goal``) keeps its parent's cell and step and the duration
    of its last arc, s.
    """

    cell: tuple[int, int, int]
    step: int
    move: int
    velocity: np.ndarray
    cost: float
    parent: int
    goal: bool = False
    duration: float = 0.0


@dataclass
class Statistics:
    """Counts of one search."""

    points_searched: int = 0
    nodes_generated: int = 0
    open_peak: int = 0

    def as_dict(self, burns: int) -> dict[str, float]:
        """The trajectory's statistics mapping."""
        return {
            "points_searched": float(self.points_searched),
            "nodes_expanded": float(self.points_searched),
            "nodes_generated": float(self.nodes_generated),
            "open_peak": float(self.open_peak),
            "burns": float(burns),
        }


@dataclass
class GridSearch:
    """One A* search of a path problem on the grid (see the module docstring)."""

    problem: PathProblem
    params: GridAStarParams
    motion: FreeMotion = field(init=False)
    moves: MoveTable = field(init=False)
    obstacles: ObstacleField = field(init=False)

    def __post_init__(self) -> None:
        p, problem = self.params, self.problem
        grid = self.grid = GridSettings.derive(p, problem)
        self.motion = FreeMotion.of(problem.frame)
        offsets, steps = neighbour_moves(
            grid.distance_resolution,
            grid.time_resolution,
            grid.min_speed,
            grid.max_speed,
            p.max_leg_steps,
            self.motion.longest_duration,
        )
        self.moves = move_table(
            self.motion, offsets, steps, grid.distance_resolution, grid.time_resolution
        )
        self.obstacles = ObstacleField(problem)
        # how far the flown path may stray from the impulsive arcs near a burn
        self.corner_cut = 0.5 * grid.max_burn**2 / problem.max_acceleration
        self.resting = self.obstacles.resting_indices
        self.moving = self.obstacles.moving_indices
        self.timed_key = len(self.moving) > 0 or problem.goal.time is not None
        self.origin = problem.start.position
        self.resting_clear: dict[tuple[int, int, int], np.ndarray] = {}
        self.states: list[SearchState] = []
        self.best: dict[tuple, float] = {}
        self.statistics = Statistics()
        weights = problem.weights
        self.w_dv, self.w_length, self.w_time = weights.delta_v, weights.length, weights.time
        self.move_cost = self.w_length * self.moves.distance + self.w_time * self.moves.duration

    # ------------------------------------------------------------------ geometry
    def position(self, cell: tuple[int, int, int]) -> np.ndarray:
        """The grid point of a cell, m."""
        return self.origin + self.grid.distance_resolution * np.asarray(cell, dtype=float)

    def time_of(self, step: int) -> float:
        """The time of a time step, s."""
        return self.problem.start.time + step * self.grid.time_resolution

    def _arc_samples(
        self, position: np.ndarray, departures: np.ndarray, durations: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Samples of each arc from ``position`` (:func:`swept_arcs`): times since its
        start (m, s) s, points (m, s, 3) m, and each arc's margin (m,) m."""
        return swept_arcs(
            self.motion,
            position,
            departures,
            durations,
            self.problem.max_speed,
            self.obstacles.max_obstacle_speed,
            self.params.check_spacing,
        )

    def _clear(
        self,
        position: np.ndarray,
        start_time: float,
        departures: np.ndarray,
        durations: np.ndarray,
        which: np.ndarray,
    ) -> np.ndarray:
        """Whether each arc from ``position`` is clear of the obstacles ``which``."""
        if self.params.collision == "grid-points":
            ends, _ = self.motion.propagate(position, departures, durations)
            points, elapsed = ends[:, None, :], durations[:, None]
            margins = np.zeros(len(durations))
        else:
            elapsed, points, margins = self._arc_samples(position, departures, durations)
            margins = np.maximum(margins, 0.5 * self.params.check_spacing) + self.corner_cut
        inside = np.ones(len(durations), dtype=bool)
        if self.problem.bounds is not None:
            inside = np.all(self.problem.bounds.contains(points), axis=1)
        return inside & self.obstacles.clear_arcs(points, start_time + elapsed, margins, which)

    def _resting_clear(self, cell: tuple[int, int, int], position: np.ndarray) -> np.ndarray:
        """Which moves from ``cell`` clear the obstacles at rest (cached per cell)."""
        known = self.resting_clear.get(cell)
        if known is None:
            departures = self.moves.departures(position)
            known = self._clear(position, 0.0, departures, self.moves.duration, self.resting)
            self.resting_clear[cell] = known
        return known

    # ------------------------------------------------------------------ heuristic
    def heuristic(
        self, positions: np.ndarray, velocities: np.ndarray, times: np.ndarray
    ) -> np.ndarray:
        """Estimated cost from each state to the goal (see the module docstring)."""
        goal = self.problem.goal
        offset = goal.position - positions
        distance = np.linalg.norm(offset, axis=1)
        if self.params.heuristic == "lower-bound":
            return (
                self.w_dv * np.linalg.norm(goal.velocity - velocities, axis=1)
                + self.w_length * distance
                + self.w_time * distance / self.problem.max_speed
            )
        if goal.time is not None:
            remaining = goal.time - times
        else:
            speed = np.clip(
                np.linalg.norm(velocities, axis=1),
                max(self.grid.min_speed, 1e-3 * self.problem.max_speed),
                self.problem.max_speed,
            )
            remaining = distance / speed
        remaining = np.minimum(remaining, self.motion.longest_duration)
        estimate = np.full(len(positions), np.inf)
        usable = remaining > 1e-9
        if usable.any():
            delta_v = self.motion.two_burn_delta_v(
                positions[usable],
                velocities[usable],
                goal.position,
                goal.velocity,
                remaining[usable],
            )
            estimate[usable] = (
                self.w_dv * delta_v
                + self.w_length * distance[usable]
                + self.w_time * remaining[usable]
            )
        here = distance < 1e-9
        estimate[here] = self.w_dv * np.linalg.norm(goal.velocity - velocities[here], axis=1)
        return estimate

    # ------------------------------------------------------------------ search
    def run(self, deadline: float) -> BurnPlan | NoPath:
        """A* from the start to the goal; the plan, or why there is none."""
        start = self.problem.start
        root = SearchState((0, 0, 0), 0, -1, start.velocity, 0.0, -1)
        self.states.append(root)
        h0 = self.heuristic(start.position[None], start.velocity[None], np.array([start.time]))[0]
        tie = itertools.count()
        queue: list[tuple[float, int, int]] = [(float(h0), next(tie), 0)]
        while queue:
            if time.monotonic() > deadline:
                return NoPath(
                    f"no path within the time budget ({self.statistics.points_searched} points "
                    f"searched, {len(queue)} open)"
                )
            _, _, index = heapq.heappop(queue)
            state = self.states[index]
            if state.goal:
                return self._plan(index)
            if state.cost > self.best.get(self._key(state), math.inf):
                continue
            self.statistics.points_searched += 1
            for child, estimate in self._expand(index):
                heapq.heappush(queue, (child.cost + estimate, next(tie), len(self.states)))
                self.states.append(child)
                self.statistics.nodes_generated += 1
            self.statistics.open_peak = max(self.statistics.open_peak, len(queue))
        return NoPath(
            f"the grid has no path to the goal ({self.statistics.points_searched} points searched)"
        )

    def _key(self, state: SearchState) -> tuple:
        return (state.cell, state.step if self.timed_key else 0, state.move)

    def _expand(self, index: int) -> list[tuple[SearchState, float]]:
        """The children of a state that are new or cheaper than known, with estimates."""
        state = self.states[index]
        position = self.position(state.cell)
        now = self.time_of(state.step)
        moves = self.moves
        departures = moves.departures(position)
        burns = np.linalg.norm(departures - state.velocity, axis=1)
        usable = (burns <= self.grid.max_burn) & self._resting_clear(state.cell, position)
        if len(self.moving) and usable.any():
            rows = np.flatnonzero(usable)
            usable[rows] = self._clear(
                position, now, departures[rows], moves.duration[rows], self.moving
            )
        children = self._goal_children(index, position, now)
        rows = np.flatnonzero(usable)
        if not len(rows):
            return children
        costs = state.cost + self.w_dv * burns[rows] + self.move_cost[rows]
        arrivals = moves.arrivals(position, departures[rows], rows)
        fresh = []
        for row, cost, arrival in zip(rows, costs, arrivals, strict=True):
            x, y, z = (int(c) for c in np.add(state.cell, moves.offsets[row]))
            child = SearchState(
                (x, y, z), state.step + int(moves.steps[row]), int(row), arrival, float(cost), index
            )
            key = self._key(child)
            if cost < self.best.get(key, math.inf):
                self.best[key] = float(cost)
                fresh.append(child)
        if not fresh:
            return children
        positions = np.array([self.position(c.cell) for c in fresh])
        velocities = np.array([c.velocity for c in fresh])
        times = np.array([self.time_of(c.step) for c in fresh])
        estimates = self.heuristic(positions, velocities, times)
        children += [(c, float(e)) for c, e in zip(fresh, estimates, strict=True) if np.isfinite(e)]
        return children

    def _goal_children(
        self, index: int, position: np.ndarray, now: float
    ) -> list[tuple[SearchState, float]]:
        """Arrivals at the goal's centre from this state, each with its last burn."""
        goal, params, state = self.problem.goal, self.params, self.states[index]
        distance = float(np.linalg.norm(goal.position - position))
        t = self.grid.time_resolution
        if goal.time is not None:
            durations = np.array([goal.time - now])
        elif distance < 2 * self.grid.distance_resolution:
            durations = t * np.arange(1, params.max_leg_steps + 1, dtype=float)
        else:
            durations = np.array([t])
        durations = durations[
            (durations > 1e-9)
            & (durations <= self.motion.longest_duration)
            & (distance <= self.problem.max_speed * durations * (1 + 1e-9))
        ]
        if goal.time is None:  # the least speed holds too, unless the arrival time is set
            durations = durations[distance >= self.grid.min_speed * durations * (1 - 1e-9)]
        if not len(durations):
            return []
        departures, arrivals = self.motion.single_burn(
            np.broadcast_to(position, (len(durations), 3)),
            np.broadcast_to(goal.position, (len(durations), 3)),
            durations,
        )
        first = np.linalg.norm(departures - state.velocity, axis=1)
        last = np.linalg.norm(goal.velocity - arrivals, axis=1)
        usable = (first <= self.grid.max_burn) & (last <= self.grid.max_burn)
        usable &= (first + last) / self.problem.max_acceleration <= durations
        everyone = np.arange(self.obstacles.count)
        usable &= self._clear(position, now, departures, durations, everyone)
        children = []
        for k in np.flatnonzero(usable):
            cost = (
                state.cost
                + self.w_dv * (first[k] + last[k])
                + self.w_length * distance
                + self.w_time * durations[k]
            )
            arrival = SearchState(
                state.cell,
                state.step,
                -1,
                goal.velocity,
                float(cost),
                index,
                goal=True,
                duration=float(durations[k]),
            )
            children.append((arrival, 0.0))
        return children

    def _plan(self, index: int) -> BurnPlan:
        """The burn plan from the start to the goal state ``index``."""
        chain = []
        while index >= 0:
            chain.append(self.states[index])
            index = self.states[index].parent
        chain.reverse()
        *path, arrival = chain
        times = [self.time_of(s.step) for s in path]
        times.append(times[-1] + arrival.duration)
        positions = [self.position(s.cell) for s in path] + [self.problem.goal.position]
        return BurnPlan(
            self.motion,
            np.array(times),
            np.array(positions),
            self.problem.start.velocity,
            self.problem.goal.velocity,
        )


class GridAStarPlanner(PathPlanner):
    """A* over positions, incoming velocities and times with delta-v cost (Boeing paper)."""

    name = "grid-astar"
    summary = (
        "A* on a space-time grid, one impulsive burn per move on Clohessy–Wiltshire arcs, "
        "weighted delta-v, distance and time cost (Boeing paper)"
    )
    Params = GridAStarParams
    params: GridAStarParams
    handles_moving_obstacles = True

    def plan(self, problem: PathProblem) -> Trajectory | NoPath:
        """Search the grid; the cheapest plan found, or why there is none."""
        deadline = problem.due()
        search = GridSearch(problem, self.params)
        refusal = endpoint_refusal(problem, search.obstacles)
        if refusal is not None:
            return refusal
        if not len(search.moves.steps):
            return NoPath("no move of the grid keeps the speed limits")
        answer = search.run(deadline)
        if isinstance(answer, NoPath):
            return answer
        statistics = search.statistics.as_dict(burns=len(answer.times))
        try:
            flown = answer.trajectory(
                problem.max_acceleration, problem.robot_mass, self.params.sample_step, statistics
            )
        except ValueError:
            return NoPath(
                f"the plan's burns take longer than its legs at "
                f"{problem.max_acceleration:g} m/s²: lower max_burn or raise time_resolution"
            )
        swept = self.params.collision == "swept"
        if swept and not search.obstacles.clear_trajectory(flown, self.params.check_spacing):
            return NoPath(
                "the plan flown with finite burns cuts a corner into an obstacle: "
                "raise the safety margin (mission.safety_distance) or lower max_burn"
            )
        return flown


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the grid A* path planner."""
    return [GridAStarPlanner]
