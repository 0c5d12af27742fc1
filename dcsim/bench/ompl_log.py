"""OMPL's benchmark log, written for any planner, and the database OMPL's parser makes of it.

The log follows the grammar of OMPL's doc/markdown/benchmark.md ("The benchmark logfile
format"): one experiment (one problem) per file, a block per planner with its common
properties, its per-run properties (``name TYPE``, TYPE one of BOOLEAN, INTEGER, REAL,
ENUM) and one line of values per run. :func:`write_database` hands the logs to OMPL's own
parser (``ompl.tools.readBenchmarkLog``), which writes the SQLite tables Planner Arena
reads: ``experiments``, ``plannerConfigs``, ``runs``, ``progress`` and ``enums``.
"""

from __future__ import annotations

import contextlib
import io
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from dcsim.errors import DcsimError

Value = bool | int | float | None
"""A run's measurement; None when it has none (an empty field, NULL in the database)."""


@dataclass(frozen=True)
class PlannerBlock:
    """One planner's data in an experiment.

    Attributes
    ----------
    name : str
        The planner configuration's name.
    settings : mapping of str to str
        Its common properties (parameters, version), one ``name = value`` line each.
    properties : sequence of (str, str)
        ``(name, TYPE)`` of each per-run property; names may hold spaces, not newlines.
    runs : sequence of sequence of Value
        One row of values per run, in the order of ``properties``.
    """

    name: str
    settings: Mapping[str, str]
    properties: Sequence[tuple[str, str]]
    runs: Sequence[Sequence[Value]]


@dataclass(frozen=True)
class Experiment:
    """One problem's benchmark: what the preamble of the log says, and the planners' data.

    Attributes
    ----------
    name : str
        Experiment name, without whitespace.
    library, version : str
        Who wrote the log (the database's ``version`` is ``"library version"``).
    properties : mapping of str to (str, Value)
        Experiment properties: one-word name → ``(TYPE, value)``.
    host, date : str
        Where and when it ran.
    setup, cpuinfo : str
        Multi-line descriptions of the problem and the machine.
    seed : int
        The first run's random seed.
    time_limit : float
        Time budget of each run, s.
    memory_limit : float
        Memory limit of each run, MB (0: none).
    runs_per_planner : int
        Runs of each planner.
    total_time : float
        Wall time spent on the experiment, s.
    enums : mapping of str to sequence of str
        Enumerated property types: name → the descriptions of values 0, 1, ...
    planners : sequence of PlannerBlock
        The planners' data.
    """

    name: str
    library: str
    version: str
    properties: Mapping[str, tuple[str, Value]]
    host: str
    date: str
    setup: str
    cpuinfo: str
    seed: int
    time_limit: float
    memory_limit: float
    runs_per_planner: int
    total_time: float
    enums: Mapping[str, Sequence[str]]
    planners: Sequence[PlannerBlock]


def _field(value: Value) -> str:
    """A measurement as the log writes it: booleans as 1/0, floats round-tripping."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "1" if value else "0"
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if math.isnan(value) else "inf"
    return repr(value) if isinstance(value, float) else str(value)


def _multiline(text: str) -> list[str]:
    return ["<<<|", *text.rstrip("\n").splitlines(), "|>>>"]


def _preamble(experiment: Experiment) -> list[str]:
    lines = [
        f"{experiment.library} version {experiment.version}",
        f"Experiment {experiment.name}",
        f"{len(experiment.properties)} experiment properties",
    ]
    lines += [f"{n} {t} = {_field(v)}" for n, (t, v) in experiment.properties.items()]
    lines += [f"Running on {experiment.host}", f"Starting at {experiment.date}"]
    lines += _multiline(experiment.setup) + _multiline(experiment.cpuinfo)
    lines += [
        f"{experiment.seed} is the random seed",
        f"{experiment.time_limit!r} seconds per run",
        f"{experiment.memory_limit!r} MB per run",
        f"{experiment.runs_per_planner} runs per planner",
        f"{experiment.total_time!r} seconds spent to collect the data",
        f"{len(experiment.enums)} enum type",
    ]
    lines += ["|".join([name, *values]) for name, values in experiment.enums.items()]
    return lines


def _planner(block: PlannerBlock) -> list[str]:
    lines = [block.name, f"{len(block.settings)} common properties"]
    lines += [f"{name} = {value}" for name, value in block.settings.items()]
    lines.append(f"{len(block.properties)} properties for each run")
    lines += [f"{name} {kind}" for name, kind in block.properties]
    lines.append(f"{len(block.runs)} runs")
    lines += ["".join(f"{_field(v)}; " for v in run) for run in block.runs]
    return [*lines, "."]


def benchmark_log(experiment: Experiment) -> str:
    """The experiment as the text of an OMPL benchmark log."""
    lines = _preamble(experiment) + [f"{len(experiment.planners)} planners"]
    for block in experiment.planners:
        lines += _planner(block)
    return "\n".join(lines) + "\n"


def benchmark_parser() -> Callable[..., None]:
    """OMPL's benchmark-log parser, ``readBenchmarkLog(database, logs, moveitformat)``.

    Raises
    ------
    DcsimError
        If OMPL's Python package is not installed.
    """
    try:
        from ompl.tools import readBenchmarkLog
    except ImportError:
        raise DcsimError(
            "writing the database needs OMPL's Python package: pip install 'dcsim[bench]'"
        ) from None
    return readBenchmarkLog


def write_database(logs: Sequence[Path], database: Path) -> None:
    """Parse benchmark logs with OMPL's own parser into a fresh SQLite database.

    Parameters
    ----------
    logs : sequence of Path
        Benchmark log files, one experiment each.
    database : Path
        The database to write; an existing file is replaced.

    Raises
    ------
    DcsimError
        If OMPL's Python package is not installed.
    """
    parse = benchmark_parser()
    database.parent.mkdir(parents=True, exist_ok=True)
    database.unlink(missing_ok=True)
    with contextlib.redirect_stdout(io.StringIO()):  # it prints a line per file and planner
        parse(str(database), [str(path) for path in logs], False)
