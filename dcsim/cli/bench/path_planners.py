"""Benches of the path planners: the Boeing paper's tables (``grid-search``) and every
planner side by side (``path-planners``)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import click

from dcsim.bench.options import comma_words
from dcsim.cli.common import plugin_registry, progress
from dcsim.cli.options import (
    count_option,
    fly_option,
    plot_option,
    positive_option,
)

if TYPE_CHECKING:  # the bench modules are imported by their commands only
    from dcsim.bench.path_planners import PlannerChoice, ProblemResult


@click.command(
    "grid-search", short_help="The Boeing paper's Tables 3-4: grid-astar and multi-burn."
)
@click.option(
    "--scenario",
    type=click.Path(exists=True, dir_okay=False, path_type=Path),
    default=Path("scenarios/station_inspection.yaml"),
    show_default=True,
    help="The station scenario the paper's three goals are posed in.",
)
@positive_option("--budget", 60.0, "Planning budget of every cell, s.")
@click.option(
    "--grid",
    "grid_params",
    default=None,
    help="grid-astar's parameters as key=value:key=value (default: its defaults).",
)
@fly_option("Also fly every plan through the transfer mission.")
def bench_grid_search_command(
    scenario: Path, budget: float, grid_params: str | None, fly: bool
) -> None:
    """The Boeing paper's Tables 3 and 4 regenerated: grid-astar on three goals under five
    weightings of delta-v and distance, beside the paper's figures, and multi-burn's
    delta-v per goal. Prints Markdown tables for docs/benchmarks.md.
    """
    from dcsim.bench.grid_search import bench_grid_search, tables
    from dcsim.bench.path_planners import planner_spec

    registry = plugin_registry()
    params = None
    if grid_params:
        params = dict(planner_spec(registry, f"grid-astar:{grid_params}").params)
    cells = bench_grid_search(registry, scenario, budget, fly, progress, params)
    click.echo(tables(cells))


@click.command(
    "path-planners", short_help="Path planners side by side on seeded fields and scenarios."
)
@click.option(
    "--planners",
    default=None,
    help="Comma-separated path planners (default: every registered one), each with its "
    "default parameters or some set as NAME:key=value:key=value.",
)
@click.option(
    "--problems",
    default="static-spheres,cw-spheres,shapes",
    show_default=True,
    help="Comma-separated problems: a family (static-spheres, cw-spheres, shapes, "
    "asteroid-escape) with an optional :SEED (default 0) or :FIRST..LAST seeds, or the path "
    "of a transfer scenario file.",
)
@count_option("--runs", 10, "Runs of every planner on every problem (world seeds 0 to N - 1).")
@click.option(
    "--db",
    "database",
    type=click.Path(dir_okay=False, path_type=Path),
    help="Write the SQLite database OMPL's parser makes of the logs (Planner Arena opens "
    "it); replaced if it exists. Needs dcsim[bench].",
)
@click.option(
    "--log",
    "log",
    type=click.Path(dir_okay=False, path_type=Path),
    help="Write OMPL benchmark logs, one per problem: FILE's stem, the problem, FILE's suffix "
    "(--log out/bench.log writes out/bench.static-spheres-0.log, ...).",
)
@fly_option("Also fly every run that gave a trajectory through the transfer mission.")
@plot_option("Save box plots of planning time, delta-v and length per problem and planner.")
@click.option(
    "--memory/--no-memory",
    default=True,
    show_default=True,
    help="Trace a second plan call of every run for its peak Python memory (it takes "
    "several times as long as the timed call).",
)
def bench_path_planners_command(
    planners: str | None,
    problems: str,
    runs: int,
    database: Path | None,
    log: Path | None,
    fly: bool,
    plot_path: Path | None,
    memory: bool,
) -> None:
    """Path planners side by side on seeded random fields and transfer scenarios.

    Every planner plans every problem RUNS times, each run in a fresh process with its own
    seed; the trajectory is judged by the goal region's tolerances and an independent
    swept clearance check. Prints a Markdown table for docs/benchmarks.md; writes OMPL
    benchmark logs and their Planner Arena database on request.
    """
    from dcsim.bench import path_reports
    from dcsim.bench.ompl_log import benchmark_parser
    from dcsim.bench.path_planners import bench_path_planners, select_planners
    from dcsim.bench.path_problems import expand_specs, load_problem

    if database is not None:
        benchmark_parser()  # refuse before the runs, not after them
    registry = plugin_registry()
    chosen = select_planners(registry, _names(planners, "--planners"))
    specs = expand_specs(_names(problems, "--problems") or [])
    bench_problems = [load_problem(spec) for spec in specs]
    names = [p.name for p in bench_problems]
    if len(set(names)) < len(names):
        raise click.BadParameter(f"two problems have one name: {names}", param_hint="--problems")
    results = bench_path_planners(
        bench_problems,
        chosen,
        runs,
        fly,
        registry,
        progress,
        memory,
    )
    click.echo(path_reports.markdown_table(results, fly))
    click.echo("")
    click.echo(path_reports.family_table(results, fly))
    if log is not None or database is not None:
        _write_records(results, chosen, runs, fly, log, database)
    if plot_path is not None:
        path_reports.plot(results, plot_path)
        click.echo(f"plot: {plot_path}")


def _write_records(
    results: Sequence[ProblemResult],
    planners: Sequence[PlannerChoice],
    runs: int,
    fly: bool,
    log: Path | None,
    database: Path | None,
) -> None:
    """The path-planner bench's OMPL logs (in a temporary folder without ``log``) and database."""
    import tempfile

    from dcsim.bench.ompl_log import write_database
    from dcsim.bench.path_reports import write_logs

    click.echo("")
    with tempfile.TemporaryDirectory(prefix="dcsim-path-bench-") as tmp:
        logs = write_logs(results, planners, runs, fly, log or Path(tmp) / "path_planners.log")
        if log is not None:
            click.echo(f"logs: {', '.join(str(p) for p in logs)}")
        if database is not None:
            write_database(logs, database)
            click.echo(f"database: {database}")


def _names(text: str | None, option: str) -> list[str] | None:
    """The comma-separated names of an option (None when it is not given)."""
    return None if text is None else comma_words(text, option)
