"""Runs from Python: load a scenario, run it or step it, read a run directory back.

These are the calls :mod:`dcsim.api` offers a script or a notebook (docs/python.md)::

    from dcsim.api import run

    result = run("scenarios/default.yaml", overrides=["world.duration=120"])
    result.telemetry.plot(x="time_s", y="delta_v_mps")

A run is the one ``dcsim run`` makes: the same scenario, overrides and seed give the
same telemetry and events, in memory or in a run directory.
"""

from __future__ import annotations

import dataclasses
import json
import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from dcsim.registry.discovery import PluginRegistry
from dcsim.run.directory import RunDirectoryError, prepare_run_directory
from dcsim.run.recording import column_unit, count_lines, to_json
from dcsim.run.setup import Overrides, ScenarioInput, setup_run
from dcsim.scenario import Scenario

if TYPE_CHECKING:
    import pandas

    from dcsim.run.loop import Runner
    from dcsim.run.recording import Recorder


@dataclass(frozen=True, eq=False)
class RunResult:
    """What a run recorded: its summary, telemetry, events and plugins.

    Attributes
    ----------
    summary : dict
        The fields of ``summary.json`` (docs/cli.md): ``status``, ``reason``, the
        mission's outcome and figures, each with its unit in its name
        (``delta_v_mps``, ``sim_time_s``).
    telemetry : pandas.DataFrame
        One row per control tick, the columns of ``telemetry.csv`` named with their
        unit suffix (``time_s``, ``x_m``, ``vx_mps``, ``fuel_used_kg``: docs/cli.md);
        ``telemetry.attrs["units"]`` maps each column to its unit (``"m/s"``; empty for
        a count, a flag, a text or a dimensionless number).
    events : list of dict
        The events in order (``events.jsonl``): ``t`` (s), ``event`` and its fields.
    plugins : dict of str to str
        Name and version of the plugin of each role the run used (from the summary;
        empty for a run directory whose run never ended).
    run_dir : Path or None
        The run directory; None for a run recorded in memory only.
    """

    summary: dict[str, Any]
    telemetry: pandas.DataFrame
    events: list[dict[str, Any]]
    plugins: dict[str, str]
    run_dir: Path | None = None

    @property
    def status(self) -> str:
        """How the run ended: ``completed``, ``stopped`` or ``failed`` (``running`` for a
        run directory whose run was killed)."""
        return self.summary["status"]

    def events_table(self) -> pandas.DataFrame:
        """The events as a DataFrame: one row per event, one column per field (NaN where
        an event has no such field)."""
        import pandas as pd

        return pd.DataFrame(self.events)


def load_scenario(
    scenario: ScenarioInput = None,
    overrides: Overrides = (),
    *,
    seed: int | None = None,
    registry: PluginRegistry | None = None,
) -> Scenario:
    """Load and validate a scenario, as ``dcsim run`` would fly it.

    Parameters
    ----------
    scenario : str, Path, mapping or Scenario, optional
        A scenario file, the scenario's data as a mapping (the YAML file's content), or
        a loaded scenario; the packaged default scenario if None.
    overrides : sequence of str or mapping
        ``key.path=value`` texts, as ``dcsim run --set`` takes them
        (``["world.duration=30", "mission.targets[0].motion.r=150000"]``), or a mapping of key
        paths to values (``{"world.duration": 30}``).
    seed : int, optional
        Replaces ``world.seed``.
    registry : PluginRegistry, optional
        The plugins to choose from; the installed ones if None.

    Returns
    -------
    Scenario
        The validated scenario, every plugin's parameters with their defaults filled
        in (SI units; docs/scenarios.md).

    Raises
    ------
    ScenarioError
        Listing every problem: key path, and the file's line or the override.
    """
    return setup_run(scenario, overrides, seed, registry).scenario


def run(
    scenario: ScenarioInput = None,
    overrides: Overrides = (),
    out: str | Path | None = None,
    *,
    seed: int | None = None,
    force: bool = False,
    plots: bool = True,
    registry: PluginRegistry | None = None,
) -> RunResult:
    """Fly a scenario to its end, as ``dcsim run`` does, and return what it recorded.

    Parameters
    ----------
    scenario : str, Path, mapping or Scenario, optional
        As for :func:`load_scenario`; the packaged default scenario if None.
    overrides : sequence of str or mapping
        As for :func:`load_scenario`.
    out : str or Path, optional
        Run directory to write (``scenario.yaml``, ``telemetry.csv``, ``events.jsonl``,
        ``summary.json``, ``plots/``: docs/cli.md), checked before the run as
        ``dcsim run --out`` checks it; None records in memory only and writes nothing.
    seed : int, optional
        Replaces ``world.seed``.
    force : bool
        Replace ``out`` if it already holds a run (or anything else).
    plots : bool
        Draw the plots into ``out/plots`` (only with ``out``).
    registry : PluginRegistry, optional
        The plugins to choose from; the installed ones if None.

    Returns
    -------
    RunResult
        The summary, telemetry, events and plugins. A plugin that raised ends the run
        ``failed`` with the reason in the summary; Ctrl-C ends it ``stopped``
        (``interrupted``), with what was recorded until then.

    Raises
    ------
    ScenarioError
        If the scenario, an override or a plugin choice is invalid (nothing runs).
    RunDirectoryError
        If ``out`` cannot be used (nothing runs).
    """
    runner = _runner(scenario, overrides, out, seed, force, plots, registry)
    runner.run()
    return close_run(runner)


def open_run(
    scenario: ScenarioInput = None,
    overrides: Overrides = (),
    out: str | Path | None = None,
    *,
    seed: int | None = None,
    force: bool = False,
    plots: bool = True,
    registry: PluginRegistry | None = None,
) -> Runner:
    """Start a run to be flown one control period at a time; finish it with :func:`close_run`.

    Parameters are those of :func:`run`. The world is built and the first control
    period decided (time 0) before the call returns.

    Returns
    -------
    dcsim.run.loop.Runner
        The open run: ``advance()`` flies one control period (``world.control_period``
        s, optionally with a disturbance force in N and torque in N·m, world frame)
        and decides the next; ``ended`` says when the mission, ``world.duration`` or a
        stop rule has ended it (``status`` and ``reason`` say how); ``world.time`` is
        the simulated time (s), ``outputs`` the world's outputs now (true state, SI),
        ``estimate`` the localiser's estimate and ``mode`` the mission's mode.

    Raises
    ------
    ScenarioError, RunDirectoryError
        As for :func:`run`.
    """
    runner = _runner(scenario, overrides, out, seed, force, plots, registry)
    runner.open()
    return runner


def close_run(runner: Runner) -> RunResult:
    """Finish a run from :func:`open_run` and return what it recorded.

    A run that has not ended is ended ``stopped`` (``closed before the end``); the
    records are written (with ``out``) and the summary made. Closing a run that was
    closed already only reads its result.

    Parameters
    ----------
    runner : dcsim.run.loop.Runner
        The run, from :func:`open_run`.

    Returns
    -------
    RunResult
        As from :func:`run`.
    """
    if not runner.summary:
        runner.close()
    summary = json.loads(to_json(runner.summary))  # the runner's: it knows how writing ended
    if runner.info.out_dir is not None:
        try:
            recorded = read_run(runner.info.out_dir)
        except RunDirectoryError:
            pass  # the records could not be written (the summary says why): what is in memory
        else:
            return dataclasses.replace(recorded, summary=summary, plugins=_plugins(summary))
    events = [json.loads(to_json(event)) for event in runner.recorder.events]
    return RunResult(summary, _memory_telemetry(runner.recorder), events, _plugins(summary))


def read_run(run_dir: str | Path) -> RunResult:
    """Read a run directory (``dcsim run``'s, a campaign case's) into a :class:`RunResult`.

    A run killed mid-way reads too: its summary says ``running``, its telemetry ends at
    the last complete row.

    Parameters
    ----------
    run_dir : str or Path
        The run directory.

    Returns
    -------
    RunResult
        Its summary, telemetry, events and plugins.

    Raises
    ------
    RunDirectoryError
        If ``run_dir`` is not a run directory or one of its records cannot be read.
    """
    run_dir = Path(run_dir)
    try:
        summary = json.loads(_record(run_dir, "summary.json").read_text(encoding="utf-8"))
        telemetry = telemetry_frame(_record(run_dir, "telemetry.csv"))
        events = read_events(_record(run_dir, "events.jsonl"))
    except (OSError, ValueError) as error:  # unreadable, not UTF-8, not JSON, not CSV
        raise RunDirectoryError(f"cannot read the run directory {run_dir}: {error}") from None
    return RunResult(summary, telemetry, events, _plugins(summary), run_dir)


def telemetry_frame(path: Path) -> pandas.DataFrame:
    """A ``telemetry.csv`` as a DataFrame, leaving out a last line cut short by a killed run.

    Columns keep the header's names with their unit suffix; ``attrs["units"]`` maps
    each to its unit. Floats read back exactly as written.
    """
    import pandas as pd

    lines = count_lines(path)
    if lines == 0:
        return _with_units(pd.DataFrame())
    with path.open("rb") as stream:
        stream.seek(-1, os.SEEK_END)
        whole = stream.read(1) == b"\n"
    # pandas 3 parses floats exactly by default (and deprecates the option); pandas 2 must be asked
    exact = {"float_precision": "round_trip"} if int(pd.__version__.split(".")[0]) < 3 else {}
    frame = pd.read_csv(
        path,
        nrows=None if whole else lines - 1,
        keep_default_na=False,
        na_values=["nan"],
        **exact,
    )
    return _with_units(frame)


def read_events(path: Path) -> list[dict[str, Any]]:
    """The events of an ``events.jsonl``, leaving out a last line cut short by a killed run."""
    text = path.read_text(encoding="utf-8")
    return [json.loads(line) for line in text[: text.rfind("\n") + 1].splitlines()]


def _runner(
    scenario: ScenarioInput,
    overrides: Overrides,
    out: str | Path | None,
    seed: int | None,
    force: bool,
    plots: bool,
    registry: PluginRegistry | None,
) -> Runner:
    """A runner of the resolved scenario, its run directory checked and made ready."""
    from dcsim.run.loop import Runner  # the world engine loads PyBullet

    setup = setup_run(scenario, overrides, seed, registry)
    out_dir = None if out is None else prepare_run_directory(Path(out), force)
    return Runner(setup, out_dir, plots=plots)


def _memory_telemetry(recorder: Recorder) -> pandas.DataFrame:
    """The rows a run kept in memory, under the names of ``telemetry.csv``'s header."""
    import pandas as pd

    frame = pd.DataFrame(recorder.rows, columns=list(recorder.columns))
    frame.columns = list(recorder.header)
    return _with_units(frame)


def _with_units(frame: pandas.DataFrame) -> pandas.DataFrame:
    frame.attrs["units"] = {name: column_unit(name) for name in frame.columns}
    return frame


def _plugins(summary: Mapping[str, Any]) -> dict[str, str]:
    """Name → version of the plugin of each role in a summary."""
    return {entry["name"]: entry["version"] for entry in summary.get("plugins", {}).values()}


def _record(run_dir: Path, name: str) -> Path:
    """The path of one of a run directory's records, which must exist."""
    path = run_dir / name
    if not path.is_file():
        what = "is not a run directory" if not run_dir.is_dir() else f"has no {name}"
        raise RunDirectoryError(f"{run_dir} {what}; name a folder that dcsim run wrote")
    return path
