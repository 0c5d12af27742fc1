"""Benches of the built-in localisers (``localisers``), task planners
(``task-planners``), controllers (``controllers``) and tracker (``tracking``) against
their references, and of the capture of a tumbling target over dispersed cases
(``capture``) against its targets."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from dcsim.bench.options import comma_words
from dcsim.cli.campaign import EXIT_INTERRUPTED
from dcsim.cli.common import checkout_campaign, progress
from dcsim.cli.options import (
    cluster_choice,
    cluster_options,
    count_option,
    out_dir_option,
    overrides_option,
    plot_option,
    positive_option,
)
from dcsim.registry.discovery import PluginRegistry
from dcsim.scenario import read_scenario


@click.command("localisers", short_help="Localisers' RMSE against the Cramér–Rao bound; latency.")
@count_option("--runs", 10, "Monte Carlo runs.")
@count_option("--steps", 400, "Updates per run (0.5 s each).", minimum=10)
@positive_option("--sigma", 1.0, "White range noise, m (the localisers are told).")
@positive_option(
    "--acceleration-sigma",
    0.005,
    "Thrust noise of the manoeuvring collector, m/s^2 (the filters are told).",
)
@click.option(
    "--ranges",
    default="white,biased,outliers",
    show_default=True,
    help="Range models flown: white noise; a 2-sigma bias; 5 % outliers of 20 sigma.",
)
@plot_option("Save the RMSE-over-time plot here (one panel per range model).")
def bench_localisers_command(
    runs: int,
    steps: int,
    sigma: float,
    acceleration_sigma: float,
    ranges: str,
    plot_path: Path | None,
) -> None:
    """Localisers' RMSE against the posterior Cramér–Rao bound, and their update latency.

    Every localiser (trilateration, ekf, ukf, sspf with 1k, 10k and 100k particles; the
    last on two runs only) flies the same runs of a manoeuvring collector ranging to the
    three nearest of eight beacons, under each range model the beacon-range sensor model
    gives: white noise, a constant bias of 2 sigma, 5 % outliers with an extra 20 sigma;
    each against its own bound. Prints a Markdown table for docs/benchmarks.md.
    """
    from dcsim.bench.localisers import bench_localisers, markdown_table, plot, range_cases

    cases = range_cases(comma_words(ranges, "--ranges"))
    flown = bench_localisers(runs, steps, sigma, acceleration_sigma, cases, progress=progress)
    click.echo(markdown_table(flown))
    if plot_path is not None:
        plot(flown, plot_path)
        click.echo(f"plot: {plot_path}")


@click.command(
    "task-planners",
    short_help="Task planners: optimality gaps, strategies, tracked targets.",
)
@click.option(
    "--studies",
    default="gaps,strategies,tracked",
    show_default=True,
    help="Comma-separated studies to run: gaps, strategies, tracked.",
)
@count_option("--instances", 100, "Random instances per problem size (gaps and strategies).")
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
@count_option(
    "--tracked-instances", 50, "Moving instances per size planned from the truth and from tracks."
)
@positive_option("--observation", 10.0, "Time the object sensor watches before planning, s.")
@click.option(
    "--plots",
    "plot_dir",
    type=click.Path(file_okay=False, path_type=Path),
    help="Save task_planner_strategies.png and task_planner_gaps.png here.",
)
def bench_task_planners_command(
    studies: str,
    instances: int,
    moving_instances: int,
    repeats: int,
    dispersion_instances: int,
    grid_step: float,
    tracked_instances: int,
    observation: float,
    plot_dir: Path | None,
) -> None:
    """The ga planner's time strategies (thesis ch. 3), task planners' gaps to the
    optimum, and their plans from tracked targets.

    Gaps: stationary targets with 5, 7, 9 and 11 (exact Held-Karp optimum), moving
    targets with 5 and 7 (optimum over a time grid of 2500 s). Time strategies: 5, 10
    and 15 moving targets. Tracked: 5 and 10 moving targets planned from their true
    motions and from the kalman tracker's tracks of the object sensor's detections
    (realistic profile) after --observation seconds, each plan flown against the truth.
    Prints Markdown tables for docs/benchmarks.md.
    """
    from dcsim.bench.task_planners import (
        compare_strategies,
        gap_table,
        optimality_gaps,
        plot_gaps,
        plot_strategies,
        strategy_table,
        tracked_table,
        tracked_targets,
    )

    chosen = comma_words(studies, "--studies")
    unknown = sorted(set(chosen) - {"gaps", "strategies", "tracked"})
    if unknown:
        raise click.BadParameter(
            f"{', '.join(unknown)}: choose among gaps, strategies, tracked", param_hint="--studies"
        )
    if plot_dir is not None:
        plot_dir.mkdir(parents=True, exist_ok=True)
    if "gaps" in chosen:
        gaps = optimality_gaps(
            (5, 7, 9, 11), (5, 7), instances, moving_instances, grid_step, 2500.0, progress
        )
        click.echo(gap_table(gaps) + "\n")
        if plot_dir is not None:
            plot_gaps(gaps, plot_dir / "task_planner_gaps.png")
    if "strategies" in chosen:
        strategies = compare_strategies(
            (5, 10, 15), instances, repeats, dispersion_instances, progress
        )
        click.echo(strategy_table(strategies, repeats) + "\n")
        if plot_dir is not None:
            plot_strategies(strategies, plot_dir / "task_planner_strategies.png")
    if "tracked" in chosen:
        tracked = tracked_targets((5, 10), tracked_instances, observation, progress)
        click.echo(tracked_table(tracked))
    if plot_dir is not None:
        click.echo(f"plots: {plot_dir}")


@click.command("controllers", short_help="Controllers across crowded fields of drifting obstacles.")
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
@click.option(
    "--sensors",
    default="ideal,realistic",
    show_default=True,
    help="Comma-separated sensing profiles (sensors.profile) every controller flies under.",
)
@cluster_options
@overrides_option("Override a value of the crowded-field scenario, as for dcsim run. Repeatable.")
@plot_option("Save the distribution of the closest approach here.")
def bench_controllers_command(
    seeds: int,
    first_seed: int,
    controllers: str,
    sensors: str,
    scheduler: str | None,
    connect_timeout: float | None,
    workers: int | None,
    worker_deaths: int,
    overrides: tuple[str, ...],
    plot_path: Path | None,
) -> None:
    """Controllers crossing scenarios/crowded_field.yaml, a fresh field of 60 obstacles per seed.

    Every controller flies every field under each sensing profile (ideal: exact tracks
    of the obstacles; realistic: the tracker's tracks from the object sensor). Reports
    per controller and profile the runs with a collision, the closest approach to any
    obstacle, delta-v and mission time as a Markdown table for docs/benchmarks.md.
    The runs are campaign cases on Dask (a local cluster unless --scheduler).
    """
    from dcsim.bench.controllers import bench_controllers, markdown_table, plot
    from dcsim.scenario import packaged_scenario_path

    scenario = packaged_scenario_path("crowded_field.yaml")
    names = comma_words(controllers, "--controllers")
    profiles = comma_words(sensors, "--sensors")
    registry = PluginRegistry.discover()
    for name in names:  # unknown names and bad overrides fail here, before any run
        for profile in profiles:
            chosen = [
                f"controller.plugin={name}",
                "controller.params={}",
                f"sensors.profile={profile}",
                *overrides,
            ]
            safety = _safety_distance(scenario, chosen, registry)
    runs = bench_controllers(
        scenario,
        names,
        range(first_seed, first_seed + seeds),
        overrides,
        cluster_choice(scheduler, workers, worker_deaths, connect_timeout),
        progress=progress,
        sensors=profiles,
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


@click.command("tracking", short_help="The tracker's tracks against the truth in the closed loop.")
@click.argument("scenarios", nargs=-1, type=click.Path(exists=True, dir_okay=False, path_type=Path))
@count_option("--seeds", 3, "World seeds flown per scenario.")
@count_option("--first-seed", 0, "Seed of the first run (seeds FIRST to FIRST + N - 1).", minimum=0)
@click.option(
    "--duration",
    type=click.FloatRange(min=0, min_open=True),
    help="Simulated seconds at most per run, s  [default: the scenario's world.duration]",
)
@overrides_option("Override a value of every scenario, as for dcsim run. Repeatable.")
def bench_tracking_command(
    scenarios: tuple[Path, ...],
    seeds: int,
    first_seed: int,
    duration: float | None,
    overrides: tuple[str, ...],
) -> None:
    """The tracker's consistency in the closed loop, under sensors.profile=realistic.

    Flies each SCENARIO (default: the packaged default.yaml and crowded_field.yaml) on
    every seed and compares, each control tick, every track of a free object the
    mission sees with the object's true state: the position and velocity NEES, the
    fraction of track-ticks inside the 3-sigma bound (chi-square, 3 dof, 0.9973) and
    the RMS errors. Prints a Markdown table for docs/benchmarks.md.
    """
    from dcsim.bench.tracking import bench_tracking, markdown_table
    from dcsim.scenario import packaged_scenario_path

    chosen = scenarios or tuple(
        packaged_scenario_path(name) for name in ("default.yaml", "crowded_field.yaml")
    )
    runs = bench_tracking(
        chosen, range(first_seed, first_seed + seeds), duration, overrides, progress=progress
    )
    click.echo(markdown_table(runs))


@click.command("capture", short_help="A tumbling target's capture over dispersed cases, judged.")
@click.argument(
    "campaign", required=False, type=click.Path(dir_okay=False, exists=True, path_type=Path)
)
@count_option("--cases", 100, "Cases run: the campaign's first N.")
@click.option(
    "--duration",
    type=click.FloatRange(min=0, min_open=True),
    help="world.duration of every case, s  [default: the scenario's]",
)
@out_dir_option("Campaign directory to keep. Default: a temporary folder, removed after.")
@click.option(
    "--resume",
    type=click.Path(file_okay=False, exists=True, path_type=Path),
    help="Run the cases of this campaign directory (an earlier --out) that have no result "
    "yet, after Ctrl-C, and judge them all.",
)
@cluster_options
@plot_option("Save the figures' histograms and the cases' tumbles here.")
def bench_capture_command(
    campaign: Path | None,
    cases: int,
    duration: float | None,
    out: Path | None,
    resume: Path | None,
    scheduler: str | None,
    connect_timeout: float | None,
    workers: int | None,
    worker_deaths: int,
    plot_path: Path | None,
) -> None:
    """The capture of a tumbling target over the cases of CAMPAIGN, judged.

    CAMPAIGN (default: scenarios/campaigns/debris_capture_dispersed.yaml of this
    checkout, 100 cases) is a campaign of a capture scenario; its first CASES cases run
    on Dask (a local cluster unless --scheduler). A case succeeds when it captured the
    target and detumbled the stack to the mission's detumbled_rate_deg_s, with no
    contact force above the gripper's force_limit and the base turned at most
    max_base_excursion_deg. Prints as Markdown for docs/benchmarks.md the success rate,
    the median, 95th percentile and maximum of the peak contact force, the base's turn,
    the detumble time and the capture time, the failures by cause and each failed
    case's tumble and start.
    """
    import tempfile

    from dcsim.bench import capture as bench
    from dcsim.bench.campaign import with_duration
    from dcsim.campaign import campaign_cases, load_campaign, resume_campaign, run_campaign
    from dcsim.campaign.run import load_campaign_directory

    options = cluster_choice(scheduler, workers, worker_deaths, connect_timeout)
    if resume is not None and (campaign, out, duration) != (None, None, None):
        raise click.BadParameter(
            "--resume completes the campaign stored in its directory: drop CAMPAIGN, "
            "--out and --duration",
            param_hint="--resume",
        )
    with tempfile.TemporaryDirectory(prefix="dcsim-capture-") as scratch:
        if resume is not None:
            loaded, count = load_campaign_directory(resume)
            limits = bench.limits_of(loaded)
            run = resume_campaign(resume, options)
        else:
            path = campaign or checkout_campaign(bench.DEFAULT_CAMPAIGN)
            if duration is not None:
                path = with_duration(path, Path(scratch), duration)
            loaded = load_campaign(path)
            limits = bench.limits_of(loaded)  # another mission is refused before any run
            count = loaded.spec.total_cases
            if cases > count:
                raise click.BadParameter(
                    f"the campaign has {count} cases: raise its `cases:` to run more",
                    param_hint="--cases",
                )
            count = cases
            folder = out if out is not None else Path(scratch) / "campaign"
            progress(f"campaign {loaded.spec.name}: {count} cases → {folder}")
            run = run_campaign(loaded, folder, options, count)
        selected = campaign_cases(loaded, PluginRegistry.discover(), count)
        judged = bench.judge(loaded, selected, run.table, limits)
        click.echo(bench.markdown(judged, limits))
        if plot_path is not None:
            bench.plot(judged, limits, plot_path)
            click.echo(f"\nplot: {plot_path}")
    if run.interrupted:
        again = resume or out
        click.echo(
            f"interrupted: dcsim bench capture --resume {again} runs the rest"
            if again is not None
            else "interrupted (the campaign was in a temporary folder: give --out to keep it)",
            err=True,
        )
        sys.exit(EXIT_INTERRUPTED)
