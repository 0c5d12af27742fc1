"""The ``dcsim`` command line.

Every error a user can cause is printed as ``error: <message>`` with exit status 2 and
no traceback; ``dcsim --debug ...`` shows the traceback instead. Installed plugin
packages add their own commands (``dcsim bench ant-colony`` is the ``ant-colony``
plugin's) through the ``dcsim_register_commands`` hook (:mod:`dcsim.cli.plugin_commands`).
"""

from __future__ import annotations

import json
import sys
import warnings
from collections.abc import Sequence
from dataclasses import asdict
from datetime import datetime
from pathlib import Path
from typing import TYPE_CHECKING

import click

from dcsim import __version__
from dcsim.bench.options import comma_numbers, comma_words
from dcsim.cli.campaign import campaign_group, cluster_choice, cluster_options
from dcsim.errors import DcsimError, PluginLoadWarning, PluginNotFoundError, did_you_mean
from dcsim.params import ParameterInfo, parameter_infos
from dcsim.registry.discovery import PluginRegistry, RegisteredPlugin
from dcsim.registry.interfaces import PLUGIN_KINDS
from dcsim.run.directory import file_name_part, prepare_run_directory
from dcsim.run.setup import setup_run
from dcsim.scenario import read_scenario
from dcsim.scenario.model import MAX_SEED

if TYPE_CHECKING:  # the bench modules and the runner are imported by their commands only
    from dcsim.bench.path_planners import PlannerChoice, ProblemResult
    from dcsim.run.loop import Runner

EXIT_USER_ERROR = 2


class _PluginGroup(click.Group):
    """A click group that also holds the commands plugin packages add to it.

    The packages are asked (:mod:`dcsim.cli.plugin_commands`) only when a command is not one of
    dcsim's own, or when the commands are listed, once per command line.
    """

    hook_argument = "bench"
    """The argument of ``dcsim_register_commands`` that stands for this group."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        """dcsim's own commands and the plugin packages', sorted."""
        return sorted({*self.commands, *_plugin_commands(ctx)[self.hook_argument]})

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        """dcsim's own command of that name, else a plugin package's."""
        own = self.commands.get(cmd_name)
        return own if own is not None else _plugin_commands(ctx)[self.hook_argument].get(cmd_name)


class _Group(_PluginGroup):
    """The ``dcsim`` group: it prints dcsim errors without a traceback."""

    hook_argument = "cli"

    def invoke(self, ctx: click.Context) -> object:
        try:
            return super().invoke(ctx)
        except DcsimError as exc:
            if ctx.meta.get("dcsim.debug"):
                raise
            click.echo(f"error: {exc}", err=True)
            ctx.exit(EXIT_USER_ERROR)


def _registry() -> PluginRegistry:
    """Discover plugins, printing loading problems as warnings on stderr."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PluginLoadWarning)
        registry = PluginRegistry.discover()
    for message in registry.warnings:
        click.echo(f"warning: {message}", err=True)
    return registry


def _plugin_commands(ctx: click.Context) -> dict[str, dict[str, click.Command]]:
    """The commands plugin packages add, by hook argument (asked once per command line;
    refused ones are printed as warnings on stderr)."""
    meta = ctx.find_root().meta
    if "dcsim.plugin_commands" not in meta:
        from dcsim.cli.plugin_commands import plugin_commands

        taken = {"cli": cli.commands, "bench": bench_group.commands}
        found = plugin_commands(_registry(), taken)
        for message in found.warnings:
            click.echo(f"warning: {message}", err=True)
        meta["dcsim.plugin_commands"] = found.commands
    return meta["dcsim.plugin_commands"]


@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, "--version", "-V", prog_name="dcsim")
@click.option("--debug", is_flag=True, help="Show full tracebacks for errors.")
@click.pass_context
def cli(ctx: click.Context, debug: bool) -> None:
    """dcsim: simulate space debris collectors and free-flying space robots.

    Run a scenario with `dcsim run`, check scenario files with `dcsim validate`, and
    list the installed localisers, planners and controllers with `dcsim plugins`.
    """
    ctx.meta["dcsim.debug"] = debug


@cli.command("plugins", short_help="List the registered plugins, or one's parameters.")
@click.argument("name", required=False)
@click.option(
    "--kind",
    type=click.Choice(list(PLUGIN_KINDS)),
    help="Only list plugins of this kind.",
)
@click.option("--json", "as_json", is_flag=True, help="Print a JSON list instead of a table.")
def plugins_command(name: str | None, kind: str | None, as_json: bool) -> None:
    """List registered plugins: kind, name, summary and origin; or NAME's parameters.

    The origin is the installed distribution (and version) that provides the plugin.
    With NAME, prints that plugin's robots and parameters (name, default, unit, bounds
    or allowed values, description), the keys of its scenario section's params; --kind
    picks one of two plugins of that name. Set DCSIM_LOAD_PLUGINS to a comma-separated
    list of distributions to restrict which external plugins load.
    """
    registry = _registry()
    if name is not None:
        _print_parameters(_plugins_named(registry, name, kind), as_json)
        return
    entries = [p.as_dict() for p in registry.plugins(kind)]
    if as_json:
        click.echo(json.dumps(entries, indent=2))
        return
    rows = [
        (e["kind"], e["name"], e["summary"], f"{e['distribution']} {e['version']}") for e in entries
    ]
    _print_table(("KIND", "NAME", "SUMMARY", "ORIGIN"), rows)


def _plugins_named(registry: PluginRegistry, name: str, kind: str | None) -> list[RegisteredPlugin]:
    """The registered plugins called ``name`` (of ``kind``, if given).

    Raises
    ------
    PluginNotFoundError
        Naming the closest names when there is none.
    """
    found = [p for p in registry.plugins(kind) if p.name == name]
    if found:
        return found
    if kind is not None:
        registry.get(kind, name)  # raises, with the names of that kind
    names = sorted({p.name for p in registry.plugins()})
    raise PluginNotFoundError(
        f"no plugin named '{name}' (see dcsim plugins)" + did_you_mean(name, names)
    )


def _print_parameters(plugins: list[RegisteredPlugin], as_json: bool) -> None:
    """Each plugin's origin, robots and parameter table (or all of it as JSON)."""
    if as_json:
        entries = [
            {
                **plugin.as_dict(),
                "robots": list(plugin.cls.robots),
                "parameters": [asdict(info) for info in parameter_infos(plugin.cls.Params)],
            }
            for plugin in plugins
        ]
        click.echo(json.dumps(entries, indent=2, ensure_ascii=False))
        return
    for index, plugin in enumerate(plugins):
        click.echo(("\n" if index else "") + f"{plugin.kind} {plugin.name}: {plugin.cls.summary}")
        click.echo(f"origin: {plugin.origin}")
        click.echo(f"robots: {', '.join(plugin.cls.robots)}")
        rows = [
            (i.name, _default_text(i), i.unit, i.bounds, i.description)
            for i in parameter_infos(plugin.cls.Params)
        ]
        if not rows:
            click.echo("parameters: none")
            continue
        click.echo("")
        _print_table(("PARAMETER", "DEFAULT", "UNIT", "BOUNDS", "DESCRIPTION"), rows)


def _default_text(info: ParameterInfo) -> str:
    """A parameter's default as a scenario file would write it."""
    if info.required:
        return "required"
    if isinstance(info.default, str):
        return info.default
    return json.dumps(info.default, ensure_ascii=False)


def _print_table(header: tuple[str, ...], rows: list[tuple[str, ...]]) -> None:
    widths = [max(len(str(r[i])) for r in [header, *rows]) for i in range(len(header))]
    for row in [header, *rows]:
        click.echo(
            "  ".join(str(cell).ljust(w) for cell, w in zip(row, widths, strict=True)).rstrip()
        )


@cli.command("validate")
@click.argument("files", nargs=-1, required=True, type=click.Path(dir_okay=False, path_type=Path))
def validate_command(files: tuple[Path, ...]) -> None:
    """Check scenario FILES without running anything.

    Each file is parsed, checked against the schema, and its plugin names and
    parameters are checked against the installed plugins. Prints `ok FILE` for each
    valid file and every problem of each invalid one; exits with status 2 if any file
    is invalid.
    """
    registry = _registry()
    failed = False
    for path in files:
        try:
            read_scenario(path, registry=registry)
        except DcsimError as exc:
            click.echo(f"error: {exc}", err=True)
            failed = True
        else:
            click.echo(f"ok {path}")
    if failed:
        sys.exit(EXIT_USER_ERROR)


@cli.command("run", short_help="Run a scenario and record it in a run directory.")
@click.argument("scenario", required=False, type=click.Path(dir_okay=False, path_type=Path))
@click.option(
    "--out",
    type=click.Path(file_okay=False, path_type=Path),
    help="Run directory to write (created if missing). Default: runs/NAME-YYYYmmdd-HHMMSS.",
)
@click.option("--force", is_flag=True, help="Replace the run directory if it already holds a run.")
@click.option(
    "--seed",
    type=click.IntRange(min=0, max=MAX_SEED),
    help="Seed for this run; replaces world.seed.",
)
@click.option(
    "--set",
    "overrides",
    multiple=True,
    metavar="KEY.PATH=VALUE",
    help="Override one scenario value, e.g. --set robot.max_force=20 or "
    "--set mission.targets[0].motion.r=150000; the value is read as YAML. A path ending in "
    "[+] appends to the list there: --set 'mission.targets[+]={id: 9, ...}'. Repeatable.",
)
@click.option(
    "--view",
    is_flag=True,
    help="Also write view.html, the run replayed in 3-D in a browser (see `dcsim view`).",
)
def run_command(
    scenario: Path | None,
    out: Path | None,
    force: bool,
    seed: int | None,
    overrides: tuple[str, ...],
    view: bool,
) -> None:
    """Run SCENARIO (default: the scenario shipped with dcsim) and record it.

    The scenario is validated (overrides applied first), its plugins constructed with
    their validated parameters, and the mission flown until it is done (for debris:
    every target delivered), world.duration is reached, or a stop rule ends it. The run
    directory receives scenario.yaml (resolved, to repeat the run), telemetry.csv, events.jsonl,
    summary.json and plots/; scenario.yaml and a summary with status "running" are
    there before the first step, and telemetry is streamed as the run goes. A run
    directory that cannot be written, or that already holds a run (unless --force), is
    refused before anything runs. Exit status: 0 when the run completed or was stopped
    by a stop rule, 1 when a plugin failed or the records could not be written, 130
    when interrupted with Ctrl-C. With --view the run directory also receives
    view.html, written after the run however it ended.
    """
    from dcsim.run.loop import Runner, terminal_progress  # the world engine loads PyBullet

    setup = setup_run(scenario, overrides, seed, registry=_registry())
    if out is None:
        stamp = f"{datetime.now():%Y%m%d-%H%M%S}"
        out = Path("runs") / f"{file_name_part(setup.scenario.name)}-{stamp}"
    prepare_run_directory(out, force)
    runner = Runner(setup, out, progress=terminal_progress())
    with warnings.catch_warnings():
        warnings.showwarning = _show_run_warning
        summary = runner.run()
    if sys.stderr.isatty():
        click.echo("", err=True)
    _print_plugin_traceback(runner)
    _print_summary(summary, out)
    if view:
        _write_view(out)
    if summary["reason"] == "interrupted":
        sys.exit(130)
    if summary["status"] == "failed":
        sys.exit(1)


def _print_plugin_traceback(runner: Runner) -> None:
    """With ``--debug``, print the traceback of the plugin whose exception ended the run
    (it is also kept in the run's ``plugin_failed`` event)."""
    failure = runner.failure
    if failure is None or failure.traceback is None:
        return
    if click.get_current_context().find_root().meta.get("dcsim.debug"):
        click.echo(failure.traceback.rstrip(), err=True)


def _show_run_warning(message: Warning | str, category: type[Warning], *args: object) -> None:
    """Print a warning issued during a run as ``warning: ...`` on stderr (on a line of
    its own, below the progress line on a terminal)."""
    start = "\n" if sys.stderr.isatty() else ""
    click.echo(f"{start}warning: {message}", err=True)


def _print_summary(summary: dict, out: Path) -> None:
    def number(key: str, unit: str, digits: int = 3) -> str:
        value = summary[key]
        return "n/a" if value is None else f"{value:.{digits}g} {unit}".rstrip()

    reason = f" ({summary['reason']})" if summary["reason"] else ""
    if summary["goal_met"] is False:
        reason += f" — goal not met: {summary['outcome']}"
    click.echo(f"{summary['scenario']} seed {summary['seed']}: {summary['status']}{reason}")
    outcome = f"{summary['outcome']}, " if summary["outcome"] else ""
    click.echo(f"  {outcome}collisions {summary['collisions']}")
    click.echo(
        f"  delta-v {number('delta_v_mps', 'm/s')}, propellant {number('fuel_used_kg', 'kg')}, "
        f"localisation RMSE {number('localisation_rmse_m', 'm')}, "
        f"closest obstacle {number('min_obstacle_distance_m', 'm')}"
    )
    click.echo(
        f"  simulated {summary['sim_time_s']:.1f} s in {summary['wall_time_s']:.1f} s of wall time "
        f"(x{summary['real_time_factor']:.0f} real time)"
    )
    click.echo(f"  plugins: {_plugins_flown(summary['plugins'])}")
    click.echo(f"  results in {out}")


@cli.command("view", short_help="Write a page that replays a run in 3-D in a browser.")
@click.argument("run_dir", type=click.Path(path_type=Path))
@click.option(
    "--out",
    type=click.Path(dir_okay=False, path_type=Path),
    help="Page to write. Default: RUN_DIR/view.html.",
)
@click.option(
    "--max-frames",
    type=click.IntRange(min=2),
    default=600,
    show_default=True,
    help="Frames the page holds at most (telemetry rows evenly spread over the run).",
)
def view_command(run_dir: Path, out: Path | None, max_frames: int) -> None:
    """Write a page that replays the run in RUN_DIR in 3-D in a browser.

    The page (RUN_DIR/view.html) is one self-contained HTML file, with plotly.js and
    the run's data inside: open it in any browser, no server or network needed. It
    shows the robot with its attitude (a manipulator's arm too), every target and
    obstacle in its true shape as it moves (grabbed targets ride along, delivered ones
    disappear), the plans, beacons, drop point or goal, a time slider with play and
    pause, and the mission's mode and key numbers at the time shown.
    """
    from dcsim.report.viewer import write_view

    page = write_view(run_dir, out, max_frames)
    click.echo(f"wrote {page} ({_megabytes(page)})")


def _write_view(run_dir: Path) -> None:
    """Write the run's page after ``dcsim run --view``, saying where; a run that left
    nothing to show (no telemetry row) gets a warning, and keeps its exit status."""
    from dcsim.report.viewer import ViewError, write_view

    try:
        page = write_view(run_dir)
    except ViewError as error:
        click.echo(f"warning: no view written: {error}", err=True)
        return
    click.echo(f"  view in {page} ({_megabytes(page)})")


def _megabytes(path: Path) -> str:
    return f"{path.stat().st_size / 1e6:.1f} MB"


def _plugins_flown(plugins: dict[str, dict[str, str]]) -> str:
    """``localiser ekf (dcsim 0.1.0), ...``: each role's plugin and where it came from."""
    return ", ".join(
        f"{role} {entry['name']} ({entry['distribution']} {entry['version']})"
        for role, entry in plugins.items()
    )


@cli.command("new-plugin", short_help="Write a plugin or mission package of your own.")
@click.argument("kind", type=click.Choice([*PLUGIN_KINDS, "mission"]))
@click.argument("name")
@click.option(
    "--dir",
    "directory",
    type=click.Path(file_okay=False, path_type=Path),
    default=Path("."),
    show_default=True,
    help="Folder to create the package in.",
)
def new_plugin_command(kind: str, name: str, directory: Path) -> None:
    """Write an out-of-tree package: a plugin of KIND called NAME, or a mission.

    The package (DIR/dcsim-NAME) has a pyproject.toml with the dcsim entry point, the
    plugin class with its parameter model and a simple working algorithm, a test file
    that runs the conformance suite, and a README. KIND `mission` writes a mission
    instead (mission.type NAME, found through the dcsim.missions entry point: its
    settings and a mission that flies to a point and holds it), with an example
    scenario its tests fly through the mission conformance suite. Install it with
    `pip install -e DIR/dcsim-NAME` and run `pytest` inside it. A NAME an installed
    plugin of KIND (or an installed mission) already has is refused.
    """
    from dcsim.registry.scaffold import new_plugin

    root = new_plugin(kind, name, directory, _registry())
    click.echo(f"wrote {root}")
    click.echo(f"next: pip install -e '{root}[test]' && (cd {root} && pytest)")


@cli.group(
    "bench", cls=_PluginGroup, short_help="Measure dcsim and its plugins against references."
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
@click.option(
    "--duration",
    type=click.FloatRange(min=1.0),
    default=60.0,
    show_default=True,
    help="Simulated seconds per measurement.",
)
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
    rows = bench_world(sizes, duration, progress=lambda line: click.echo(line, err=True))
    click.echo(markdown_table(rows))
    registry = _registry()
    summary = Runner(setup_run(registry=registry)).run()
    click.echo(
        f"\ndefault scenario: {summary['status']} ({summary['reason']}), "
        f"{summary['sim_time_s']:.1f} s simulated in {summary['wall_time_s']:.2f} s, "
        f"real-time factor {summary['real_time_factor']:.0f}"
    )
    click.echo(floor_line(loop_floor(summary["sim_time_s"], summary["wall_time_s"], registry)))


@bench_group.command("soak", short_help="A long run's memory and time per tick; FMU lifetimes.")
@click.option(
    "--ticks",
    type=click.IntRange(min=100),
    default=1_000_000,
    show_default=True,
    help="Control ticks to fly.",
)
@click.option(
    "--samples",
    type=click.IntRange(min=10),
    default=100,
    show_default=True,
    help="Memory and speed samples, evenly spaced.",
)
@click.option(
    "--fmu-cycles",
    type=click.IntRange(min=0),
    default=200,
    show_default=True,
    help="FMU instantiate/step/terminate/free cycles after the run (0: none).",
)
@click.option(
    "--out",
    type=click.Path(file_okay=False, path_type=Path),
    default=None,
    help="Run directory for the soak run's records (default: a temporary one).",
)
@click.option(
    "--plot",
    "plot_path",
    type=click.Path(dir_okay=False, path_type=Path),
    default=None,
    help="Write memory and time per tick against ticks as a PNG.",
)
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

    def say(line: str) -> None:
        click.echo(line, err=True)

    with tempfile.TemporaryDirectory(prefix="dcsim-soak-run-") as tmp:
        run_dir = prepare_run_directory(out or Path(tmp) / "run", force=False)
        result = soak.soak(ticks, samples, run_dir, say)
    click.echo(soak.markdown_table(result))
    if plot_path is not None:
        soak.plot(result, plot_path)
        click.echo(f"\nplot: {plot_path}")
    if fmu_cycles:
        memory = soak.fmu_cycles(fmu_cycles, say)
        early = memory[min(len(memory), 20) - 1]
        click.echo(
            f"\nFMU: {fmu_cycles} cycles, resident memory {early / 2**20:.1f} MB after cycle "
            f"{min(len(memory), 20)}, {memory[-1] / 2**20:.1f} MB after the last "
            f"({100 * (memory[-1] - early) / early:+.1f} %)"
        )


@bench_group.command(
    "localisers", short_help="Localisers' RMSE against the Cramér–Rao bound; latency."
)
@click.option(
    "--runs", type=click.IntRange(min=1), default=10, show_default=True, help="Monte Carlo runs."
)
@click.option(
    "--steps",
    type=click.IntRange(min=10),
    default=400,
    show_default=True,
    help="Updates per run (0.5 s each).",
)
@click.option(
    "--sigma",
    type=click.FloatRange(min=0, min_open=True),
    default=1.0,
    show_default=True,
    help="Range noise, m.",
)
@click.option(
    "--acceleration-sigma",
    type=click.FloatRange(min=0, min_open=True),
    default=0.005,
    show_default=True,
    help="Thrust noise of the manoeuvring collector, m/s^2 (the filters are told).",
)
@click.option(
    "--plot",
    "plot_path",
    type=click.Path(dir_okay=False, path_type=Path),
    help="Save the RMSE-over-time plot here.",
)
def bench_localisers_command(
    runs: int, steps: int, sigma: float, acceleration_sigma: float, plot_path: Path | None
) -> None:
    """Localisers' RMSE against the posterior Cramér–Rao bound, and their update latency.

    Every localiser (trilateration, ekf, ukf, sspf with 1k, 10k and 100k particles; the
    last on two runs only) flies the same runs of a manoeuvring collector ranging to the
    three nearest of eight beacons. Prints a Markdown table for docs/benchmarks.md.
    """
    from dcsim.bench.localisers import bench_localisers, markdown_table, plot

    bound, results = bench_localisers(
        runs, steps, sigma, acceleration_sigma, progress=lambda line: click.echo(line, err=True)
    )
    click.echo(markdown_table(bound, results))
    if plot_path is not None:
        plot(bound, results, plot_path)
        click.echo(f"plot: {plot_path}")


@bench_group.command(
    "task-planners", short_help="ga's time strategies; task planners' gaps to the optimum."
)
@click.option(
    "--instances",
    type=click.IntRange(min=1),
    default=100,
    show_default=True,
    help="Random instances per problem size (both studies).",
)
@click.option(
    "--moving-instances",
    type=click.IntRange(min=0),
    default=50,
    show_default=True,
    help="Instances per size for the gap to the grid optimum with moving targets.",
)
@click.option(
    "--repeats",
    type=click.IntRange(min=2),
    default=10,
    show_default=True,
    help="Runs with different seeds per instance for the dispersion.",
)
@click.option(
    "--dispersion-instances",
    type=click.IntRange(min=1),
    default=5,
    show_default=True,
    help="Instances whose dispersion is measured.",
)
@click.option(
    "--grid-step",
    type=click.FloatRange(min=0, min_open=True),
    default=10.0,
    show_default=True,
    help="Time grid of the moving-target optimum, s.",
)
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

    def progress(line: str) -> None:
        click.echo(line, err=True)

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
@click.option(
    "--seeds",
    type=click.IntRange(min=1),
    default=50,
    show_default=True,
    help="Fields (and world seeds) flown by every controller.",
)
@click.option(
    "--first-seed",
    type=click.IntRange(min=0),
    default=0,
    show_default=True,
    help="Seed of the first field (seeds FIRST to FIRST + N - 1).",
)
@click.option(
    "--controllers",
    default="elastic,pd",
    show_default=True,
    help="Comma-separated controller plugins (default parameters).",
)
@cluster_options
@click.option(
    "--set",
    "overrides",
    multiple=True,
    metavar="KEY.PATH=VALUE",
    help="Override a value of the crowded-field scenario, as for dcsim run. Repeatable.",
)
@click.option(
    "--plot",
    "plot_path",
    type=click.Path(dir_okay=False, path_type=Path),
    help="Save the distribution of the closest approach here.",
)
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
        safety = read_scenario(scenario, chosen, registry).mission.safety_distance
    runs = bench_controllers(
        scenario,
        names,
        range(first_seed, first_seed + seeds),
        overrides,
        cluster_choice(scheduler, workers, worker_deaths, connect_timeout),
        progress=lambda line: click.echo(line, err=True),
    )
    click.echo(markdown_table(runs))
    if plot_path is not None:
        plot(runs, safety, plot_path)
        click.echo(f"plot: {plot_path}")


@bench_group.command(
    "campaign", short_help="The campaign engine's overhead and speed-up per worker."
)
@click.argument(
    "campaign",
    required=False,
    type=click.Path(dir_okay=False, exists=True, path_type=Path),
)
@click.option(
    "--cases", type=click.IntRange(min=1), default=40, show_default=True, help="Cases run."
)
@click.option(
    "--workers",
    default="1,2",
    show_default=True,
    help="Comma-separated local cluster sizes (1 is always run: the reference).",
)
@click.option(
    "--duration",
    type=click.FloatRange(min=0, min_open=True),
    default=300.0,
    show_default=True,
    help="world.duration of every case, s.",
)
@click.option(
    "--out",
    type=click.Path(file_okay=False, path_type=Path),
    help="Folder for the run directories. Default: a temporary folder, removed after.",
)
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
        bench = bench_campaign(
            campaign, folder, cases, counts, duration, lambda line: click.echo(line, err=True)
        )
    click.echo(markdown_table(bench))


@bench_group.command("fmu", short_help="The closed-loop FMU in fmpy against dcsim run, per tick.")
@click.argument("scenario", required=False, type=click.Path(dir_okay=False, path_type=Path))
@click.option(
    "--duration",
    type=click.FloatRange(min=1.0),
    default=300.0,
    show_default=True,
    help="Simulated seconds per measurement.",
)
@click.option(
    "--repeats", type=click.IntRange(min=1), default=3, show_default=True, help="Measurements."
)
def bench_fmu_command(scenario: Path | None, duration: float, repeats: int) -> None:
    """Closed-loop FMU in fmpy against dcsim run: wall time per control tick.

    SCENARIO (default: the packaged one) is exported as a closed-loop FMU and flown
    natively and through the FMU, alternately, REPEATS times each. Prints a Markdown
    table for docs/benchmarks.md.
    """
    from dcsim.bench.fmu import bench_fmu, markdown_table

    result = bench_fmu(
        scenario, duration, repeats, progress=lambda line: click.echo(line, err=True)
    )
    click.echo(markdown_table(result))


@bench_group.command("peers", short_help="dcsim's attitude loop beside Basilisk's.")
@click.option(
    "--duration",
    type=click.FloatRange(min=1.0, max=86_400.0),
    default=600.0,
    show_default=True,
    help="Simulated seconds per run (whole control periods of 0.1 s).",
)
@click.option(
    "--repeats",
    type=click.IntRange(min=1),
    default=3,
    show_default=True,
    help="Timed runs per side.",
)
@click.option(
    "--basilisk-step",
    type=click.FloatRange(min=1e-4, max=0.1),
    default=None,
    help="Basilisk's dynamics step, s; it must divide the 0.1 s control period "
    "(default: dcsim's physics step, 0.01 s).",
)
@click.option(
    "--plot",
    "plot_path",
    type=click.Path(dir_okay=False, path_type=Path),
    default=None,
    help="Write the pointing error (and the position hold) against time as a PNG.",
)
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
    result = peers.bench_peers(
        duration, repeats, basilisk_step, progress=lambda line: click.echo(line, err=True)
    )
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
@click.option(
    "--states",
    type=click.IntRange(min=1),
    default=64,
    show_default=True,
    help="Random states (fixed seed) each call is timed at.",
)
@click.option(
    "--repeats",
    type=click.IntRange(min=1),
    default=30,
    show_default=True,
    help="Timing rounds over every call in turn; each call's best round counts.",
)
@click.option(
    "--number",
    type=click.IntRange(min=1),
    default=10,
    show_default=True,
    help="Passes over the states per call and round.",
)
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

    result = bench.bench_manipulator(
        states, repeats, number, progress=lambda line: click.echo(line, err=True)
    )
    click.echo(bench.markdown_table(result))
    click.echo(f"\n{bench.agreement_line(result)}")
    if scenario is not None:
        speed = bench.scenario_speed(scenario, registry=_registry())
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
@click.option(
    "--budget",
    type=click.FloatRange(min=0, min_open=True),
    default=60.0,
    show_default=True,
    help="Planning budget of every cell, s.",
)
@click.option(
    "--grid",
    "grid_params",
    default=None,
    help="grid-astar's parameters as key=value:key=value (default: its defaults).",
)
@click.option("--fly", is_flag=True, help="Also fly every plan through the transfer mission.")
def bench_grid_search_command(
    scenario: Path, budget: float, grid_params: str | None, fly: bool
) -> None:
    """The Boeing paper's Tables 3 and 4 regenerated: grid-astar on three goals under five
    weightings of delta-v and distance, beside the paper's figures, and multi-burn's
    delta-v per goal. Prints Markdown tables for docs/benchmarks.md.
    """
    from dcsim.bench.grid_search import bench_grid_search, tables
    from dcsim.bench.path_planners import planner_spec

    registry = _registry()
    params = None
    if grid_params:
        params = dict(planner_spec(registry, f"grid-astar:{grid_params}").params)
    cells = bench_grid_search(
        registry, scenario, budget, fly, lambda line: click.echo(line, err=True), params
    )
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
@click.option(
    "--runs",
    type=click.IntRange(min=1),
    default=10,
    show_default=True,
    help="Runs of every planner on every problem (world seeds 0 to N - 1).",
)
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
@click.option(
    "--fly",
    is_flag=True,
    help="Also fly every run that gave a trajectory through the transfer mission.",
)
@click.option(
    "--plot",
    "plot_path",
    type=click.Path(dir_okay=False, path_type=Path),
    help="Save box plots of planning time, delta-v and length per problem and planner.",
)
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
    registry = _registry()
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
        lambda line: click.echo(line, err=True),
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


@cli.group("robot")
def robot_group() -> None:
    """The robot of a scenario file: its model for other tools."""


@robot_group.command("urdf", short_help="Write the URDF of a scenario's manipulator.")
@click.argument("scenario", type=click.Path(dir_okay=False, path_type=Path))
@click.option(
    "-o",
    "--out",
    required=True,
    type=click.Path(dir_okay=False, path_type=Path),
    help="URDF file to write (.urdf).",
)
@click.option(
    "--set",
    "overrides",
    multiple=True,
    metavar="KEY.PATH=VALUE",
    help="Override one scenario value first (as for dcsim run). Repeatable.",
)
def robot_urdf_command(scenario: Path, out: Path, overrides: tuple[str, ...]) -> None:
    """Write the URDF of SCENARIO's manipulator (robot.type: manipulator) to OUT.

    It is the file the world loads: base link at the base's centre of mass, one
    revolute joint and link per DH row, a fixed end_effector link, inertias to be used as
    given (PyBullet: URDF_USE_INERTIA_FROM_FILE; Pinocchio: a free-flyer root joint).
    """
    from dcsim.robots.loading import load_robot_model

    model = load_robot_model(scenario, overrides)
    out.write_text(model.urdf(), encoding="utf-8")
    click.echo(f"URDF of {model.n_joints}-joint manipulator written to {out}")


@cli.group("fmu", short_help="FMI 2.0 co-simulation: export scenarios, couple FMUs.")
def fmu_group() -> None:
    """FMI 2.0 co-simulation: export scenarios as FMUs, couple FMUs (docs/fmu.md)."""


@fmu_group.command("export", short_help="Build an FMI 2.0 co-simulation FMU of a scenario.")
@click.argument("scenario", required=False, type=click.Path(dir_okay=False, path_type=Path))
@click.option(
    "-o",
    "--out",
    required=True,
    type=click.Path(dir_okay=False, path_type=Path),
    help="FMU file to write (.fmu).",
)
@click.option(
    "--plant-only",
    is_flag=True,
    help="Export the world alone: force and torque (and a manipulator's joint torques) in, "
    "true state and sensors out.",
)
@click.option(
    "--beacons",
    type=click.IntRange(min=1),
    help="With --plant-only: how many nearest beacons' ranges to output.  [default: 4]",
)
@click.option(
    "--set",
    "overrides",
    multiple=True,
    metavar="KEY.PATH=VALUE",
    help="Override one scenario value before export (as for dcsim run). Repeatable.",
)
def fmu_export_command(
    scenario: Path | None,
    out: Path,
    plant_only: bool,
    beacons: int | None,
    overrides: tuple[str, ...],
) -> None:
    """Build an FMI 2.0 co-simulation FMU of SCENARIO (default: the packaged one).

    The closed-loop FMU runs the whole scenario (world, localiser, planners, controller,
    mission) with disturbance force and torque as inputs; --plant-only exports the world
    alone. A manipulator's FMUs also output its joint angles and rates and its end
    effector, and its plant FMU takes the joint torques. The resolved scenario travels
    inside the FMU; importing it needs Python with dcsim installed.
    """
    from dcsim.fmu.export import export_fmu
    from dcsim.fmu.variables import DEFAULT_BEACONS

    if beacons is not None and not plant_only:
        raise click.BadParameter("only the plant FMU outputs beacon ranges", param_hint="--beacons")
    beacons = DEFAULT_BEACONS if beacons is None else beacons
    path = export_fmu(scenario, out, plant_only, overrides, beacons, registry=_registry())
    kind = "plant-only" if plant_only else "closed-loop"
    click.echo(f"{kind} FMU written to {path}")


@fmu_group.command("cosim", short_help="Couple a plant FMU with a controller FMU through fmpy.")
@click.argument("plant", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option(
    "--controller",
    required=True,
    type=click.Path(exists=True, dir_okay=False, path_type=Path),
    help="The controller FMU.",
)
@click.option(
    "--stop",
    type=click.FloatRange(min=0, min_open=True),
    default=60.0,
    show_default=True,
    help="Stop time, s.",
)
@click.option(
    "--step",
    type=click.FloatRange(min=0, min_open=True),
    default=0.1,
    show_default=True,
    help="Communication step, s.",
)
@click.option(
    "--set",
    "settings",
    multiple=True,
    metavar="FMU:NAME=VALUE",
    help="Start value of a parameter or input, FMU being plant or controller, e.g. "
    "--set controller:reference.position.x=5. Repeatable.",
)
@click.option(
    "--out",
    type=click.Path(file_okay=False, path_type=Path),
    default=Path("cosim"),
    show_default=True,
    help="Directory for results.csv and results.png.",
)
def fmu_cosim_command(
    plant: Path,
    controller: Path,
    stop: float,
    step: float,
    settings: tuple[str, ...],
    out: Path,
) -> None:
    """Couple the PLANT FMU with a controller FMU through fmpy; write a CSV and a plot.

    Signals connect by equal names (controller inputs from plant outputs, plant inputs
    from controller outputs); each step runs the controller, then the plant.
    """
    from dcsim.fmu.cosim import cosimulate, output_units, plot, write_csv

    results, coupling = cosimulate(plant, controller, stop, step, _start_values(settings))
    click.echo(f"connected to the controller: {', '.join(coupling.to_controller)}")
    click.echo(f"connected to the plant: {', '.join(coupling.to_plant)}")
    if coupling.unfed:
        click.echo(f"left at their start values: {', '.join(coupling.unfed)}")
    write_csv(results, out / "results.csv")
    plot(results, out / "results.png", output_units(plant, controller))
    click.echo(f"results in {out}/results.csv and {out}/results.png")


def _start_values(settings: tuple[str, ...]) -> dict[str, dict[str, float]]:
    values: dict[str, dict[str, float]] = {"plant": {}, "controller": {}}
    for setting in settings:
        fmu, _, assignment = setting.partition(":")
        name, equals, text = assignment.partition("=")
        if fmu not in values or not equals or not name:
            raise click.BadParameter(
                f"{setting!r}: write plant:NAME=VALUE or controller:NAME=VALUE",
                param_hint="--set",
            )
        try:
            values[fmu][name] = float(text)
        except ValueError:
            raise click.BadParameter(
                f"{setting!r}: {text!r} is not a number", param_hint="--set"
            ) from None
    return values


cli.add_command(campaign_group)


def main() -> None:
    """Entry point of the ``dcsim`` console script."""
    cli(prog_name="dcsim")
