"""``ant-colony`` path planner (the ant colony paper): ants choose one point per cross-section.

The planner of the ant colony collision-avoidance paper (LI Hua-Zhong and Liang
Yong-Sheng), for a free flyer among obstacles. A plan has three steps, each
in a module of its own (their docstrings give the details):

Candidate graph (:mod:`layered_graph`, eqs 4–9)
    The segment from the start S to the goal G is cut into ``parts`` (m) equal parts;
    the plane perpendicular to SG at each division point is a cross-section holding
    2n + 1 points on a line (``cross_section: line``, the paper) or (2n + 1)² on a grid.
    A path is S, one point of each cross-section in order, and G. A point closer to an
    obstacle's true shape than ``robot_radius + safety_margin`` is unusable, and so is a
    segment the robot's grown sphere, swept along it, touches. The objective is
    ``F = L + δ Σᵢ 1/d_min,i`` (eq. 8): the path's length plus δ (``delta``, m²) times
    the reciprocal clearances of its m − 1 points. The balance depends on the problem's
    scale and on m: on a 6 m transfer with clearances near 1 m, δ = 2 makes the safety
    term most of F, and the best path keeps to the edge of the cross-sections.
Ants (:mod:`colony`, eqs 10–13)
    Each cycle ``ants`` walk from S to G choosing each next point by roulette wheel on
    ``τ^α η^β`` (eq. 11), then lay pheromone ``Q/F`` on their segments while the old
    evaporates (eqs 12–13), until they converge, stall, run out of cycles or of time.
    The answer is the best path found in any cycle.
Flight (:mod:`polyline_flight`)
    The best path is reduced to fewer vertices (``layered_graph.simplify``) and flown at
    one cruise speed with parabolic corner blends, or rest to rest at every vertex when
    the blends cut too close; the timed trajectory is checked against the obstacles'
    predicted motion.
Departures from the paper (each a parameter; the defaults use them)
    The paper's constants are the defaults (α = 1, β = 5, ρ = 0.526, Q = 320, 30 ants,
    m = 40, 242 cycles, δ = 2), but its colony, scored against the exact optimum of the
    same graph (``dcsim.api.layered_optimum``), stops far above it: with β = 5 and
    ``η = 1/d_pq`` the ants hardly ever step sideways before an obstacle forces them to,
    so the δ term, which the visibility does not see, is left to the pheromone, and the
    pheromone of the first cycles' paths (Q/F against C) fixes the colony on one of
    them within a few dozen cycles. Four changes bring it to the optimum (:mod:`colony`
    describes each): ``visibility: objective``, ``local_search``, ``deposit_by: best``
    and ``pheromone_floor``. With ``visibility: length``, ``local_search: false``,
    ``deposit_by: all`` and ``pheromone_floor: 0`` the colony is the paper's.
Moving obstacles (an extension; the paper's are at rest)
    Each layer is taken to be crossed when a nominal straight flight from S to G reaches
    it, and its points and segments are judged against the obstacles' predicted places
    then. The flown timing differs from the nominal one; the timed trajectory is
    therefore checked again and the answer is "no path" if that check fails.

Statistics: ``cycles`` (cycles run), ``ants``, ``best_cost`` (F of the answer),
``converged`` (1 if the colony converged before ``max_cycles`` and the budget),
``nodes`` (usable candidate points), ``waypoints`` (vertices flown). The best cost of
every cycle is in :class:`~colony.ColonyResult`. The plugin's own bench
(:mod:`ant_colony_bench`, ``dcsim bench ant-colony``, added through the
``dcsim_register_commands`` hook) reaches both halves: ``planner.candidate_graph(problem)``
is the graph :meth:`~AntColonyPlanner.plan` searches (its ``lengths`` and
``node_cost`` are what ``dcsim.api.layered_optimum`` minimises exactly) and
``planner.colony(graph)`` runs the colony on it with the planner's generator.
"""

from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING, Literal

import numpy as np
from dcsim_plugins.path_planners.ant_colony.colony import ColonyResult, solve_colony
from dcsim_plugins.path_planners.ant_colony.layered_graph import (
    GraphUnfinished,
    LayeredGraph,
    build_graph,
    endpoints,
    graph_between,
    simplify,
)
from dcsim_plugins.path_planners.polyline_flight import (
    SHORTEST,
    Departure,
    arrival_refusal,
    fly_polyline,
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

if TYPE_CHECKING:
    import click

PAPER_PARTS = 40
"""The paper's number of equal parts m."""
_RESERVE = 0.1  # share of the time budget kept for timing and checking the path


class AntColonyParams(PathPlannerParams):
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
        0.3,
        ge=0,
        le=1,
        description="Least pheromone as a share of the most a segment can hold, "
        "k Q / (F_best (1 - ρ)) with k the ants that lay (0: none, the paper; 0.3 chosen "
        "on the 100 layouts of `dcsim bench ant-colony`, where 0.1 left the p95 gap at "
        "δ = 6 at 3.3 %).",
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


class AntColonyPlanner(PathPlanner):
    """Ant colony over points on cross-sections of the start-goal segment (the ant colony paper)."""

    name = "ant-colony"
    summary = (
        "Ant colony choosing one point per cross-section of the start-goal segment, "
        "objective length + δ Σ 1/clearance; corner-blended timing (ant colony paper)"
    )
    Params = AntColonyParams
    params: AntColonyParams
    handles_moving_obstacles = True

    def candidate_graph(self, problem: PathProblem) -> LayeredGraph:
        """The graph :meth:`plan` searches for ``problem`` (:func:`~layered_graph.build_graph`
        with this planner's parameters), for scoring the colony against the exact optimum
        of the same graph (``dcsim.api.layered_optimum``).

        Raises
        ------
        ValueError
            When the problem has no graph (the start or the goal inside an obstacle or
            outside the bounds, or the start at the goal).
        """
        return build_graph(problem, self.params)

    def colony(self, graph: LayeredGraph, deadline: float = math.inf) -> ColonyResult:
        """Run this planner's colony on ``graph`` with its generator
        (:func:`~colony.solve_colony`): the best path, its objective and the best
        objective of every cycle."""
        return solve_colony(graph, self.params, self.rng, deadline)

    def plan(self, problem: PathProblem) -> Trajectory | NoPath:
        """Build the graph, run the colony, simplify and fly the best path."""
        started, due = time.monotonic(), problem.due()
        refusal = arrival_refusal(problem)
        if refusal is not None:
            return refusal
        ends = endpoints(problem, self.params)
        if isinstance(ends, NoPath):
            return ends
        if np.linalg.norm(ends.goal - ends.start) < SHORTEST:
            return self._flown(problem, ends.departure, ends.start[None], {"cycles": 0.0})
        deadline = due - _RESERVE * max(0.0, due - started)
        try:
            graph = graph_between(problem, self.params, ends, deadline)
        except GraphUnfinished as unfinished:
            return NoPath(
                f"no path within the time budget: the candidate graph was not finished "
                f"({unfinished}; a coarser check_spacing tests boxes and cylinders faster)"
            )
        if not graph.has_path:
            return NoPath(
                f"every path across the {self.params.parts - 1} cross-sections meets an "
                "obstacle or leaves the bounds (widen half_width or add points)"
            )
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
        return self._flown(problem, ends.departure, vertices, statistics)

    def _flown(
        self,
        problem: PathProblem,
        start: Departure,
        vertices: np.ndarray,
        statistics: dict[str, float],
    ) -> Trajectory | NoPath:
        """The polyline flown at this planner's speed and checked with the problem's
        safety margin."""
        return fly_polyline(problem, start, vertices, self.params.speed_fraction, statistics)


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the ant colony path planner."""
    return [AntColonyPlanner]


@hookimpl
def dcsim_register_commands(bench: click.Group) -> None:
    """Add ``dcsim bench ant-colony``: the colony against its graph's exact optimum."""
    from dcsim_plugins.path_planners.ant_colony.bench import command

    bench.add_command(command)
