"""A run directory's records as the viewer reads them: scenario, telemetry, events, summary.

Tables (``telemetry.csv``, a transfer's ``trajectory.csv``) are read through
:func:`read_table`, the one place that maps column names with a unit suffix
(``x_m``, ``time_s``, ``fuel_used_kg``) to the plain names (``x``, ``time``,
``fuel_used``), so the viewer reads either style of header.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from dcsim.errors import DcsimError
from dcsim.run.recording import column_name
from dcsim.run.scripting import read_events, telemetry_frame
from dcsim.scenario import read_scenario
from dcsim.scenario.model import Scenario

_BRACKETED_UNIT = re.compile(r"^(?P<name>.+?)\s*\[[^\]]*\]$")  # ``time [s]``
_TEXT_COLUMNS = ("mode",)


class ViewError(DcsimError):
    """A run viewer page cannot be written: not a run directory, or records unreadable."""


@dataclass(frozen=True)
class RunRecords:
    """Everything the viewer reads from one run directory.

    Attributes
    ----------
    directory : Path
        The run directory.
    scenario : Scenario
        The resolved scenario (``scenario.yaml``).
    telemetry : dict of str to ndarray
        One array per telemetry column (plain names, no unit suffix), one row per
        control tick: floats, except ``mode`` (text).
    events : list of dict
        The event log, each with ``t`` (s) and ``event``.
    summary : dict
        ``summary.json`` (empty if missing or unreadable).
    planned : ndarray (M, 3)
        Positions of the last planned trajectory (a transfer's ``trajectory.csv``), m,
        world frame; empty (0, 3) without one.
    """

    directory: Path
    scenario: Scenario
    telemetry: dict[str, np.ndarray]
    events: list[dict[str, Any]]
    summary: dict[str, Any]
    planned: np.ndarray


def plain_name(column: str) -> str:
    """A column name without its unit: ``x_m`` → ``x`` (the suffixes of
    :data:`dcsim.run.recording.UNITS`), ``time [s]`` → ``time``."""
    column = column.strip()
    match = _BRACKETED_UNIT.match(column)
    return match.group("name") if match else column_name(column)


def read_table(path: Path) -> dict[str, np.ndarray]:
    """Read a CSV table of dcsim's (telemetry, trajectory) into arrays by plain column name.

    A last line cut short (a killed run was writing it) is left out.

    Parameters
    ----------
    path : Path
        The CSV file, with a header line.

    Returns
    -------
    dict of str to ndarray
        One array per column, named by :func:`plain_name`: floats (empty cells NaN),
        except ``mode`` (text).

    Raises
    ------
    ViewError
        If the file cannot be read or parsed as CSV.
    """
    try:
        frame = telemetry_frame(path)
    except (OSError, ValueError) as error:  # unreadable, not UTF-8, not CSV
        raise ViewError(f"cannot read {path}: {error}") from None
    if not len(frame.columns):
        raise ViewError(f"cannot read {path}: it is empty, not even a header line")
    table: dict[str, np.ndarray] = {}
    for column in frame.columns:
        name = plain_name(str(column))
        values = frame[column]
        table[name] = (
            values.fillna("").to_numpy(str)
            if name in _TEXT_COLUMNS
            else pd.to_numeric(values, errors="coerce").to_numpy(float)
        )
    return table


def read_run(directory: Path) -> RunRecords:
    """Read a run directory written by ``dcsim run``.

    Parameters
    ----------
    directory : Path
        The run directory: it holds ``scenario.yaml`` and ``telemetry.csv`` with at
        least one row; ``events.jsonl``, ``summary.json`` and ``trajectory.csv`` are
        read when present.

    Raises
    ------
    ViewError
        If ``directory`` is not a run directory or its records cannot be read.
    """
    if not directory.is_dir():
        raise ViewError(f"{directory} is not a run directory: no such folder")
    for name in ("scenario.yaml", "telemetry.csv"):
        if not (directory / name).is_file():
            raise ViewError(
                f"{directory} is not a run directory: it has no {name} (dcsim run writes one)"
            )
    telemetry = read_table(directory / "telemetry.csv")
    missing = [c for c in ("time", "x", "y", "z") if c not in telemetry]
    if missing:
        raise ViewError(f"{directory / 'telemetry.csv'} has no column {', '.join(missing)}")
    if not len(telemetry["time"]):
        raise ViewError(f"{directory / 'telemetry.csv'} has no rows yet: nothing to show")
    try:
        scenario = read_scenario(directory / "scenario.yaml")
    except DcsimError as error:
        raise ViewError(f"cannot read the run's scenario: {error}") from None
    return RunRecords(
        directory=directory,
        scenario=scenario,
        telemetry=telemetry,
        events=_events(directory / "events.jsonl"),
        summary=_read_summary(directory / "summary.json"),
        planned=_planned_positions(directory / "trajectory.csv"),
    )


def _events(path: Path) -> list[dict[str, Any]]:
    """The events of an ``events.jsonl`` (:func:`dcsim.run.scripting.read_events`); none if
    missing."""
    if not path.is_file():
        return []
    try:
        return read_events(path)
    except (OSError, ValueError) as error:
        raise ViewError(f"cannot read {path}: {error}") from None


def _read_summary(path: Path) -> dict[str, Any]:
    try:
        summary = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError):
        return {}
    return summary if isinstance(summary, dict) else {}


def _planned_positions(path: Path) -> np.ndarray:
    """Positions (M, 3) of a ``trajectory.csv``, m; (0, 3) without the file."""
    if not path.is_file():
        return np.zeros((0, 3))
    table = read_table(path)
    if not all(axis in table for axis in "xyz"):
        return np.zeros((0, 3))
    return np.column_stack([table[axis] for axis in "xyz"])
