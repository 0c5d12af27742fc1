"""``multi-burn`` path planner: the fewest-burn transfer that clears the obstacles (Boeing paper).

The second experiment the Boeing guidance paper proposes (its §6), for a free
flyer in an inertial or a Clohessy–Wiltshire (LVLH) frame: solve the two-burn transfer,
and when it does not clear the obstacles, move to successively more burns, looking for
each new burn point on a grid scaled to the plan's legs, so that the grids grow finer as
the burns grow in number; collisions are tested along the whole trajectory.

Plans
    Waypoints joined by free arcs (``FreeMotion.single_burn``: closed-form Clohessy–
    Wiltshire transition), an impulsive burn at each: the first from the start's
    velocity onto the first arc, the last from the arrival at the goal's centre onto the
    goal's velocity (:class:`BurnPlan`). A plan of ``k`` legs has ``k + 1`` burns.
Limits (those of ``grid-astar``)
    The mean speed of every leg (chord over duration) within ``[min_speed,
    problem.max_speed]`` (the leg into a goal that sets a time need not keep the least
    speed: the time sets its duration), every burn within ``max_burn``, every leg within
    the frame's longest single arc (``FreeMotion.longest_duration``), the whole plan
    within ``problem.max_delta_v``, and the burns fitting their legs when flown at
    ``problem.max_acceleration``: a leg spends at most :data:`FIT_SHARE` of its duration
    in burns (all of the first and the last burn, which start at the start and end on
    arrival, half of each interior one, centred on its waypoint). A goal with a time
    fixes the plan's duration.
Cost
    ``w_dv Σ|Δv| + w_L Σ chord + w_T T`` with the problem's weights (straight-line
    distance between waypoints, as ``grid-astar``'s).
Two burns
    The direct transfer from the start to the goal: its duration scanned on
    :data:`SCAN_POINTS` geometric steps between the chord at the speed limit and the
    chord at the least speed (or the longest arc), the cheapest within the limits
    refined by a bounded scalar minimisation (``scipy.optimize.minimize_scalar``), or
    the goal's time when it sets one. In an inertial frame, at rest at both ends, this
    is the slowest transfer: ``T = chord / min_speed``, delta-v ``2 min_speed``.
Collisions
    Swept: every arc sampled at most ``check_spacing`` of closing distance apart, the
    robot's sphere (``robot_radius`` + the problem's ``safety_margin``, grown by half
    the largest step between samples but at least half of ``check_spacing``, as the
    flown trajectory's check grows it, and by how far flying the burns at the problem's
    acceleration takes the robot off the arcs) tested against every obstacle's true
    shape where the obstacle is at each sample's time (``ObstacleField.arc_overlaps``,
    which also gives how deep an arc goes in). Samples also stay in the problem's
    bounds.
More burns
    When the best plan so far collides, one burn is added: each leg of the few best
    plans that collides is split at a new waypoint. The waypoint is searched on a grid
    of ``grid_points``³ points spanning the leg's ends, grown on every side by half the
    leg's chord (at least two robot reaches), so the grid shrinks with the legs as the
    burns multiply; the two new legs take each pair of ``speed_levels`` mean speeds
    (geometric from the least to the largest), which fixes the waypoint's time (with a
    goal time, all legs are then scaled to keep it). Every candidate's cost and limits
    are evaluated at once (numpy, over candidates and legs); the cheapest within the
    limits are swept in batches, and the ``refine`` cheapest clear ones, a grid step or
    more apart (or, when too few are clear, the least colliding), are refined.
Refinement
    Nelder–Mead over every waypoint (m, in steps of half the grid spacing) and the log
    of every leg's duration, minimising the cost plus :data:`PENALTY` times the limit
    violations and the collision depth in robot reaches (measured with :data:`SLACK`
    more clearance, so the optimum lies just inside the free space). The cheapest clear
    plan met on the way is kept: each is verified by the same exact swept check.
Answer
    The cheapest clear plan found. Burns are added only while no plan is clear (the
    paper's rule), up to ``max_burns``, and then ``extra_burns`` more times: about an
    orbit a plan with one more burn can be cheaper even when the direct arc is clear,
    as its longer path at the least speed takes longer. It is flown with each burn at
    the problem's acceleration (``BurnPlan.trajectory``) and the flown trajectory is
    checked once more against the obstacles before it is returned. Nothing is random:
    the same problem gives the same plan.

Statistics: ``burns`` (of the answer), ``candidates_evaluated`` (plans whose cost and
limits were computed: transfer times scanned and grid candidates), ``plans_tried``
(plans swept for collisions, grid candidates and refinement steps), ``refinements``
(Nelder–Mead runs).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from dcsim_plugins.path_planners.deadline import OutOfTime, check
from dcsim_plugins.path_planners.obstacle_field import ObstacleField, endpoint_refusal
from dcsim_plugins.path_planners.relative_motion import (
    BurnPlan,
    FreeMotion,
    SpeedLimits,
    swept_arcs,
)
from scipy.optimize import minimize, minimize_scalar

from dcsim.api import (
    NoPath,
    PathPlanner,
    PathPlannerParams,
    PathProblem,
    Trajectory,
    hookimpl,
    quantity,
)

FIT_SHARE = 0.9
"""Largest share of a leg's duration its burns may take, s/s."""
SCAN_POINTS = 48
"""Transfer times tried by the two-burn scan."""
PENALTY = 10.0
"""Weight of one unit of limit violation (relative excess) or of collision depth (robot
reaches), in units of the direct two-burn transfer's cost."""
SLACK = 0.05
"""Extra clearance the refinement aims for, in robot reaches."""
LOG_STEP = 0.2
"""Nelder–Mead's first step in the log of a leg's duration."""
XATOL = 1e-2
"""Nelder–Mead's tolerance on the simplex, in first steps."""
FATOL = 1e-4
"""Nelder–Mead's tolerance on the objective, in units of the direct transfer's cost."""
EVALUATIONS_PER_VARIABLE = 100
"""Nelder–Mead evaluations allowed per variable of a refinement."""
SHORTEST_LEG = 1e-3
"""Shortest leg the two-burn scan tries, s."""
MOST_SAMPLES = 4000
"""Most swept samples of one arc (the sphere's margin grows to match)."""
BATCH_PAIRS = 400_000
"""Swept samples times obstacles of one batch of candidates (bounds the memory and the
time of one check)."""
SWEPT_PER_REFINEMENT = 256
"""Candidates swept for collisions per candidate to refine, at most, at each number of
burns."""
KEPT_PLANS = 8
"""Clear plans kept for the answer (the cheapest)."""


class MultiBurnParams(PathPlannerParams):
    """Parameters of :class:`MultiBurnPlanner`.

    ``min_speed`` and ``max_burn`` mean what they mean to ``grid-astar`` and, left
    unset, follow the paper's Table 2 scaled to the problem's speed limit ``v`` the same
    way (:class:`SpeedLimits`): least speed ``0.09/0.19 v``, largest burn ``0.2/0.19 v``.
    Where ``grid-astar`` also holds an unset ``max_burn`` to half a time step of thrust,
    this planner has no time step: it keeps each leg long enough for the burns at its
    ends instead (see the module docstring).
    """

    min_speed: float | None = quantity(
        None,
        unit="m/s",
        gt=0,
        description="Least mean speed of a leg (unset: 0.09/0.19 of the speed limit); the "
        "largest is the problem's speed limit. Positive: in a force-free frame a slower "
        "transfer is always cheaper.",
    )
    max_burn: float | None = quantity(
        None,
        unit="m/s",
        gt=0,
        description="Largest single delta-v (unset: 0.2/0.19 of the speed limit).",
    )
    max_burns: int = quantity(
        6, ge=2, le=12, description="Most burns of a plan, the first and the last included."
    )
    grid_points: int = quantity(
        9,
        ge=2,
        le=41,
        description="Points along each axis of the grid a new waypoint is searched on.",
    )
    speed_levels: int = quantity(
        4,
        ge=1,
        le=16,
        description="Mean speeds tried for each new leg, geometric from min_speed to the "
        "speed limit.",
    )
    extra_burns: int = quantity(
        0,
        ge=0,
        le=10,
        description="Burns beyond the fewest that clear the obstacles to try for a cheaper "
        "plan (within max_burns).",
    )
    refine: int = quantity(
        4, ge=1, le=64, description="Candidates refined at each number of burns."
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


@dataclass
class Statistics:
    """Counts of one search."""

    candidates_evaluated: int = 0
    plans_tried: int = 0
    refinements: int = 0

    def as_dict(self, burns: int) -> dict[str, float]:
        """The trajectory's statistics mapping."""
        return {
            "burns": float(burns),
            "candidates_evaluated": float(self.candidates_evaluated),
            "plans_tried": float(self.plans_tried),
            "refinements": float(self.refinements),
        }


@dataclass(frozen=True)
class Assessment:
    """Cost and limits of a batch of ``C`` plans of ``k`` legs (:meth:`BurnSearch.assess`).

    Attributes
    ----------
    cost : ndarray (C,)
        Weighted cost (module docstring), in the weights' units.
    delta_v : ndarray (C,)
        Total delta-v, m/s.
    violation : ndarray (C,)
        Sum of the relative excesses over the limits; 0 within them.
    depth : ndarray (C, k) or None
        Largest overlap of each leg's swept sphere with an obstacle, or its distance out
        of the bounds, m; None when not swept.
    """

    cost: np.ndarray
    delta_v: np.ndarray
    violation: np.ndarray
    depth: np.ndarray | None = None

    @property
    def swept_depth(self) -> np.ndarray:
        """``depth`` of an assessment made with ``sweep`` (C, k), m.

        Raises
        ------
        ValueError
            If the plans were not swept.
        """
        if self.depth is None:
            raise ValueError("the plans were not swept: assess them with sweep=True")
        return self.depth


@dataclass(frozen=True)
class Candidate:
    """One plan: waypoints, leg durations and how it fares.

    Attributes
    ----------
    positions : ndarray (k + 1, 3)
        Waypoints, m: the start, the intermediate ones, the goal's centre.
    durations : ndarray (k,)
        Leg durations, s.
    cost : float
        Weighted cost.
    violation : float
        Relative excess over the limits (0 within them).
    depth : ndarray (k,)
        Collision depth of each leg, m (0: clear).
    step : float
        Grid spacing it was found on, m (the refinement's first step is half of it).
    """

    positions: np.ndarray
    durations: np.ndarray
    cost: float
    violation: float
    depth: np.ndarray
    step: float

    @property
    def clear(self) -> bool:
        """Whether it is within the limits and clear of the obstacles."""
        return self.violation == 0.0 and not np.any(self.depth > 0.0)


@dataclass
class BurnSearch:
    """The search of one path problem for a plan of few burns (see the module docstring).

    Parameters
    ----------
    problem : PathProblem
        The problem.
    params : MultiBurnParams
        The planner's parameters.
    """

    problem: PathProblem
    params: MultiBurnParams
    motion: FreeMotion = field(init=False)
    limits: SpeedLimits = field(init=False)
    obstacles: ObstacleField = field(init=False)

    def __post_init__(self) -> None:
        problem = self.problem
        self.limits = SpeedLimits.derive(
            self.params.min_speed, self.params.max_burn, problem.max_speed
        )
        self.motion = FreeMotion.of(problem.frame)
        self.obstacles = ObstacleField(problem)
        self.everyone = np.arange(self.obstacles.count)
        goal, start = problem.goal, problem.start
        self.total = None if goal.time is None else float(goal.time - start.time)
        self.reach = max(self.obstacles.reach, self.params.check_spacing)
        self.penalty = PENALTY
        self.statistics = Statistics()
        self.found: list[Candidate] = []
        self.deadline = math.inf

    # ------------------------------------------------------------------ evaluation
    def assess(
        self,
        positions: np.ndarray,
        durations: np.ndarray,
        sweep: bool = False,
        slack: float = 0.0,
    ) -> Assessment:
        """Cost, limits and (with ``sweep``) collision depth of a batch of plans.

        Parameters
        ----------
        positions : ndarray (C, k + 1, 3)
            Waypoints of each plan, m, from the start to the goal's centre.
        durations : ndarray (C, k)
            Leg durations, s.
        sweep : bool
            Whether to sweep the legs against the obstacles.
        slack : float
            Extra clearance of the sweep, m: the depths then count from it.

        Returns
        -------
        Assessment
        """
        limits, problem = self.limits, self.problem
        longest = self.motion.longest_duration
        durations = np.asarray(durations, dtype=float)
        solved = np.clip(durations, SHORTEST_LEG * 1e-3, longest)
        departures, arrivals = self.motion.single_burn(positions[:, :-1], positions[:, 1:], solved)
        count = len(positions)
        before = np.concatenate(
            [np.broadcast_to(problem.start.velocity, (count, 1, 3)), arrivals], axis=1
        )
        after = np.concatenate(
            [departures, np.broadcast_to(problem.goal.velocity, (count, 1, 3))], axis=1
        )
        burns = after - before
        sizes = np.linalg.norm(burns, axis=-1)
        delta_v = sizes.sum(axis=1)
        chords = np.linalg.norm(np.diff(positions, axis=1), axis=-1)
        weights = problem.weights
        cost = (
            weights.delta_v * delta_v
            + weights.length * chords.sum(axis=1)
            + weights.time * durations.sum(axis=1)
        )
        speeds = chords / np.maximum(durations, 1e-12)
        violation = np.maximum(speeds / limits.max_speed - 1.0, 0.0).sum(axis=1)
        slow = np.maximum(1.0 - speeds / limits.min_speed, 0.0)
        if self.total is not None:
            slow[:, -1] = 0.0
        violation += slow.sum(axis=1)
        violation += np.maximum(sizes / limits.max_burn - 1.0, 0.0).sum(axis=1)
        spans = sizes / problem.max_acceleration
        shares = spans.copy()
        shares[:, 1:-1] *= 0.5
        busy = shares[:, :-1] + shares[:, 1:]
        violation += np.maximum(busy / (FIT_SHARE * durations) - 1.0, 0.0).sum(axis=1)
        if math.isfinite(longest):
            violation += np.maximum(durations / longest - 1.0, 0.0).sum(axis=1)
        if math.isfinite(problem.max_delta_v):
            violation += np.maximum(delta_v / problem.max_delta_v - 1.0, 0.0)
        depth = None
        if sweep:
            drift = self._burn_drift(burns, spans, departures, arrivals)
            depth = self._depths(positions, durations, solved, departures, drift, slack)
        return Assessment(cost, delta_v, violation, depth)

    @staticmethod
    def _burn_drift(
        burns: np.ndarray, spans: np.ndarray, departures: np.ndarray, arrivals: np.ndarray
    ) -> np.ndarray:
        """How far flying each leg's end burns with finite thrust can take the robot off
        the leg's arc, (C, k) m: ``|Δv| s / 8`` for an interior burn of ``s`` seconds
        centred on its waypoint (the corner it cuts), ``|Δv⊥| s / 2`` for the first and
        the last (the part of the burn across the arc they join)."""
        drift = np.linalg.norm(burns, axis=-1) * spans / 8.0
        for end, velocity in ((0, departures[:, 0]), (-1, arrivals[:, -1])):
            speed = np.linalg.norm(velocity, axis=-1, keepdims=True)
            along = np.divide(velocity, speed, out=np.zeros_like(velocity), where=speed > 0)
            across = burns[:, end] - np.sum(burns[:, end] * along, axis=-1)[:, None] * along
            drift[:, end] = np.linalg.norm(across, axis=-1) * spans[:, end] / 2.0
        drift = np.nan_to_num(drift)
        return np.maximum(drift[:, :-1], drift[:, 1:])

    def _depths(
        self,
        positions: np.ndarray,
        durations: np.ndarray,
        solved: np.ndarray,
        departures: np.ndarray,
        drift: np.ndarray,
        slack: float,
    ) -> np.ndarray:
        """Collision depth of every leg of a batch of plans (swept, true shapes, moving
        obstacles where they are at each sample's time), (C, k) m."""
        count, legs = durations.shape
        starts = self.problem.start.time + np.concatenate(
            [np.zeros((count, 1)), np.cumsum(durations, axis=1)[:, :-1]], axis=1
        )
        elapsed, points, margins = swept_arcs(
            self.motion,
            positions[:, :-1],
            departures,
            solved,
            self.problem.max_speed,
            self.obstacles.max_obstacle_speed,
            self.params.check_spacing,
            MOST_SAMPLES,
        )
        samples = points.shape[2]
        depth = self.obstacles.arc_overlaps(
            points.reshape(count * legs, samples, 3),
            (starts[..., None] + elapsed).reshape(count * legs, samples),
            (np.maximum(margins, 0.5 * self.params.check_spacing) + drift).ravel() + slack,
            self.everyone,
        ).reshape(count, legs)
        bounds = self.problem.bounds
        if bounds is not None:
            outside = np.maximum(bounds.lower - points, points - bounds.upper)
            depth += np.maximum(outside.max(axis=(2, 3)), 0.0)
        return depth

    def _sweep_batches(self, legs: int, durations: np.ndarray) -> int:
        """How many plans of ``legs`` legs one sweep may take."""
        closing = self.problem.max_speed + self.obstacles.max_obstacle_speed
        samples = min(
            int(np.ceil(closing * float(durations.max()) / self.params.check_spacing)) + 1,
            MOST_SAMPLES,
        )
        pairs = legs * max(samples, 2) * max(self.obstacles.count, 1)
        return max(1, BATCH_PAIRS // pairs)

    def _candidate(self, positions: np.ndarray, durations: np.ndarray, step: float) -> Candidate:
        """A plan, assessed and swept."""
        found = self.assess(positions[None], durations[None], sweep=True)
        self.statistics.plans_tried += 1
        candidate = Candidate(
            positions,
            durations,
            float(found.cost[0]),
            float(found.violation[0]),
            found.swept_depth[0],
            step,
        )
        self._keep(candidate)
        return candidate

    def _keep(self, candidate: Candidate) -> None:
        """Remember a clear plan (the cheapest :data:`KEPT_PLANS`)."""
        if candidate.clear:
            self.found.append(candidate)
            self.found.sort(key=lambda c: c.cost)
            del self.found[KEPT_PLANS:]

    def score(self, candidate: Candidate) -> float:
        """Cost plus the penalties of limit violations and collision depth."""
        return candidate.cost + self.penalty * (
            candidate.violation + float(candidate.depth.sum()) / self.reach
        )

    def _check_time(self) -> None:
        check(self.deadline, f"{self.statistics.plans_tried} plans tried")

    # ------------------------------------------------------------------ two burns
    def two_burn(self) -> Candidate:
        """The best direct transfer (module docstring), swept; it sets the penalty scale."""
        start, goal = self.problem.start.position, self.problem.goal.position
        chord = float(np.linalg.norm(goal - start))
        ends = np.array([start, goal], dtype=float)
        if self.total is not None:
            times = np.array([self.total])
        else:
            lowest = max(chord / self.limits.max_speed, SHORTEST_LEG)
            highest = max(min(chord / self.limits.min_speed, self.motion.longest_duration), lowest)
            times = np.unique(np.geomspace(lowest, highest, SCAN_POINTS))
        scan = self.assess(np.broadcast_to(ends, (len(times), 2, 3)), times[:, None])
        self.statistics.candidates_evaluated += len(times)
        cheapest = float(scan.cost[scan.violation == 0].min(initial=np.inf))
        if not math.isfinite(cheapest) or cheapest <= 0:
            cheapest = float(np.median(scan.cost))
        scale = cheapest if cheapest > 0 else 1.0
        self.penalty = PENALTY * scale
        scores = scan.cost + self.penalty * scan.violation
        best = int(np.argmin(scores))
        duration = float(times[best])
        if len(times) > 1:

            def score(t: float) -> float:
                found = self.assess(ends[None], np.array([[t]]))
                return float(found.cost[0] + self.penalty * found.violation[0])

            low, high = times[max(best - 1, 0)], times[min(best + 1, len(times) - 1)]
            refined = minimize_scalar(
                score, bounds=(low, high), method="bounded", options={"xatol": 1e-6 * high}
            )
            self.statistics.candidates_evaluated += int(refined.nfev)
            if refined.fun < scores[best]:
                duration = float(refined.x)
        return self._candidate(ends, np.array([duration]), max(chord, self.reach))

    # ------------------------------------------------------------------ more burns
    def insertions(self, seeds: list[Candidate]) -> tuple[np.ndarray, ...]:
        """Every plan with one more waypoint in a colliding leg of a seed (module
        docstring): waypoints (C, k + 2, 3) m, durations (C, k + 1) s, the new waypoint
        (C, 3) m and its grid's spacing (C,) m."""
        limits, points = self.limits, self.params.grid_points
        if limits.min_speed >= limits.max_speed:
            speeds = np.array([limits.max_speed])
        else:
            speeds = np.geomspace(limits.min_speed, limits.max_speed, self.params.speed_levels)
        bounds = self.problem.bounds
        parts: list[tuple[np.ndarray, ...]] = []
        for seed in seeds:
            legs = np.flatnonzero(seed.depth > 0)
            if not len(legs):
                legs = np.arange(len(seed.durations))
            for leg in map(int, legs):
                a, b = seed.positions[leg], seed.positions[leg + 1]
                grow = max(0.5 * float(np.linalg.norm(b - a)), 2.0 * self.reach)
                low, high = np.minimum(a, b) - grow, np.maximum(a, b) + grow
                if bounds is not None:
                    low, high = np.maximum(low, bounds.lower), np.minimum(high, bounds.upper)
                axes = [np.linspace(lo, hi, points) for lo, hi in zip(low, high, strict=True)]
                grid = np.array(np.meshgrid(*axes, indexing="ij")).reshape(3, -1).T
                grid_spacing = float(np.mean((high - low) / (points - 1)))
                first = np.linalg.norm(grid - a, axis=1)
                second = np.linalg.norm(b - grid, axis=1)
                keep = (first > 1e-9) & (second > 1e-9)
                grid, first, second = grid[keep], first[keep], second[keep]
                count = len(grid) * len(speeds) ** 2
                one = (first[:, None, None] / speeds[:, None]).repeat(len(speeds), axis=2)
                two = (second[:, None, None] / speeds[None, :]).repeat(len(speeds), axis=1)
                new = np.repeat(grid, len(speeds) ** 2, axis=0)
                positions = np.concatenate(
                    [
                        np.broadcast_to(seed.positions[: leg + 1], (count, leg + 1, 3)),
                        new[:, None, :],
                        np.broadcast_to(
                            seed.positions[leg + 1 :], (count, len(seed.positions) - leg - 1, 3)
                        ),
                    ],
                    axis=1,
                )
                durations = np.concatenate(
                    [
                        np.broadcast_to(seed.durations[:leg], (count, leg)),
                        one.reshape(-1, 1),
                        two.reshape(-1, 1),
                        np.broadcast_to(
                            seed.durations[leg + 1 :], (count, len(seed.durations) - leg - 1)
                        ),
                    ],
                    axis=1,
                )
                parts.append((positions, durations, new, np.full(count, grid_spacing)))
        positions, durations, new, spacing = (np.concatenate(p) for p in zip(*parts, strict=True))
        if self.total is not None:
            durations = durations * (self.total / durations.sum(axis=1, keepdims=True))
        return positions, durations, new, spacing

    def pick(
        self, positions: np.ndarray, durations: np.ndarray, new: np.ndarray, spacing: np.ndarray
    ) -> list[Candidate]:
        """The candidates to refine: the cheapest clear ones within the limits, a grid
        step apart, then the least colliding, ``refine`` in all."""
        wanted = self.params.refine
        found = self.assess(positions, durations)
        self.statistics.candidates_evaluated += len(positions)
        feasible = np.flatnonzero(found.violation == 0)
        if len(feasible):
            order = feasible[np.argsort(found.cost[feasible], kind="stable")]
        else:
            scores = found.cost + self.penalty * found.violation
            order = np.argsort(scores, kind="stable")
        order = order[: wanted * SWEPT_PER_REFINEMENT]
        batch = self._sweep_batches(positions.shape[1] - 1, durations[order])
        clear: list[int] = []
        colliding: list[tuple[float, int]] = []
        depths: dict[int, np.ndarray] = {}
        for first in range(0, len(order), batch):
            self._check_time()
            rows = order[first : first + batch]
            swept = self.assess(positions[rows], durations[rows], sweep=True)
            self.statistics.plans_tried += len(rows)
            for row, depth, violation, cost in zip(
                rows, swept.swept_depth, swept.violation, swept.cost, strict=True
            ):
                depths[int(row)] = depth
                if violation == 0 and not np.any(depth > 0):
                    if _apart(new, spacing, clear, int(row)):
                        clear.append(int(row))
                else:
                    total = violation + float(depth.sum()) / self.reach
                    colliding.append((float(cost + self.penalty * total), int(row)))
            if len(clear) >= wanted:
                break
        chosen = clear[:wanted]
        for _, row in sorted(colliding):
            if len(chosen) >= wanted:
                break
            if _apart(new, spacing, chosen, row):
                chosen.append(row)
        out = []
        for row in chosen:
            assessed = self.assess(positions[row][None], durations[row][None])
            candidate = Candidate(
                positions[row],
                durations[row],
                float(assessed.cost[0]),
                float(assessed.violation[0]),
                depths[row],
                float(spacing[row]),
            )
            self._keep(candidate)
            out.append(candidate)
        return out

    def refine(self, candidate: Candidate) -> Candidate:
        """Nelder–Mead from a candidate (module docstring); the cheapest clear plan met,
        else where the search ended."""
        self.statistics.refinements += 1
        inner = len(candidate.positions) - 2
        step = 0.5 * candidate.step
        slack = SLACK * self.reach
        best = candidate if candidate.clear else None

        def unpack(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            positions = candidate.positions.copy()
            positions[1:-1] += step * x[: 3 * inner].reshape(inner, 3)
            durations = candidate.durations * np.exp(LOG_STEP * x[3 * inner :])
            if self.total is not None:
                durations *= self.total / durations.sum()
            return positions, durations

        def objective(x: np.ndarray) -> float:
            nonlocal best
            self._check_time()
            positions, durations = unpack(x)
            found = self.assess(positions[None], durations[None], sweep=True, slack=slack)
            self.statistics.plans_tried += 1
            cost, violation, depth = (
                float(found.cost[0]),
                float(found.violation[0]),
                found.swept_depth[0],
            )
            exact = np.maximum(depth - slack, 0.0)
            if violation == 0 and not np.any(exact > 0) and (best is None or cost < best.cost):
                best = Candidate(positions, durations, cost, 0.0, exact, candidate.step)
                self._keep(best)
            return cost + self.penalty * (violation + float(depth.sum()) / self.reach)

        size = 3 * inner + len(candidate.durations)
        start = np.zeros(size)
        result = minimize(
            objective,
            start,
            method="Nelder-Mead",
            options={
                "initial_simplex": np.vstack([start, np.eye(size)]),
                "maxfev": EVALUATIONS_PER_VARIABLE * size,
                "xatol": XATOL,
                "fatol": FATOL * self.penalty / PENALTY,
                "adaptive": size > 5,
            },
        )
        if best is not None:
            return best
        positions, durations = unpack(result.x)
        return self._candidate(positions, durations, candidate.step)

    # ------------------------------------------------------------------ search
    def run(self, deadline: float) -> list[Candidate] | NoPath:
        """The clear plans found (the cheapest :data:`KEPT_PLANS`, cheapest first), or why
        there are none."""
        self.deadline = deadline
        burns = 2
        try:
            seeds = [self.two_burn()]
            clear_at = burns if self.found else None
            while burns < self.params.max_burns and (
                clear_at is None or burns < clear_at + self.params.extra_burns
            ):
                if not seeds:
                    break
                burns += 1
                positions, durations, new, spacing = self.insertions(seeds)
                picked = self.pick(positions, durations, new, spacing)
                refined = [self.refine(c) for c in picked]
                seeds = sorted(refined, key=self.score)[: self.params.refine]
                if clear_at is None and self.found:
                    clear_at = burns
        except OutOfTime:
            if self.found:
                return self.found
            return NoPath(
                f"no clear plan of up to {burns} burns within the time budget "
                f"({self.statistics.plans_tried} plans tried)"
            )
        if self.found:
            return self.found
        return NoPath(
            f"no plan of up to {self.params.max_burns} burns clears the obstacles within "
            f"the limits ({self.statistics.plans_tried} plans tried)"
        )

    def plan(self, candidate: Candidate) -> BurnPlan:
        """The burn plan of a candidate."""
        times = self.problem.start.time + np.concatenate([[0.0], np.cumsum(candidate.durations)])
        return BurnPlan(
            self.motion,
            times,
            candidate.positions,
            self.problem.start.velocity,
            self.problem.goal.velocity,
        )

    def flown_clear(self, trajectory: Trajectory) -> bool:
        """Whether the flown trajectory, as its samples give it (linear between them),
        stays clear of the obstacles (``ObstacleField.clear_trajectory``) and in the
        bounds."""
        bounds = self.problem.bounds
        if bounds is not None and not bool(bounds.contains(trajectory.positions).all()):
            return False
        return self.obstacles.clear_trajectory(trajectory, self.params.check_spacing)


def _apart(new: np.ndarray, spacing: np.ndarray, chosen: list[int], row: int) -> bool:
    """Whether candidate ``row``'s new waypoint is a grid step or more from those of the
    ``chosen`` candidates."""
    if not chosen:
        return True
    gaps = np.linalg.norm(new[chosen] - new[row], axis=1)
    return bool(np.all(gaps >= spacing[row] * (1 - 1e-9)))


class MultiBurnPlanner(PathPlanner):
    """Two burns, then more at points searched on ever finer grids (Boeing paper §6)."""

    name = "multi-burn"
    summary = (
        "two-burn transfer, burns added one at a time at grid-searched, Nelder–Mead-refined "
        "waypoints until the swept trajectory clears the obstacles (Boeing paper §6)"
    )
    Params = MultiBurnParams
    params: MultiBurnParams
    handles_moving_obstacles = True

    def plan(self, problem: PathProblem) -> Trajectory | NoPath:
        """Search plans of more and more burns; the cheapest clear one, or why there is none."""
        deadline = problem.due()
        search = BurnSearch(problem, self.params)
        refusal = endpoint_refusal(problem, search.obstacles)
        if refusal is not None:
            return refusal
        if search.total is not None and search.total <= 0:
            return NoPath(f"the goal's time {problem.goal.time:g} s is not after the start")
        answer = search.run(deadline)
        if isinstance(answer, NoPath):
            return answer
        for candidate in answer:
            statistics = search.statistics.as_dict(burns=len(candidate.positions))
            try:
                trajectory = search.plan(candidate).trajectory(
                    problem.max_acceleration,
                    problem.robot_mass,
                    self.params.sample_step,
                    statistics,
                )
            except ValueError:
                continue
            if search.flown_clear(trajectory):
                return trajectory
        return NoPath(
            f"the {len(answer)} clear plans found collide or overlap their burns when flown "
            f"at {problem.max_acceleration:g} m/s²"
        )


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the multi-burn path planner."""
    return [MultiBurnPlanner]
