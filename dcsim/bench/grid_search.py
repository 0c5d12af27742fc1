"""``dcsim bench grid-search``: the Boeing paper's Tables 3 and 4 regenerated on dcsim's station.

The Boeing guidance paper (§5) ran its grid A* from the start ⟨0, 0, 0⟩ to three goals
under five weightings of delta-v and distance, and reported the points searched
(Table 3) and the total delta-v (Table 4), four runs unfinished after 6 hours; a
hand-made three-burn path to the third goal cost 0.404 ft/s against the grid's 0.870.
This bench poses the same nine-by-five grid on ``scenarios/station_inspection.yaml``
(the paper's station geometry is not published, so the figures compare planners on
dcsim's layout, not with the paper's values), prints the paper's figures beside
``grid-astar``'s, adds ``multi-burn``'s delta-v per goal (the yardstick of §6), and on
request flies every plan through the transfer mission.

Delta-v is reported in ft/s, the paper's unit; the weights scale feet and feet per
second alike, so their ratio is unchanged in SI.
"""

from __future__ import annotations

import copy
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from dcsim.bench.path_planners import Flight, fly
from dcsim.bench.path_problems import BenchProblem, load_problem
from dcsim.messages import CostWeights, NoPath, PathProblem, Trajectory
from dcsim.registry.discovery import PluginRegistry
from dcsim.registry.interfaces import PathPlanner
from dcsim.yardsticks.clearance import path_clearance

FOOT = 0.3048
"""One foot, m."""

GOALS = {
    "<1 2.167 0>": (1.8288, 3.9624, 0.0),
    "<1 4 1>": (1.8288, 7.3152, 1.8288),
    "<8.667 -.667 9.833>": (15.8496, -1.2192, 17.9832),
}
"""The paper's goals in 6 ft grid units, and where they are in the scenario, m."""

WEIGHTINGS = ((0.0, 1.0), (1.0, 1.0), (1.0, 0.5), (1.0, 0.1), (1.0, 0.0))
"""The paper's (delta-v, distance) weightings, the columns of Tables 3 and 4."""

PAPER_POINTS = (
    (18, 73, 127, 538, 1883),
    (67, 274, 492, 2351, 11217),
    (1560, 33361, None, None, None),
)
"""Table 3: points searched; None where the run did not finish in 6 hours."""

PAPER_DELTA_V = (
    (0.355, 0.355, 0.355, 0.333, 0.333),
    (0.485, 0.420, 0.420, 0.420, 0.420),
    (0.872, 0.870, None, None, None),
)
"""Table 4: total delta-v, ft/s; None where the run did not finish."""

PAPER_THREE_BURN = 0.404
"""The paper's hand-made three-burn path to the third goal, ft/s."""

Progress = Callable[[str], None]


@dataclass(frozen=True)
class Cell:
    """One planner on one goal under one weighting.

    Attributes
    ----------
    planner : str
        Plugin name.
    goal : str
        The goal in the paper's grid units.
    weights : tuple of float
        (delta-v, distance) weights.
    status : str
        ``solved``, ``no path`` (with ``reason``).
    seconds : float
        Planning wall time, s.
    points : float
        Points searched (``grid-astar``), or NaN.
    delta_v : float
        Planned total delta-v, ft/s (NaN without a plan).
    collides : bool
        Whether the plan's swept clearance finds a collision.
    clearance : float
        Its least gap to an obstacle, m.
    trajectory : Trajectory or None
        The plan.
    reason : str
        Why there is no plan.
    flight : Flight or None
        The plan flown, when asked.
    """

    planner: str
    goal: str
    weights: tuple[float, float]
    status: str
    seconds: float
    points: float = float("nan")
    delta_v: float = float("nan")
    collides: bool = False
    clearance: float = float("nan")
    trajectory: Trajectory | None = None
    reason: str = ""
    flight: Flight | None = None


def goal_problem(
    bench: BenchProblem, goal: str, weights: tuple[float, float], budget: float
) -> PathProblem:
    """The scenario's path problem towards one of the paper's goals under one weighting."""
    problem = bench.problem
    return replace(
        problem,
        goal=replace(problem.goal, position=np.array(GOALS[goal])),
        weights=CostWeights(weights[0], weights[1], 0.0),
        time_budget=budget,
    )


def plan_cell(
    registry: PluginRegistry,
    planner: str,
    problem: PathProblem,
    goal: str,
    weights: tuple[float, float],
    params: Mapping[str, Any] | None = None,
) -> Cell:
    """Plan one cell in this process and judge the plan with the swept clearance."""
    planner_class = registry.get("path_planner", planner).cls
    # the registry files plugins by their class's kind
    assert issubclass(planner_class, PathPlanner)
    plugin = planner_class(params, np.random.default_rng(0))
    began = time.perf_counter()
    answer = plugin.plan(problem)
    seconds = time.perf_counter() - began
    if isinstance(answer, NoPath):
        return Cell(planner, goal, weights, "no path", seconds, reason=answer.reason)
    closest = path_clearance(answer, problem)
    return Cell(
        planner,
        goal,
        weights,
        "solved",
        seconds,
        points=float(answer.statistics.get("points_searched", float("nan"))),
        delta_v=answer.delta_v / FOOT,
        collides=closest.collides,
        clearance=closest.distance,
        trajectory=answer,
    )


def fly_cell(
    cell: Cell, bench: BenchProblem, registry: PluginRegistry, params: Mapping[str, Any] | None
) -> Cell:
    """Fly a solved cell's goal and weighting through the transfer mission, with time to
    spare beyond the plan's duration."""
    if cell.trajectory is None:
        return cell
    document = copy.deepcopy(bench.document)
    x, y, z = GOALS[cell.goal]
    for assignment in (
        f"mission.goal.position=[{x},{y},{z}]",
        f"mission.weights.delta_v={cell.weights[0]}",
        f"mission.weights.length={cell.weights[1]}",
        f"world.duration={cell.trajectory.duration + 120.0:.0f}",
        "mission.planning_budget=60",
    ):
        document.apply_override(assignment)
    return replace(cell, flight=fly(document, cell.planner, 0, registry, params))


def bench_grid_search(
    registry: PluginRegistry,
    scenario: Path,
    budget: float,
    flights: bool,
    progress: Progress = print,
    grid_params: Mapping[str, Any] | None = None,
) -> list[Cell]:
    """Every goal under every weighting with ``grid-astar``, and every goal with
    ``multi-burn`` (weights (1, 0): delta-v alone), each with a ``budget`` s budget."""
    bench = load_problem(str(scenario))
    cells = []
    jobs: list[tuple[str, str, tuple[float, float], Mapping[str, Any] | None]] = [
        ("grid-astar", goal, weights, grid_params) for goal in GOALS for weights in WEIGHTINGS
    ]
    jobs += [("multi-burn", goal, (1.0, 0.0), None) for goal in GOALS]
    for planner, goal, weights, params in jobs:
        problem = goal_problem(bench, goal, weights, budget)
        cell = plan_cell(registry, planner, problem, goal, weights, params)
        if flights:
            cell = fly_cell(cell, bench, registry, params)
        progress(
            f"{planner} {goal} weights {weights}: {cell.status} in {cell.seconds:.2f} s"
            + (f", {cell.delta_v:.3f} ft/s" if cell.status == "solved" else f" ({cell.reason})")
        )
        cells.append(cell)
    return cells


def _number(value: float | None, digits: int) -> str:
    if value is None:
        return "*"
    if isinstance(value, float) and not np.isfinite(value):
        return "–"
    return f"{value:,.{digits}f}" if digits else f"{int(value):,}"


def _find(cells: Sequence[Cell], planner: str, goal: str, weights: tuple[float, float]) -> Cell:
    return next(
        c for c in cells if c.planner == planner and c.goal == goal and c.weights == weights
    )


def tables(cells: Sequence[Cell]) -> str:
    """Tables 3 and 4 beside the paper's, planning times, and the multi-burn yardstick,
    as Markdown."""
    header = "| goal | " + " | ".join(f"({a:g}, {b:g})" for a, b in WEIGHTINGS) + " |"
    rule = "|---|" + "---|" * len(WEIGHTINGS)
    lines = [
        "Points searched, grid-astar (the paper's Table 3 in brackets; * unfinished in 6 h)",
        "",
        header,
        rule,
    ]
    for row, goal in enumerate(GOALS):
        entries = []
        for column, weights in enumerate(WEIGHTINGS):
            cell = _find(cells, "grid-astar", goal, weights)
            ours = _number(cell.points, 0) if cell.status == "solved" else cell.status
            entries.append(f"{ours} ({_number(PAPER_POINTS[row][column], 0)})")
        lines.append(f"| {goal} | " + " | ".join(entries) + " |")
    lines += [
        "",
        "Total delta-v, ft/s, grid-astar (the paper's Table 4 in brackets)",
        "",
        header,
        rule,
    ]
    for row, goal in enumerate(GOALS):
        entries = []
        for column, weights in enumerate(WEIGHTINGS):
            cell = _find(cells, "grid-astar", goal, weights)
            ours = _number(cell.delta_v, 3) + (" collides" if cell.collides else "")
            entries.append(f"{ours} ({_number(PAPER_DELTA_V[row][column], 3)})")
        lines.append(f"| {goal} | " + " | ".join(entries) + " |")
    lines += ["", "Planning time, s, grid-astar", "", header, rule]
    for goal in GOALS:
        times = [_find(cells, "grid-astar", goal, w).seconds for w in WEIGHTINGS]
        lines.append(f"| {goal} | " + " | ".join(f"{t:.2f}" for t in times) + " |")
    lines += [
        "",
        "multi-burn (delta-v alone) against grid-astar's cheapest cell",
        "",
        "| goal | multi-burn delta-v, ft/s | burns | time, s | grid-astar best, ft/s | ratio |",
        "|---|---|---|---|---|---|",
    ]
    for goal in GOALS:
        multi = _find(cells, "multi-burn", goal, (1.0, 0.0))
        best = min(_find(cells, "grid-astar", goal, w).delta_v for w in WEIGHTINGS)
        burns = (
            multi.trajectory.statistics.get("burns", float("nan"))
            if multi.trajectory
            else float("nan")
        )
        ratio = best / multi.delta_v if multi.status == "solved" else float("nan")
        lines.append(
            f"| {goal} | {_number(multi.delta_v, 3)} | {_number(burns, 0)} | {multi.seconds:.2f} "
            f"| {_number(best, 3)} | {_number(ratio, 2)} |"
        )
    lines.append("")
    lines.append(f"The paper's three-burn path to the third goal: {PAPER_THREE_BURN} ft/s.")
    flown = [(c, c.flight) for c in cells if c.flight is not None]
    if flown:
        lines += [
            "",
            "Flown through the transfer mission",
            "",
            "| planner | goal | weights | reached | collisions "
            "| planned / flown delta-v, ft/s | flown − planned |",
            "|---|---|---|---|---|---|---|",
        ]
        for c, flight in flown:
            flown_dv = flight.delta_v / FOOT
            lines.append(
                f"| {c.planner} | {c.goal} | ({c.weights[0]:g}, {c.weights[1]:g}) | "
                f"{'yes' if flight.reached else 'no'} | {flight.collisions} | "
                f"{c.delta_v:.3f} / {flown_dv:.3f} | {100 * (flown_dv / c.delta_v - 1):+.1f} % |"
            )
    return "\n".join(lines)
