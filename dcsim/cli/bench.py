"""``dcsim bench``: measure dcsim and its plugins against references.

Every bench prints its results as Markdown for docs/benchmarks.md on stdout and its
progress on stderr. Plugin packages add their own benches (``dcsim bench ant-colony``)
through the ``dcsim_register_commands`` hook (:mod:`dcsim.cli.plugin_commands`).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import click

from dcsim.bench.options import comma_numbers, comma_words
from dcsim.cli.common import plugin_registry, progress
from dcsim.cli.options import (
    cluster_choice,
    cluster_options,
    count_option,
    duration_option,
    fly_option,
    out_dir_option,
    overrides_option,
    plot_option,
    positive_option,
    scenario_argument,
)
from dcsim.cli.plugin_commands import PluginGroup
from dcsim.registry.discovery import PluginRegistry
from dcsim.run.directory import prepare_run_directory
from dcsim.run.setup import setup_run
from dcsim.scenario import read_scenario

if TYPE_CHECKING:  # the bench modules are imported by their commands only
    from dcsim.bench.path_planners import PlannerChoice, ProblemResult


@click.group(
    "bench", cls=PluginGroup, short_help="Measure dcsim and its plugins against references."
)
def bench_group() -> None:
    """Measure dcsim and its plugins; results go into docs/benchmarks.md."""


@bench_group.command(
    "world", short_help="Closed-loop wall time per simulated second against PyBullet."
)
@click.option(
    "--objects",
    default="10,100,1000",
    show_default=True,
    help="Comma-separated field sizes (targets and obstacles in all), each >= 0.",
)
@duration_option(60.0)
def bench_world_command(objects: str, duration: float) -> None:
    """Closed-loop wall time per simulated second against PyBullet stepping alone.

    For each field size, one synthetic LVLH scenario is stepped bare (stepSimulation
    only) and flown by the full runner; the closed loop is split by phase of the run
    loop. Then the default scenario is flown once for its real-time factor. Prints a
    Markdown table for docs/benchmarks.md, and the floor under the default scenario's
    real-time factor: stepping, the per-step force calls and the localiser plugin alone.
    """
    from dcsim.bench.world import bench_world, floor_line, loop_floor, markdown_table
    from dcsim.run.loop import Runner

    words = [word.strip() for word in objects.split(",")]
    if not all(word.isdigit() for word in words):
        raise click.BadParameter(
            f"expected integers >= 0 like 10,100,1000, got {objects!r}", param_hint="--objects"
        )
    sizes = [int(word) for word in words]
    rows = bench_world(sizes, duration, progress=progress)
    click.echo(markdown_table(rows))
    registry = plugin_registry()
    summary = Runner(setup_run(registry=registry)).run()
    click.echo(
        f"\ndefault scenario: {summary['status']} ({summary['reason']}), "
        f"{summary['sim_time_s']:.1f} s simulated in {summary['wall_time_s']:.2f} s, "
        f"real-time factor {summary['real_time_factor']:.0f}"
    )
    click.echo(floor_line(loop_floor(summary["sim_time_s"], summary["wall_time_s"], registry)))


@bench_group.command("soak", short_help="A long run's memory and time per tick; FMU lifetimes.")
@count_option("--ticks", 1_000_000, "Control ticks to fly.", minimum=100)
@count_option("--samples", 100, "Memory and speed samples, evenly spaced.", minimum=10)
@count_option(
    "--fmu-cycles",
    200,
    "FMU instantiate/step/terminate/free cycles after the run (0: none).",
    minimum=0,
)
@out_dir_option("Run directory for the soak run's records (default: a temporary one).")
@plot_option("Write memory and time per tick against ticks as a PNG.")
def bench_soak_command(
    ticks: int, samples: int, fmu_cycles: int, out: Path | None, plot_path: Path | None
) -> None:
    """A long run's resident memory and time per tick, and repeated FMU lifetimes.

    Flies the default scenario for TICKS control ticks with its records streamed to
    disk, sampling resident memory and wall time per tick; then runs FMU-CYCLES
    lifetimes of the closed-loop FMU in the same process. Prints Markdown for
    docs/benchmarks.md.
    """
    import tempfile

    from dcsim.bench import soak

    with tempfile.TemporaryDirectory(prefix="dcsim-soak-run-") as tmp:
        run_dir = prepare_run_directory(out or Path(tmp) / "run", force=False)
        result = soak.soak(ticks, samples, run_dir, progress)
    click.echo(soak.markdown_table(result))
    if plot_path is not None:
        soak.plot(result, plot_path)
        click.echo(f"\nplot: {plot_path}")
    if fmu_cycles:
        memory = soak.fmu_cycles(fmu_cycles, progress)
        early = memory[min(len(memory), 20) - 1]
        click.echo(
            f"\nFMU: {fmu_cycles} cycles, resident memory {early / 2**20:.1f} MB after cycle "
            f"{min(len(memory), 20)}, {memory[-1] / 2**20:.1f} MB after the last "
            f"({100 * (memory[-1] - early) / early:+.1f} %)"
        )


@bench_group.command(
    "localisers", short_help="Localisers' RMSE against the Cramér–Rao bound; latency."
)
@count_option("--runs", 10, "Monte Carlo runs.")
@count_option("--steps", 400, "Updates per run (0.5 s each).", minimum=10)
@positive_option("--sigma", 1.0, "Range noise, m.")
@positive_option(
    "--acceleration-sigma",
    0.005,
    "Thrust noise of the manoeuvring collector, m/s^2 (the filters are told).",
)
@plot_option("Save the RMSE-over-time plot here.")
def bench_localisers_command(
    runs: int, steps: int, sigma: float, acceleration_sigma: float, plot_path: Path | None
) -> None:
    """Localisers' RMSE against the posterior Cramér–Rao bound, and their update latency.

    Every localiser (trilateration, ekf, ukf, sspf with 1k, 10k and 100k particles; the
    last on two runs only) flies the same runs of a manoeuvring collector ranging to the
    three nearest of eight beacons. Prints a Markdown table for docs/benchmarks.md.
    """
    from dcsim.bench.localisers import bench_localisers, markdown_table, plot

    bound, results = bench_localisers(runs, steps, sigma, acceleration_sigma, progress=progress)
    click.echo(markdown_table(bound, results))
    if plot_path is not None:
        plot(bound, results, plot_path)
        click.echo(f"plot: {plot_path}")


@bench_group.command(
    "task-planners", short_help="ga's time strategies; task planners' gaps to the optimum."
)
@count_option("--instances", 100, "Random instances per problem size (both studies).")
@count_option(
    "--moving-instances",
    50,
    "Instances per size for the gap to the grid optimum with moving targets.",
    minimum=0,
)
@count_option(
    "--repeats", 10, "Runs with different seeds per instance for the dispersion.", minimum=2
)
@count_option("--dispersion-instances", 5, "Instances whose dispersion is measured.")
@positive_option("--grid-step", 10.0, "Time grid of the moving-target optimum, s.")
@click.option(
    "--plots",
    "plot_dir",
    type=click.Path(file_okay=False, path_type=Path),
    help="Save task_planner_strategies.png and task_planner_gaps.png here.",
)
def bench_task_planners_command(
    instances: int,
    moving_instances: int,
    repeats: int,
    dispersion_instances: int,
    grid_step: float,
    plot_dir: Path | None,
) -> None:
    """The ga planner's time strategies (thesis ch. 3) and task planners' gaps to the optimum.

    Time strategies: 5, 10 and 15 moving targets. Gaps: stationary targets with 5, 7, 9
    and 11 (exact Held-Karp optimum), moving targets with 5 and 7 (optimum over a time
    grid of 2500 s). Prints Markdown tables for docs/benchmarks.md.
    """
    from dcsim.bench.task_planners import (
        compare_strategies,
        gap_table,
        optimality_gaps,
        plot_gaps,
        plot_strategies,
        strategy_table,
    )

    gaps = optimality_gaps(
        (5, 7, 9, 11), (5, 7), instances, moving_instances, grid_step, 2500.0, progress
    )
    click.echo(gap_table(gaps) + "\n")
    strategies = compare_strategies((5, 10, 15), instances, repeats, dispersion_instances, progress)
    click.echo(strategy_table(strategies, repeats))
    if plot_dir is not None:
        plot_dir.mkdir(parents=True, exist_ok=True)
        plot_gaps(gaps, plot_dir / "task_planner_gaps.png")
        plot_strategies(strategies, plot_dir / "task_planner_strategies.png")
        click.echo(f"plots: {plot_dir}")


@bench_group.command(
    "controllers", short_help="Controllers across crowded fields of drifting obstacles."
)
@count_option("--seeds", 50, "Fields (and world seeds) flown by every controller.")
@count_option(
    "--first-seed", 0, "Seed of the first field (seeds FIRST to FIRST + N - 1).", minimum=0
)
@click.option(
    "--controllers",
    default="elastic,pd",
    show_default=True,
    help="Comma-separated controller plugins (default parameters).",
)
@cluster_options
@overrides_option("Override a value of the crowded-field scenario, as for dcsim run. Repeatable.")
@plot_option("Save the distribution of the closest approach here.")
def bench_controllers_command(
    seeds: int,
    first_seed: int,
    controllers: str,
    scheduler: str | None,
    connect_timeout: float | None,
    workers: int | None,
    worker_deaths: int,
    overrides: tuple[str, ...],
    plot_path: Path | None,
) -> None:
    """Controllers crossing scenarios/crowded_field.yaml, a fresh field of 60 obstacles per seed.

    Reports per controller the runs with a collision, the closest approach to any
    obstacle, delta-v and mission time as a Markdown table for docs/benchmarks.md.
    The runs are campaign cases on Dask (a local cluster unless --scheduler).
    """
    from dcsim.bench.controllers import bench_controllers, markdown_table, plot
    from dcsim.scenario import packaged_scenario_path

    scenario = packaged_scenario_path("crowded_field.yaml")
    names = comma_words(controllers, "--controllers")
    registry = PluginRegistry.discover()
    for name in names:  # unknown controllers and bad overrides fail here, before any run
        chosen = [f"controller.plugin={name}", "controller.params={}", *overrides]
        safety = _safety_distance(scenario, chosen, registry)
    runs = bench_controllers(
        scenario,
        names,
        range(first_seed, first_seed + seeds),
        overrides,
        cluster_choice(scheduler, workers, worker_deaths, connect_timeout),
        progress=progress,
    )
    click.echo(markdown_table(runs))
    if plot_path is not None:
        plot(runs, safety, plot_path)
        click.echo(f"plot: {plot_path}")


def _safety_distance(scenario: Path, overrides: list[str], registry: PluginRegistry) -> float:
    """The debris mission's safety distance of ``scenario`` with ``overrides``, m.

    Raises
    ------
    click.BadParameter
        When the overrides chose another mission type.
    """
    from dcsim.missions.debris.settings import DebrisMissionSection

    mission = read_scenario(scenario, overrides, registry).mission
    if not isinstance(mission, DebrisMissionSection):
        raise click.BadParameter(
            f"the controller bench flies the debris mission, not mission.type {mission.type!r}",
            param_hint="--set",
        )
    return mission.safety_distance


@bench_group.command(
    "campaign", short_help="The campaign engine's overhead and speed-up per worker."
)
@click.argument(
    "campaign",
    required=False,
    type=click.Path(dir_okay=False, exists=True, path_type=Path),
)
@count_option("--cases", 40, "Cases run.")
@click.option(
    "--workers",
    default="1,2",
    show_default=True,
    help="Comma-separated local cluster sizes (1 is always run: the reference).",
)
@positive_option("--duration", 300.0, "world.duration of every case, s.")
@out_dir_option("Folder for the run directories. Default: a temporary folder, removed after.")
def bench_campaign_command(
    campaign: Path | None, cases: int, workers: str, duration: float, out: Path | None
) -> None:
    """The campaign engine against direct runs: overhead per case and speed-up per worker.

    CAMPAIGN defaults to scenarios/campaigns/default_dispersed.yaml of this checkout.
    """
    import tempfile

    from dcsim.bench.campaign import bench_campaign, markdown_table

    if campaign is None:
        campaign = (
            Path(__file__).resolve().parents[2] / "scenarios/campaigns/default_dispersed.yaml"
        )
        if not campaign.exists():
            raise click.BadParameter("name a campaign file", param_hint="CAMPAIGN")
    counts = [int(n) for n in comma_numbers(workers, "--workers") if n >= 1]
    with tempfile.TemporaryDirectory() as scratch:
        folder = out if out is not None else Path(scratch)
        bench = bench_campaign(campaign, folder, cases, counts, duration, progress)
    click.echo(markdown_table(bench))


@bench_group.command("fmu", short_help="The closed-loop FMU in fmpy against dcsim run, per tick.")
@scenario_argument(required=False)
@duration_option(300.0)
@count_option("--repeats", 3, "Measurements.")
def bench_fmu_command(scenario: Path | None, duration: float, repeats: int) -> None:
    """Closed-loop FMU in fmpy against dcsim run: wall time per control tick.

    SCENARIO (default: the packaged one) is exported as a closed-loop FMU and flown
    natively and through the FMU, alternately, REPEATS times each. Prints a Markdown
    table for docs/benchmarks.md.
    """
    from dcsim.bench.fmu import bench_fmu, markdown_table

    result = bench_fmu(scenario, duration, repeats, progress=progress)
    click.echo(markdown_table(result))


@bench_group.command("peers", short_help="dcsim's attitude loop beside Basilisk's.")
@click.option(
    "--duration",
    type=click.FloatRange(min=1.0, max=86_400.0),
    default=600.0,
    show_default=True,
    help="Simulated seconds per run (whole control periods of 0.1 s).",
)
@count_option("--repeats", 3, "Timed runs per side.")
@click.option(
    "--basilisk-step",
    type=click.FloatRange(min=1e-4, max=0.1),
    default=None,
    help="Basilisk's dynamics step, s; it must divide the 0.1 s control period "
    "(default: dcsim's physics step, 0.01 s).",
)
@plot_option("Write the pointing error (and the position hold) against time as a PNG.")
def bench_peers_command(
    duration: float, repeats: int, basilisk_step: float | None, plot_path: Path | None
) -> None:
    """dcsim's attitude loop beside Basilisk's: the same slew, gains and rates.

    A rigid free flyer slews 90° to a fixed inertial attitude under a PD law at 10 Hz,
    truth-fed, once with translation free and once holding its position; dcsim (the
    hold mission, pd, PyBullet) and Basilisk (spacecraft hub, extForceTorque, simpleNav,
    inertial3D, attTrackingError, mrpFeedback, hillFrameRelativeControl) fly it
    alternately, REPEATS times each. Prints a Markdown table for docs/benchmarks.md.
    Basilisk is optional (pip install 'dcsim[peers]'); without it the dcsim side runs
    alone.
    """
    from dcsim.bench import peers

    if basilisk_step is not None:
        periods = peers.SlewCase().control_period / basilisk_step
        if abs(periods - round(periods)) > 1e-9:
            raise click.BadParameter(
                f"{basilisk_step:g} s does not divide the 0.1 s control period",
                param_hint="'--basilisk-step'",
            )
    result = peers.bench_peers(duration, repeats, basilisk_step, progress=progress)
    click.echo(peers.markdown_table(result))
    click.echo()
    click.echo(peers.notes(result))
    click.echo()
    click.echo(peers.verdict(result))
    if plot_path is not None:
        peers.plot(result, plot_path)
        click.echo(f"\nplot: {plot_path}")


@bench_group.command(
    "manipulator", short_help="The manipulator model's time per call against Pinocchio."
)
@count_option("--states", 64, "Random states (fixed seed) each call is timed at.")
@count_option(
    "--repeats", 30, "Timing rounds over every call in turn; each call's best round counts."
)
@count_option("--number", 10, "Passes over the states per call and round.")
@click.option(
    "--scenario",
    type=click.Path(exists=True, dir_okay=False, path_type=Path),
    help="Also run this scenario once and report its real-time factor.",
)
def bench_manipulator_command(
    states: int, repeats: int, number: int, scenario: Path | None
) -> None:
    """The manipulator model's time per call against PyBullet's and Pinocchio's.

    Forward kinematics, the end effector's Jacobian, M, C and C q̇ of the thesis's robot,
    timed with timeit (best of REPEATS rounds) at STATES random states, for dcsim, PyBullet and
    Pinocchio (if installed), with dcsim's ratio to Pinocchio and whether M + C is
    within 10× of Pinocchio's. Prints a Markdown table for docs/benchmarks.md.
    """
    from dcsim.bench import manipulator as bench

    result = bench.bench_manipulator(states, repeats, number, progress=progress)
    click.echo(bench.markdown_table(result))
    click.echo(f"\n{bench.agreement_line(result)}")
    if scenario is not None:
        speed = bench.scenario_speed(scenario, registry=plugin_registry())
        click.echo(f"\n{bench.scenario_line(speed)}")


@bench_group.command(
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


@bench_group.command(
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
