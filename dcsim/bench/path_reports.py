"""What ``dcsim bench path-planners`` writes: OMPL benchmark logs, the database, a table, box plots.

One benchmark log per problem (an OMPL experiment), with one block per planner; its
per-run properties use OMPL's names where the meaning is the same:

=========================  =========  ==================================================
property                   type       meaning
=========================  =========  ==================================================
seed                       INTEGER    world seed of the run
time                       REAL       wall time of the plan call, s
memory                     REAL       peak Python memory of the plan call, MB
status                     ENUM       solved, no path, error, timeout
solved                     BOOLEAN    the trajectory ends in the goal region (exact)
approximate solution       BOOLEAN    a trajectory that does not
correct solution           BOOLEAN    the swept check finds no overlap
solution length            REAL       m, as the planner reports it
solution duration          REAL       s
solution delta v           REAL       m/s
solution clearance         REAL       least gap to an obstacle (swept check), m
planner NAME               REAL       each statistic of ``Trajectory.statistics``
flown reached ... (--fly)  ...        flown arrival, delta-v, tracking error, collisions
=========================  =========  ==================================================

OMPL counts an approximate solution as solved; here ``solved`` is the exact arrival.
"""

from __future__ import annotations

import math
import os
import platform
import re
import socket
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from dcsim import __version__
from dcsim.bench.figures import pyplot, save
from dcsim.bench.ompl_log import Experiment, PlannerBlock, Value, benchmark_log
from dcsim.bench.path_planners import (
    STATUSES,
    PlannerChoice,
    PlanRun,
    ProblemResult,
    planner_choice,
)
from dcsim.messages import PathProblem
from dcsim.registry.discovery import RegisteredPlugin

_RUN_PROPERTIES = (
    ("seed", "INTEGER"),
    ("time", "REAL"),
    ("memory", "REAL"),
    ("status", "ENUM"),
    ("solved", "BOOLEAN"),
    ("approximate solution", "BOOLEAN"),
    ("correct solution", "BOOLEAN"),
    ("solution length", "REAL"),
    ("solution duration", "REAL"),
    ("solution delta v", "REAL"),
    ("solution clearance", "REAL"),
)
_FLIGHT_PROPERTIES = (
    ("flown reached", "BOOLEAN"),
    ("flown delta v", "REAL"),
    ("flown max tracking error", "REAL"),
    ("flown collisions", "INTEGER"),
)


def _run_values(run: PlanRun) -> list[Value]:
    """The run's row (NaN, no trajectory's figures, is written "nan": NULL in the database)."""
    return [
        run.seed,
        run.time,
        run.peak_memory / 2**20,
        STATUSES.index(run.status),
        run.exact,
        run.approximate,
        None if run.collides is None else not run.collides,
        run.length,
        run.duration,
        run.delta_v,
        run.clearance,
    ]


def _flight_values(run: PlanRun) -> list[Value]:
    flight = run.flight
    if flight is None:
        return [None] * len(_FLIGHT_PROPERTIES)
    return [flight.reached, flight.delta_v, flight.max_tracking_error, flight.collisions]


def statistic_property(name: str) -> str:
    """The log property of a planner statistic: ``planner`` and its words (a safe column)."""
    return "planner " + " ".join(re.findall(r"[0-9A-Za-z]+", name))


def planner_block(
    entry: RegisteredPlugin | PlannerChoice, runs: Sequence[PlanRun], flights: bool
) -> PlannerBlock:
    """One planner's runs on one problem as a block of the log."""
    statistics = sorted({name for run in runs for name in run.statistics})
    properties = [*_RUN_PROPERTIES, *((statistic_property(n), "REAL") for n in statistics)]
    if flights:
        properties += _FLIGHT_PROPERTIES
    rows = []
    for run in runs:
        row = _run_values(run) + [run.statistics.get(name) for name in statistics]
        rows.append(row + _flight_values(run) if flights else row)
    settings = {
        "distribution": f"{entry.origin.distribution} {entry.origin.version}",
        **{name: str(value) for name, value in planner_choice(entry).settings().items()},
    }
    return PlannerBlock(entry.name, settings, properties, rows)


def describe(problem: PathProblem) -> str:
    """The path problem in words and numbers (the experiment's setup), SI units."""
    shapes: dict[str, int] = {}
    for obstacle in problem.obstacles:
        shapes[str(obstacle.shape.kind)] = shapes.get(str(obstacle.shape.kind), 0) + 1
    start, goal = problem.start, problem.goal
    bounds = (
        "none" if problem.bounds is None else f"{problem.bounds.lower} to {problem.bounds.upper}"
    )
    return "\n".join(
        [
            f"frame: {problem.frame.kind} (mean motion {problem.frame.mean_motion:g} rad/s)",
            f"start: t = {start.time:g} s, position {start.position} m, "
            f"velocity {start.velocity} m/s",
            f"goal: {goal!r}",
            f"obstacles: {len(problem.obstacles)} {shapes}",
            f"robot radius {problem.robot_radius:g} m, max speed {problem.max_speed:g} m/s, "
            f"max acceleration {problem.max_acceleration:g} m/s^2, "
            f"max delta-v {problem.max_delta_v:g} m/s",
            f"bounds: {bounds}",
            f"time budget {problem.time_budget:g} s",
        ]
    )


def _machine() -> str:
    return "\n".join(
        [
            platform.platform(),
            f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores",
            f"Python {platform.python_version()}, numpy {np.__version__}",
        ]
    )


def experiment(
    result: ProblemResult,
    planners: Sequence[RegisteredPlugin | PlannerChoice],
    runs: int,
    flights: bool,
) -> Experiment:
    """One problem's runs as an OMPL experiment."""
    problem = result.problem.problem
    blocks = [
        planner_block(entry, [r for r in result.runs if r.planner == entry.name], flights)
        for entry in map(planner_choice, planners)
    ]
    return Experiment(
        name=result.problem.name,
        library="dcsim",
        version=__version__,
        properties={
            "obstacles": ("INTEGER", len(problem.obstacles)),
            "robotradius": ("REAL", problem.robot_radius),
        },
        host=socket.gethostname() or "unknown",
        date=result.started,
        setup=f"{result.problem.document.filename}\n{describe(problem)}",
        cpuinfo=_machine(),
        seed=0,
        time_limit=problem.time_budget,
        memory_limit=0.0,
        runs_per_planner=runs,
        total_time=result.total_time,
        enums={"status": STATUSES},
        planners=blocks,
    )


def log_path(base: Path, problem: str) -> Path:
    """Where the log of ``problem`` goes: ``base``'s stem, the problem, ``base``'s suffix."""
    return base.with_name(f"{base.stem}.{problem}{base.suffix or '.log'}")


# --------------------------------------------------------------------- table and plot


def _median(values: Sequence[float], scale: float = 1.0, digits: int = 2) -> str:
    finite = [v for v in values if math.isfinite(v)]
    return f"{scale * float(np.median(finite)):.{digits}f}" if finite else "–"


def _failures(runs: Sequence[PlanRun]) -> str:
    counts = {status: sum(r.status == status for r in runs) for status in STATUSES[1:]}
    return ", ".join(f"{n} {status}" for status, n in counts.items() if n) or "–"


def markdown_table(results: Sequence[ProblemResult], flights: bool) -> str:
    """Per problem and planner: success rate, other outcomes and medians over trajectories."""
    header = (
        "| problem | planner | runs | success | not solved | time median [ms] "
        "| length median [m] | delta-v median [m/s] | clearance median [m] |"
    )
    rule = "|---|---|---:|---:|---|---:|---:|---:|---:|"
    if flights:
        header += " flown delta-v median [m/s] | tracking error median [m] | collisions | reached |"
        rule += "---:|---:|---:|---:|"
    lines = [header, rule]
    for result in results:
        for planner in dict.fromkeys(r.planner for r in result.runs):
            runs = [r for r in result.runs if r.planner == planner]
            solved = [r for r in runs if r.status == "solved"]
            line = (
                f"| {result.problem.name} | {planner} | {len(runs)} "
                f"| {sum(r.success for r in runs) / len(runs):.0%} | {_failures(runs)} "
                f"| {_median([r.time for r in runs], 1e3)} "
                f"| {_median([r.length for r in solved])} "
                f"| {_median([r.delta_v for r in solved])} "
                f"| {_median([r.clearance for r in solved])} |"
            )
            if flights:
                line += _flight_cells([r.flight for r in solved if r.flight is not None])
            lines.append(line)
    return "\n".join(lines)


def _family(name: str) -> str:
    """A problem's family: its name without a trailing ``-SEED``."""
    return re.sub(r"-\d+$", "", name)


def _percentile(values: Sequence[float], q: float, scale: float = 1.0) -> str:
    finite = [v for v in values if math.isfinite(v)]
    return f"{scale * float(np.percentile(finite, q)):.1f}" if finite else "–"


def family_table(results: Sequence[ProblemResult], flights: bool) -> str:
    """Per problem family and planner, over all its problems and runs: success count,
    planning time (median, 95th percentile), the statistics ``nodes_added`` and
    ``iterations`` (medians, where the planner reports them), and the trajectory's
    duration and delta-v (medians over successes); with flights, how many reached the
    goal and how many collided."""
    header = (
        "| family | planner | runs | success | time median [ms] | time p95 [ms] "
        "| nodes added median | iterations median | duration median [s] "
        "| delta-v median [m/s] |"
    )
    rule = "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"
    if flights:
        header += " flown to the goal | flights with a collision |"
        rule += "---:|---:|"
    groups: dict[tuple[str, str], list[PlanRun]] = {}
    for result in results:
        for run in result.runs:
            groups.setdefault((_family(result.problem.name), run.planner), []).append(run)
    lines = [header, rule]
    for (family, planner), runs in groups.items():
        won = [r for r in runs if r.success]
        line = (
            f"| {family} | {planner} | {len(runs)} | {len(won)} "
            f"| {_median([r.time for r in runs], 1e3, 1)} "
            f"| {_percentile([r.time for r in runs], 95, 1e3)} "
            f"| {_median([r.statistics.get('nodes_added', math.nan) for r in runs], digits=0)} "
            f"| {_median([r.statistics.get('iterations', math.nan) for r in runs], digits=0)} "
            f"| {_median([r.duration for r in won], digits=1)} "
            f"| {_median([r.delta_v for r in won])} |"
        )
        if flights:
            flown = [r.flight for r in runs if r.flight is not None]
            reached = sum(f.reached and not f.collisions for f in flown)
            line += f" {reached} / {len(flown)} | {sum(f.collisions > 0 for f in flown)} |"
        lines.append(line)
    return "\n".join(lines)


def _flight_cells(flights: list) -> str:
    if not flights:
        return " – | – | – | – |"
    return (
        f" {_median([f.delta_v for f in flights])} "
        f"| {_median([f.max_tracking_error for f in flights])} "
        f"| {sum(f.collisions for f in flights)} "
        f"| {sum(f.reached for f in flights)} / {len(flights)} |"
    )


def plot(results: Sequence[ProblemResult], path: Path) -> None:
    """Box plots of planning time, delta-v and length per problem and planner (PNG)."""
    plt = pyplot()
    groups = [
        (result.problem.name, planner, [r for r in result.runs if r.planner == planner])
        for result in results
        for planner in dict.fromkeys(r.planner for r in result.runs)
    ]
    panels = [
        ("planning time [ms]", lambda r: 1e3 * r.time),
        ("delta-v [m/s]", lambda r: r.delta_v),
        ("length [m]", lambda r: r.length),
    ]
    figure, axes = plt.subplots(len(panels), 1, figsize=(max(8, 1.6 * len(groups)), 9))
    labels = [f"{problem}\n{planner}" for problem, planner, _ in groups]
    for axis, (title, value) in zip(axes, panels, strict=True):
        data = [[v for v in map(value, runs) if math.isfinite(v)] for _, _, runs in groups]
        axis.boxplot(data)
        axis.set_xticks(np.arange(1, len(labels) + 1), labels, fontsize=8)
        axis.set_ylabel(title)
        axis.grid(alpha=0.3, axis="y")
    axes[0].set_title(
        "Path planners per problem: time of every run; delta-v, length of trajectories"
    )
    save(figure, path)


def write_logs(
    results: Sequence[ProblemResult],
    planners: Sequence[RegisteredPlugin | PlannerChoice],
    runs: int,
    flights: bool,
    base: Path,
) -> list[Path]:
    """One OMPL benchmark log per problem beside ``base`` (:func:`log_path`); their paths."""
    base.parent.mkdir(parents=True, exist_ok=True)
    paths = []
    for result in results:
        path = log_path(base, result.problem.name)
        path.write_text(benchmark_log(experiment(result, planners, runs, flights)))
        paths.append(path)
    return paths
