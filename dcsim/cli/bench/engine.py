"""Benches of dcsim's engine: the closed loop against PyBullet (``world``), the orbit
models against an inertial reference (``dynamics``), a long run (``soak``), the FMU
(``fmu``), the campaign engine (``campaign``), the attitude loop beside Basilisk's
(``peers``), the manipulator model against Pinocchio's (``manipulator``) and the
Gymnasium environments' step speed (``gym``)."""

from __future__ import annotations

import warnings
from pathlib import Path

import click

from dcsim.bench.options import comma_numbers, comma_words
from dcsim.cli.common import checkout_campaign, plugin_registry, progress
from dcsim.cli.options import (
    count_option,
    duration_option,
    out_dir_option,
    plot_option,
    positive_option,
    scenario_argument,
)
from dcsim.errors import DcsimError, PlannerModelWarning
from dcsim.run.directory import prepare_run_directory
from dcsim.run.setup import setup_run


@click.command("world", short_help="Closed-loop wall time per simulated second against PyBullet.")
@click.option(
    "--objects",
    default="10,100,1000",
    show_default=True,
    help="Comma-separated field sizes (targets and obstacles in all), each >= 0.",
)
@duration_option(60.0)
@click.option(
    "--orbit-model",
    type=click.Choice(["cw", "two-body", "j2"]),
    default="cw",
    show_default=True,
    help="world.orbit.model of the synthetic scenarios and the default scenario's run.",
)
@click.option(
    "--sensors",
    "sensing",
    type=click.Choice(["ideal", "realistic"]),
    default="ideal",
    show_default=True,
    help="sensors.profile of the synthetic scenarios and the default scenario's run.",
)
def bench_world_command(objects: str, duration: float, orbit_model: str, sensing: str) -> None:
    """Closed-loop wall time per simulated second against PyBullet stepping alone.

    For each field size, one synthetic LVLH scenario is stepped bare (stepSimulation
    only) and flown by the full runner; the closed loop is split by phase of the run
    loop. Then the default scenario is flown once for its real-time factor. Prints a
    Markdown table for docs/benchmarks.md, and the floor under the default scenario's
    real-time factor: stepping, the per-step force calls and the localiser plugin alone;
    the last line is the whole loop's wall time over that floor.
    Every world moves by ORBIT_MODEL's dynamics and is sensed with the SENSING profile.
    """
    from dcsim.bench.world import (
        bench_world,
        floor_line,
        loop_floor,
        markdown_table,
        ratio_line,
    )
    from dcsim.run.loop import Runner

    words = [word.strip() for word in objects.split(",")]
    if not all(word.isdigit() for word in words):
        raise click.BadParameter(
            f"expected integers >= 0 like 10,100,1000, got {objects!r}", param_hint="--objects"
        )
    sizes = [int(word) for word in words]
    overrides = [] if orbit_model == "cw" else [f"world.orbit.model={orbit_model}"]
    if sensing != "ideal":
        overrides.append(f"sensors.profile={sensing}")
    registry = plugin_registry()
    with warnings.catch_warnings():  # the planners model cw only: expected in other worlds
        warnings.simplefilter("ignore", PlannerModelWarning)
        rows = bench_world(
            sizes, duration, progress=progress, orbit_model=orbit_model, sensing=sensing
        )
        click.echo(markdown_table(rows))
        summary = Runner(setup_run(overrides=overrides, registry=registry)).run()
    click.echo(
        f"\ndefault scenario: {summary['status']} ({summary['reason']}), "
        f"{summary['sim_time_s']:.1f} s simulated in {summary['wall_time_s']:.2f} s, "
        f"real-time factor {summary['real_time_factor']:.0f}"
    )
    floor = loop_floor(summary["sim_time_s"], summary["wall_time_s"], registry, overrides=overrides)
    click.echo(floor_line(floor))
    click.echo(ratio_line(floor))


@click.command("dynamics", short_help="The orbit models' free drift against an inertial reference.")
@click.option(
    "--models", default="cw,two-body,j2", show_default=True, help="World orbit models flown."
)
@click.option(
    "--separations",
    default="100,1000,10000",
    show_default=True,
    help="Comma-separated start distances from the chief, m.",
)
@click.option("--axes", default="x,y,z", show_default=True, help="LVLH axes started on.")
@click.option(
    "--eccentricities",
    default="0,0.01",
    show_default=True,
    help="Chief eccentricities (semi-major axis 6,778,137 m; cw is circular only).",
)
@positive_option("--orbits", 1.0, "Chief orbits each case drifts.")
@positive_option("--physics-step", 0.01, "world.physics_step of the drifting worlds, s.")
@positive_option("--control-period", 0.1, "world.control_period of the drifting worlds, s.")
@click.option(
    "--planners/--no-planners",
    default=True,
    show_default=True,
    help="Also fly the CW-based planners' missions under cw and j2.",
)
@click.option(
    "--scenarios",
    "scenario_dir",
    type=click.Path(file_okay=False, path_type=Path),
    default=Path("scenarios"),
    show_default=True,
    help="Folder holding station_inspection.yaml and default.yaml (for the planners).",
)
@plot_option("Write the worst drift error against separation (log-log) as a PNG.")
def bench_dynamics_command(
    models: str,
    separations: str,
    axes: str,
    eccentricities: str,
    orbits: float,
    physics_step: float,
    control_period: float,
    planners: bool,
    scenario_dir: Path,
    plot_path: Path | None,
) -> None:
    """The orbit models against an independent inertial reference.

    The robot of a bare world starts at each separation on each LVLH axis with a
    drift-free velocity and drifts free for ORBITS chief orbits under each model, on each
    orbit; its position is compared every 10 s with an inertial propagation (scipy) under
    the exact physics: cw and two-body worlds with the two-body reference, j2 with the
    J2 one. Then the integration cost of a thrust (physics step against half of it), and
    with --planners the station inspection (grid-astar, multi-burn) and default (ga)
    missions flown under cw and j2. Prints Markdown tables for docs/benchmarks.md.
    """
    from dcsim.bench import dynamics

    chosen = comma_words(models, "--models")
    chosen_axes = comma_words(axes, "--axes")
    for option, words, allowed in (
        ("--models", chosen, dynamics.MODELS),
        ("--axes", chosen_axes, dynamics.AXES),
    ):
        unknown = [w for w in words if w not in allowed]
        if unknown:
            raise DcsimError(f"{option}: unknown {', '.join(unknown)}; use {', '.join(allowed)}")
    distances = comma_numbers(separations, "--separations")
    if min(distances) <= 0:
        raise DcsimError("--separations: every distance must be above 0 m")
    cases = dynamics.drift_cases(
        chosen, comma_numbers(eccentricities, "--eccentricities"), distances, chosen_axes
    )
    results = dynamics.bench_drift(cases, orbits, physics_step, control_period, progress)
    click.echo(dynamics.drift_table(results))
    click.echo(f"\n{dynamics.verdict(results)}")
    progress("thrust: the 1 km j2 case at two physics steps")
    cost = dynamics.thrust_cost(orbits, physics_step, control_period)
    click.echo(f"\n{dynamics.thrust_line(cost)}")
    if plot_path is not None:
        dynamics.plot(results, plot_path)
        click.echo(f"\nplot: {plot_path}")
    if planners:
        flights = dynamics.bench_flights(
            scenario_dir, registry=plugin_registry(), progress=progress
        )
        click.echo(f"\n{dynamics.flights_table(flights)}")


@click.command("soak", short_help="A long run's memory and time per tick; FMU lifetimes.")
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


@click.command("fmu", short_help="The closed-loop FMU in fmpy against dcsim run, per tick.")
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


@click.command("campaign", short_help="The campaign engine's overhead and speed-up per worker.")
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
        campaign = checkout_campaign("default_dispersed.yaml")
    counts = [int(n) for n in comma_numbers(workers, "--workers") if n >= 1]
    with tempfile.TemporaryDirectory() as scratch:
        folder = out if out is not None else Path(scratch)
        bench = bench_campaign(campaign, folder, cases, counts, duration, progress)
    click.echo(markdown_table(bench))


@click.command("peers", short_help="dcsim's attitude loop beside Basilisk's.")
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
@plot_option(
    "Write the pointing error, the position hold and the wheel speeds against time as a PNG."
)
def bench_peers_command(
    duration: float, repeats: int, basilisk_step: float | None, plot_path: Path | None
) -> None:
    """dcsim's attitude loop beside Basilisk's: the same slew, gains and rates.

    A rigid free flyer slews 90° to a fixed inertial attitude under a PD law at 10 Hz,
    truth-fed, once with translation free, once holding its position, once on four
    reaction wheels and once on twelve thrusters; dcsim (the hold mission, pd, PyBullet,
    its reaction wheels and thrusters) and Basilisk (spacecraft hub, extForceTorque,
    simpleNav, inertial3D, attTrackingError, mrpFeedback, hillFrameRelativeControl,
    rwMotorTorque, reactionWheelStateEffector, thrForceMapping, thrFiringRemainder,
    thrusterDynamicEffector) fly it alternately, REPEATS times each. Prints a Markdown
    table for docs/benchmarks.md.
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


@click.command("manipulator", short_help="The manipulator model's time per call against Pinocchio.")
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


@click.command("gym", short_help="Gymnasium environments' step rates and cost per run tick.")
@click.option(
    "--envs",
    default=None,
    help="Comma-separated environment ids. Default: all (dcsim/Transfer-v0, "
    "dcsim/Debris-v0, dcsim/Reach-v0).",
)
@click.option(
    "--counts", default="1,2,8", show_default=True, help="Comma-separated copies per vector."
)
@click.option(
    "--vector",
    "vectors",
    default="async,sync",
    show_default=True,
    help="Vector environments: async (a process per copy), sync (one process).",
)
@count_option("--steps", 500, "Vector steps timed per vector and number of copies.")
@count_option("--periods", 1000, "Control periods per step-cost measurement, each side.")
@count_option("--repeats", 5, "Step-cost measurements per side (medians are reported).")
@click.option("--seed", type=int, default=0, show_default=True, help="Seeds resets and actions.")
@out_dir_option("Write gym.json (the results) and gym.png (steps per second) here.")
def bench_gym_command(
    envs: str | None,
    counts: str,
    vectors: str,
    steps: int,
    periods: int,
    repeats: int,
    seed: int,
    out: Path | None,
) -> None:
    """The Gymnasium environments' speed: steps per second in vectors, a step against a tick.

    For each environment, COUNTS copies are stepped STEPS times with random actions in
    each vector kind (AsyncVectorEnv: a worker process per copy; SyncVectorEnv: one
    process) and the environment steps per wall second reported. Then one environment
    step (gymnasium.make) is timed against one tick of dcsim run on the same scenario
    with path_planner=null and its controller commanding, over PERIODS control periods,
    alternately REPEATS times; the ratio of the medians is checked against the target
    (at most 1.2). Prints Markdown tables for docs/benchmarks.md. Needs Gymnasium (pip
    install 'dcsim[rl]').
    """
    import importlib.util
    import json

    if importlib.util.find_spec("gymnasium") is None:
        raise DcsimError("dcsim bench gym needs Gymnasium: pip install 'dcsim[rl]'")
    from dcsim.bench import gym as bench
    from dcsim.gym import ENVIRONMENTS

    env_ids = list(ENVIRONMENTS) if envs is None else comma_words(envs, "--envs")
    kinds = comma_words(vectors, "--vector")
    for option, words, allowed in (
        ("--envs", env_ids, tuple(ENVIRONMENTS)),
        ("--vector", kinds, bench.VECTOR_KINDS),
    ):
        unknown = [w for w in words if w not in allowed]
        if unknown:
            raise DcsimError(f"{option}: unknown {', '.join(unknown)}; use {', '.join(allowed)}")
    numbers = comma_numbers(counts, "--counts")
    if not all(n >= 1 and n == int(n) for n in numbers):
        raise DcsimError(f"--counts: expected whole numbers >= 1 like 1,2,8, got {counts!r}")
    result = bench.bench_gym(
        env_ids, [int(n) for n in numbers], kinds, steps, periods, repeats, seed, progress
    )
    click.echo(bench.markdown_tables(result))
    click.echo(bench.verdict(result))
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        (out / "gym.json").write_text(json.dumps(result.as_json(), indent=2) + "\n")
        bench.plot(result, out / "gym.png")
        click.echo(f"\nresults: {out / 'gym.json'}, plot: {out / 'gym.png'}")
