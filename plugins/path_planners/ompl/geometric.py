"""``ompl-geometric`` path planner: OMPL's geometric planners on positions, then timed.

OMPL plans a path of straight segments for the robot's centre in the problem's bounds
(without bounds: the box spanning the start and the goal, grown by half their distance
and at least 10 m) among the obstacles' TRUE shapes (sphere, box, cylinder) at rest. A
position is valid when the robot's sphere, grown by the problem's ``safety_margin`` and
by half the ``resolution``, is clear of every obstacle; OMPL checks each segment at
points at most ``resolution`` apart, so the whole segment is clear. The goal is the
first clear point among the goal region's centre, the ends of its axes and (for a box)
its corners and the middles of its edges and faces.

Planners (``planner``): ``rrtconnect`` (default; stops at its first path), ``rrt``,
``rrtstar``, ``informed-rrtstar`` and ``sorrtstar`` (asymptotically optimal: they
improve their path for ``optimise_for`` seconds, and carry on to the end of the budget
if they have none by then; they are not reproducible run to run): the geometric
planners that construct from Python in OMPL 2.0.1 and answer correctly. AORRTC
constructs too, but from Python it returns a zero-length path at the goal on every
problem tried (its log: "Zero-length path found. May have a common start/goal"), so it
is not offered. The path is simplified
(OMPL's ``simplifyMax``: shortcuts and vertex reduction, collision-checked).

Timing: rest to rest on every segment (``polyline_flight``), with the trapezoidal
profile of the ``straight-line`` planner (accelerate at ``max_acceleration``, cruise at
``speed_fraction`` of ``max_speed``, brake to rest at the vertex). A start that moves
first brakes to rest along its velocity (that stretch is checked too). A goal that sets
an arrival time is met by waiting at the goal; a goal that asks for a velocity the
robot cannot arrive at rest within is "no path". The attitude is held: the trajectory
leaves it free, so the transfer mission holds the goal's attitude or the start's.

Obstacles must be at rest (:attr:`handles_moving_obstacles` is False): with any obstacle
moving the answer is "no path: moving obstacles need ompl-control or a time-aware
planner". OMPL runs in a forked worker seeded from the plugin's generator
(``ompl_support``): with ``rrtconnect`` or ``rrt`` the same seed gives the same path.
Statistics: ``nodes_in_tree`` (PlannerData vertices: both trees for RRT-Connect),
``waypoints`` (of the simplified path) and ``raw_waypoints`` (before simplifying).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Literal

import numpy as np
from dcsim_plugins.path_planners.obstacle_field import ObstacleField, goal_or_refusal
from dcsim_plugins.path_planners.ompl.support import in_worker, seed_ompl
from dcsim_plugins.path_planners.polyline_flight import (
    SHORTEST,
    Samples,
    arrival_refusal,
    chain,
    rest_to_rest_segment,
    trajectory_of,
)
from ompl import base as ob
from ompl import geometric as og

from dcsim.api import (
    NoPath,
    PathPlanner,
    PathPlannerParams,
    PathProblem,
    Trajectory,
    hookimpl,
    quantity,
)

MOVING_REFUSAL = "no path: moving obstacles need ompl-control or a time-aware planner"
"""The answer to a problem with moving obstacles."""
_PLANNERS = {
    "rrtconnect": og.RRTConnect,
    "rrt": og.RRT,
    "rrtstar": og.RRTstar,
    "informed-rrtstar": og.InformedRRTstar,
    "sorrtstar": og.SORRTstar,
}
_OPTIMISING = {"rrtstar", "informed-rrtstar", "sorrtstar"}
_RESERVE = 0.05  # s of the budget kept for simplifying and returning the path
_MIN_SPAN = 10.0  # m: least growth of the box planned in when the problem has no bounds


class OmplGeometricParams(PathPlannerParams):
    """Parameters of :class:`OmplGeometricPlanner`."""

    planner: Literal["rrtconnect", "rrt", "rrtstar", "informed-rrtstar", "sorrtstar"] = quantity(
        "rrtconnect", description="OMPL geometric planner."
    )
    optimise_for: float = quantity(
        0.5,
        unit="s",
        gt=0,
        description="Least time the asymptotically optimal planners improve their path "
        "(within the budget).",
    )
    range: float = quantity(
        0.0, unit="m", ge=0, description="Longest tree edge; 0 lets OMPL choose."
    )
    resolution: float = quantity(
        0.25, unit="m", gt=0, description="Largest spacing of collision checks along a segment."
    )
    speed_fraction: float = quantity(
        0.8, gt=0, le=1, description="Fraction of the speed limit cruised at."
    )


@dataclass(frozen=True)
class Waypoints:
    """What a worker sends back: the simplified path and the planner's figures.

    Attributes
    ----------
    points : ndarray (k, 3) or None
        Vertices from the start to the goal point, m; None without an exact path.
    statistics : dict
        See the module docstring.
    """

    points: np.ndarray | None
    statistics: dict[str, float]


def planning_box(
    problem: PathProblem, start: np.ndarray, goal: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corners (m) positions are planned in."""
    if problem.bounds is not None:
        return np.asarray(problem.bounds.lower), np.asarray(problem.bounds.upper)
    grow = max(_MIN_SPAN, 0.5 * float(np.linalg.norm(goal - start)))
    return np.minimum(start, goal) - grow, np.maximum(start, goal) + grow


def goal_threshold(problem: PathProblem, point: np.ndarray) -> float:
    """Half the distance from ``point`` to the goal region's boundary (m), at least
    1e-9 m: a path ending that close to ``point`` ends inside the region."""
    goal = problem.goal
    offset = np.abs(point - goal.position)
    if goal.half_extents is None:
        inside = goal.tolerance - float(np.linalg.norm(offset))
    else:
        inside = float(np.min(goal.half_extents - offset))
    return max(1e-9, 0.5 * inside)


def solve(
    params: OmplGeometricParams,
    problem: PathProblem,
    start: np.ndarray,
    goal: np.ndarray,
    seed: int,
    deadline: float,
) -> Waypoints:
    """Plan from ``start`` to ``goal`` (m) until ``deadline`` (``time.monotonic()``), then
    simplify; run in a fresh worker (it seeds OMPL)."""
    seed_ompl(seed)
    field = ObstacleField(problem)
    t0, margin = problem.start.time, 0.5 * params.resolution
    space = ob.RealVectorStateSpace(3)
    lower, upper = planning_box(problem, start, goal)
    bounds = ob.RealVectorBounds(3)
    for k in range(3):
        bounds.setLow(k, float(lower[k]))
        bounds.setHigh(k, float(upper[k]))
    space.setBounds(bounds)
    setup = og.SimpleSetup(space)
    setup.setStateValidityChecker(lambda s: field.clear(s[0], s[1], s[2], t0, margin))
    si = setup.getSpaceInformation()
    si.setStateValidityCheckingResolution(params.resolution / space.getMaximumExtent())
    endpoints = []
    for point in (start, goal):
        state = si.allocState()
        for k in range(3):
            state[k] = float(point[k])
        endpoints.append(state)
    setup.setStartAndGoalStates(endpoints[0], endpoints[1], goal_threshold(problem, goal))
    planner = _PLANNERS[params.planner](si)
    if params.range > 0:
        planner.setRange(params.range)
    setup.setPlanner(planner)
    setup.setup()
    stop = deadline - _RESERVE
    chunk = params.optimise_for if params.planner in _OPTIMISING else math.inf
    while True:  # the optimising planners report a path only when they stop
        end = min(stop, time.monotonic() + chunk)
        setup.solve(ob.PlannerTerminationCondition(lambda end=end: time.monotonic() >= end))
        if setup.haveExactSolutionPath() or time.monotonic() >= stop:
            break
    data = ob.PlannerData(si)
    planner.getPlannerData(data)
    statistics = {"nodes_in_tree": float(data.numVertices())}
    if not setup.haveExactSolutionPath():
        return Waypoints(None, statistics)
    path = setup.getSolutionPath()
    statistics["raw_waypoints"] = float(path.getStateCount())
    og.PathSimplifier(si).simplifyMax(path)
    points = np.array(
        [[path.getState(i)[k] for k in range(3)] for i in range(path.getStateCount())]
    )
    statistics["waypoints"] = float(len(points))
    return Waypoints(points, statistics)


def _braking(position: np.ndarray, velocity: np.ndarray, acceleration: float) -> Samples:
    """Times (s), positions (m) and velocities (m/s) of braking to rest along
    ``velocity`` at ``acceleration`` (m/s², ``inf``: impulsive), from ``position``."""
    speed = float(np.linalg.norm(velocity))
    duration = speed / acceleration if math.isfinite(acceleration) else 0.0
    if duration == 0.0:
        return np.zeros(1), position[None], np.zeros((1, 3))
    tau = np.linspace(0.0, duration, 13)
    fraction = (1.0 - tau / duration)[:, None]
    positions = (
        position
        + velocity * tau[:, None]
        - 0.5 * velocity * (tau / duration)[:, None] * tau[:, None]
    )
    return tau, positions, velocity * fraction


class OmplGeometricPlanner(PathPlanner):
    """OMPL's geometric planners on positions among static obstacles, timed rest to rest."""

    name = "ompl-geometric"
    summary = (
        "RRT-Connect, RRT*, Informed RRT*... (OMPL) on positions among static obstacles, "
        "simplified, timed rest to rest"
    )
    Params = OmplGeometricParams
    params: OmplGeometricParams
    handles_moving_obstacles = False

    def plan(self, problem: PathProblem) -> Trajectory | NoPath:
        """Plan, simplify and time a path to the goal region by ``problem.due()``."""
        deadline = problem.due()
        budget = deadline - time.monotonic()  # the deadline, not time_budget, may govern
        field = ObstacleField(problem)
        if field.moving:
            return NoPath(MOVING_REFUSAL)
        goal = goal_or_refusal(problem, field)
        if isinstance(goal, NoPath):
            return goal
        start = problem.start
        stopping = _braking(
            np.asarray(start.position), np.asarray(start.velocity), problem.max_acceleration
        )
        stop = stopping[1][-1]
        if len(stopping[0]) > 1 and not field.clear_path(
            stopping[1],
            start.time + stopping[0],
            np.full(len(stopping[0]), 0.5 * self.params.resolution),
        ):
            return NoPath("braking from the start's velocity runs into an obstacle")
        seed = int(self.rng.integers(1, 2**31 - 1))
        args = (self.params, problem, stop, goal, seed, deadline)
        found = in_worker(solve, args, deadline)
        if found is None or found.points is None:
            return NoPath(f"no path within the {budget:.3g} s budget")
        return self._timed(problem, stopping, found.points, found.statistics)

    def _timed(
        self,
        problem: PathProblem,
        stopping: Samples,
        points: np.ndarray,
        statistics: dict[str, float],
    ) -> Trajectory | NoPath:
        """The waypoints ``points`` (k, 3) m flown rest to rest after braking, waiting for
        the goal's time; ``statistics`` are the worker's figures."""
        pieces = [stopping] if len(stopping[0]) > 1 else []
        speed = self.params.speed_fraction * problem.max_speed
        pieces += [
            rest_to_rest_segment(a, b, speed, problem.max_acceleration)
            for a, b in zip(points[:-1], points[1:], strict=True)
            if np.linalg.norm(b - a) > SHORTEST
        ]
        if not pieces:
            pieces = [(np.array([0.0]), points[:1], np.zeros((1, 3)))]
        times, positions, velocities = chain(pieces, problem.start.time)
        refusal = arrival_refusal(problem)
        if refusal is not None:
            return refusal
        goal = problem.goal
        if goal.time is not None:
            late = times[-1] - goal.time
            if late > goal.time_tolerance:
                return NoPath(
                    f"the path arrives {late:.1f} s after the goal's time {goal.time:g} s"
                )
            if late < 0:
                times = np.append(times, goal.time)
                positions = np.vstack([positions, positions[-1]])
                velocities = np.vstack([velocities, np.zeros(3)])
        if len(times) < 2:
            times = np.append(times, times[-1] + 1e-3)
            positions = np.vstack([positions, positions[-1]])
            velocities = np.vstack([velocities, velocities[-1]])
        return trajectory_of(problem, (times, positions, velocities), statistics)


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the OMPL geometric path planner."""
    return [OmplGeometricPlanner]
