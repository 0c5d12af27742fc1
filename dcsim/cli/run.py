"""``dcsim run``, ``dcsim validate`` and ``dcsim view``: fly a scenario, check scenario
files, and replay a run in a browser."""

from __future__ import annotations

import sys
import warnings
from datetime import datetime
from pathlib import Path
from typing import TYPE_CHECKING, TextIO

import click

from dcsim.cli.common import EXIT_USER_ERROR, plugin_registry
from dcsim.cli.options import count_option, out_dir_option, overrides_option, scenario_argument
from dcsim.errors import DcsimError
from dcsim.run.directory import file_name_part, prepare_run_directory
from dcsim.run.setup import setup_run
from dcsim.scenario import read_scenario
from dcsim.scenario.model import MAX_SEED

if TYPE_CHECKING:  # the runner is imported by its command only: it loads PyBullet
    from dcsim.run.loop import Runner


@click.command("validate")
@click.argument("files", nargs=-1, required=True, type=click.Path(dir_okay=False, path_type=Path))
def validate_command(files: tuple[Path, ...]) -> None:
    """Check scenario FILES without running anything.

    Each file is parsed, checked against the schema, and its plugin names and
    parameters are checked against the installed plugins. Prints `ok FILE` for each
    valid file and every problem of each invalid one; exits with status 2 if any file
    is invalid.
    """
    registry = plugin_registry()
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


@click.command("run", short_help="Run a scenario and record it in a run directory.")
@scenario_argument(required=False)
@out_dir_option("Run directory to write (created if missing). Default: runs/NAME-YYYYmmdd-HHMMSS.")
@click.option("--force", is_flag=True, help="Replace the run directory if it already holds a run.")
@click.option(
    "--seed",
    type=click.IntRange(min=0, max=MAX_SEED),
    help="Seed for this run; replaces world.seed.",
)
@overrides_option(
    "Override one scenario value, e.g. --set robot.max_force=20 or "
    "--set mission.targets[0].motion.r=150000; the value is read as YAML. A path ending in "
    "[+] appends to the list there: --set 'mission.targets[+]={id: 9, ...}'. Repeatable."
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

    setup = setup_run(scenario, overrides, seed, registry=plugin_registry())
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


def _show_run_warning(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: TextIO | None = None,
    line: str | None = None,
) -> None:
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
    said = summary["goal_met"] is False  # the first line gave the outcome already
    outcome = f"{summary['outcome']}, " if summary["outcome"] and not said else ""
    click.echo(f"  {outcome}collisions {summary['collisions']}")
    click.echo(
        f"  delta-v {number('delta_v_mps', 'm/s')}, propellant {number('fuel_used_kg', 'kg')}, "
        f"localisation RMSE {number('localisation_rmse_m', 'm')}, "
        f"closest obstacle {number('min_obstacle_distance_m', 'm')}"
    )
    if summary.get("cw_error_estimate_m") is not None:
        click.echo(f"  Clohessy-Wiltshire error up to {number('cw_error_estimate_m', 'm', 2)}")
    click.echo(
        f"  simulated {summary['sim_time_s']:.1f} s in {summary['wall_time_s']:.1f} s of wall time "
        f"(x{summary['real_time_factor']:.0f} real time)"
    )
    flown = summary["plugins"]
    sensors = {k.removeprefix("sensors."): v for k, v in flown.items() if k.startswith("sensors.")}
    roles = {k: v for k, v in flown.items() if not k.startswith("sensors.")}
    click.echo(f"  sensors: {_plugins_flown(sensors)}")
    click.echo(f"  plugins: {_plugins_flown(roles)}")
    click.echo(f"  results in {out}")


@click.command("view", short_help="Write a page that replays a run in 3-D in a browser.")
@click.argument("run_dir", type=click.Path(path_type=Path))
@click.option(
    "--out",
    type=click.Path(dir_okay=False, path_type=Path),
    help="Page to write. Default: RUN_DIR/view.html.",
)
@count_option(
    "--max-frames",
    600,
    "Frames the page holds at most (telemetry rows evenly spread over the run).",
    minimum=2,
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
    """``localiser ekf (dcsim 0.1.0), ...``: each role's plugin (or sensor's model) and
    where it came from."""
    return ", ".join(
        f"{role} {entry['name']} ({entry['distribution']} {entry['version']})"
        for role, entry in plugins.items()
    )
