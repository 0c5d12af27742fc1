"""What a run records, streamed to its run directory as it goes.

A run directory is useful at every instant: ``scenario.yaml`` (the resolved scenario)
and a ``summary.json`` with ``status: running`` are written before the first tick;
telemetry rows are appended to ``telemetry.csv`` in buffered blocks, flushed at least
every :data:`FLUSH_SECONDS` of wall time and at every event; events are appended to
``events.jsonl`` as they happen; the final ``summary.json`` replaces the first one
atomically at the end. Memory stays flat however long the run: no row is kept unless
the run records in memory only.

Telemetry and events are written deterministically (floats in their shortest
round-trip form), so the same scenario and seed give byte-identical files.
"""

from __future__ import annotations

import json
import os
import time as wallclock
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import IO, Any

import numpy as np

from dcsim.errors import DcsimError

FLUSH_SECONDS = 2.0
"""Longest wall time between two flushes of the telemetry, s."""

FLUSH_ROWS = 2000
"""Rows buffered at most before they are written."""

LEADING_COLUMNS = (
    "time",
    "x", "y", "z", "vx", "vy", "vz",
    "est_x", "est_y", "est_z", "est_vx", "est_vy", "est_vz",
    "qx", "qy", "qz", "qw",
    "mode", "converged",
)  # fmt: skip
"""The columns every run records before the mission's own (:func:`telemetry_columns`)."""
SIGMA_COLUMNS = ("est_sigma_x", "est_sigma_y", "est_sigma_z")
"""Standard deviations of the estimated position per axis (m): the square roots of the
diagonal of the estimate's covariance, position block."""

TRAILING_COLUMNS = (
    "fuel_used", "delta_v", "nearest_obstacle", "fx", "fy", "fz",
    "wx", "wy", "wz", *SIGMA_COLUMNS, "attitude_error",
)  # fmt: skip
"""The columns every run records after the mission's own, before any hardware's."""
_TEXT_COLUMNS = frozenset({"mode"})

UNITS = {
    "s": "s",
    "m": "m",
    "m6": "m⁶",
    "mps": "m/s",
    "rad": "rad",
    "radps": "rad/s",
    "kg": "kg",
    "N": "N",
    "Nm": "N·m",
    "Ns": "N·s",
    "Nms": "N·m·s",
}
"""The unit suffixes of ``telemetry.csv``'s header (``x_m``, ``vx_mps``), each with its unit."""

COLUMN_UNITS = {
    "time": "s",
    **dict.fromkeys(("x", "y", "z", "est_x", "est_y", "est_z", "nearest_obstacle"), "m"),
    **dict.fromkeys(("vx", "vy", "vz", "est_vx", "est_vy", "est_vz", "delta_v"), "mps"),
    "fuel_used": "kg",
    **dict.fromkeys(("fx", "fy", "fz"), "N"),
    **dict.fromkeys(("wx", "wy", "wz"), "radps"),
    **dict.fromkeys(SIGMA_COLUMNS, "m"),
    "attitude_error": "rad",
}
"""Unit suffix of each column every run records (a column absent has no unit)."""


class RecordingError(DcsimError):
    """The run directory could not be written (disk full, permissions, a vanished folder)."""


def wheel_columns(wheels: int) -> tuple[str, ...]:
    """The telemetry columns of ``wheels`` reaction wheels' momenta: ``wheel_h_1``, ...
    (N·m·s, about each wheel's spin axis, numbered in the order of
    ``robot.actuators.reaction_wheels``)."""
    return tuple(f"wheel_h_{i}" for i in range(1, wheels + 1))


def duty_columns(thrusters: int) -> tuple[str, ...]:
    """The telemetry columns of ``thrusters`` thrusters' duty cycles: ``duty_1``, ... (the
    fraction of the control period each fired, numbered in the order of
    ``robot.actuators.thrusters``)."""
    return tuple(f"duty_{i}" for i in range(1, thrusters + 1))


def telemetry_columns(
    mission_columns: Sequence[str], thrusters: int = 0, wheels: int = 0
) -> tuple[str, ...]:
    """Columns of ``telemetry.csv`` for a mission with its own ``mission_columns``.

    Every run records time (s); true and estimated position (m) and velocity (m/s);
    the attitude quaternion; the mission mode; localiser converged (0/1); then the
    mission's own columns (the debris mission's: targets carried and delivered); then
    propellant used (kg), delta-v (m/s), the surface gap to the nearest obstacle (m),
    the commanded thrust (N), the true angular velocity (world frame, rad/s) and the
    standard deviations of the estimated position (:data:`SIGMA_COLUMNS`, m; 0 when
    the mission flies on the true state), the angle from the true attitude to the
    reference's (rad; nan when the reference leaves the attitude free); last, with
    ``wheels`` reaction wheels, each
    wheel's momentum (:func:`wheel_columns`, N·m·s), and with ``thrusters`` thrusters,
    each one's duty cycle (:func:`duty_columns`).
    """
    hardware = (*wheel_columns(wheels), *duty_columns(thrusters))
    return (*LEADING_COLUMNS, *mission_columns, *TRAILING_COLUMNS, *hardware)


def telemetry_units(mission_units: Mapping[str, str], wheels: int = 0) -> dict[str, str]:
    """Unit suffix of each telemetry column: :data:`COLUMN_UNITS`, the mission's own and
    those of ``wheels`` reaction wheels' momenta (thrusters' duty cycles have none)."""
    return {**COLUMN_UNITS, **mission_units, **dict.fromkeys(wheel_columns(wheels), "Nms")}


def header_name(column: str, unit: str = "") -> str:
    """A column's name in ``telemetry.csv``'s header: ``column_unit``, or ``column`` alone.

    Parameters
    ----------
    column : str
        The column's name in a telemetry row (``x``, ``delta_v``).
    unit : str
        Its unit suffix, a key of :data:`UNITS` (``m``, ``mps``); empty for a count, a
        flag, a text or a dimensionless number.

    Raises
    ------
    ValueError
        For an unknown unit, or a column without one whose name ends like a unit suffix
        (the header could not be read back).
    """
    if unit and unit not in UNITS:
        raise ValueError(f"unknown unit {unit!r} of telemetry column {column!r}: use {list(UNITS)}")
    name = f"{column}_{unit}" if unit else column
    if column_name(name) != column:
        raise ValueError(f"telemetry column {column!r} without a unit ends like a unit suffix")
    return name


def column_name(header: str) -> str:
    """A telemetry column's row name from its header name: ``vx_mps`` → ``vx``."""
    return _split_unit(header)[0]


def column_unit(header: str) -> str:
    """The unit of a header name (``vx_mps`` → ``m/s``); empty when it has none."""
    return UNITS.get(_split_unit(header)[1], "")


def _split_unit(header: str) -> tuple[str, str]:
    """A header name's row name and unit suffix (empty when it has none)."""
    stem, _, suffix = header.rpartition("_")
    return (stem, suffix) if stem and suffix in UNITS else (header, "")


def _json_value(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return [_json_value(v) for v in value.tolist()]
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, float) and not np.isfinite(value):
        return None
    if isinstance(value, list | tuple):
        return [_json_value(v) for v in value]
    return value


def to_json(data: Mapping[str, Any]) -> str:
    """One line of JSON with numpy values converted and non-finite floats as null."""
    return json.dumps({k: _json_value(v) for k, v in data.items()}, separators=(", ", ": "))


def write_summary(out_dir: Path, summary: Mapping[str, Any]) -> None:
    """Write ``summary.json`` atomically: readers see the old file or the new, never half.

    Raises
    ------
    RecordingError
        If the file cannot be written.
    """
    text = json.dumps({k: _json_value(v) for k, v in summary.items()}, indent=2) + "\n"
    temporary = out_dir / ".summary.json.tmp"
    try:
        temporary.write_text(text, encoding="utf-8")
        os.replace(temporary, out_dir / "summary.json")
    except OSError as error:
        raise RecordingError(f"cannot write {out_dir / 'summary.json'}: {error}") from error


class Recorder:
    """Streams telemetry rows and events into a run directory, or keeps them in memory.

    Parameters
    ----------
    out_dir : Path or None
        Run directory, created if missing (:func:`dcsim.run.directory.prepare_run_directory`
        checks one before a run); None records in memory only.
    columns : sequence of str
        The telemetry columns (:func:`telemetry_columns`).
    keep_rows : bool, optional
        Keep every row in :attr:`rows` as well; by default only when there is no run
        directory.
    units : mapping of str to str, optional
        Unit suffix of each column that has one (:func:`telemetry_units`), written into
        the header of ``telemetry.csv``; the rows keep the bare column names.

    Attributes
    ----------
    header : tuple of str
        The columns' names in the header of ``telemetry.csv`` (:func:`header_name`).
    rows : list of dict
        The rows kept in memory (empty unless ``keep_rows``).
    events : list of dict
        Every event so far.
    count : int
        Rows recorded so far.
    """

    def __init__(
        self,
        out_dir: Path | None,
        columns: Sequence[str],
        keep_rows: bool | None = None,
        units: Mapping[str, str] | None = None,
    ) -> None:
        self.out_dir = out_dir
        self.columns = tuple(columns)
        units = units or {}
        self.header = tuple(header_name(c, units.get(c, "")) for c in self.columns)
        self.keep_rows = out_dir is None if keep_rows is None else keep_rows
        self.rows: list[dict[str, Any]] = []
        self.events: list[dict[str, Any]] = []
        self.count = 0
        self._pending: list[str] = []
        self._flushed_at = wallclock.perf_counter()
        self._telemetry_file: IO[str] | None = None
        self._events_file: IO[str] | None = None

    def start(self, scenario_yaml: str, summary: Mapping[str, Any]) -> None:
        """Write ``scenario.yaml`` and the first ``summary.json``; open the streams."""
        if self.out_dir is None:
            return
        with self._writing("scenario.yaml"):
            self.out_dir.mkdir(parents=True, exist_ok=True)
            (self.out_dir / "scenario.yaml").write_text(scenario_yaml, encoding="utf-8")
        write_summary(self.out_dir, summary)
        with self._writing("telemetry.csv"):
            self._telemetry_file = (self.out_dir / "telemetry.csv").open("w", encoding="utf-8")
            self._telemetry_file.write(",".join(self.header) + "\n")
            self._telemetry_file.flush()
        with self._writing("events.jsonl"):
            self._events_file = (self.out_dir / "events.jsonl").open("w", encoding="utf-8")

    def row(self, values: dict[str, Any]) -> None:
        """Record one telemetry row (a value for every column)."""
        self.count += 1
        if self.keep_rows:
            self.rows.append(values)
        if self._telemetry_file is None:
            return
        self._pending.append(",".join(map(_cell, map(values.__getitem__, self.columns))))
        if len(self._pending) >= FLUSH_ROWS or (
            wallclock.perf_counter() - self._flushed_at > FLUSH_SECONDS
        ):
            self.flush()

    @property
    def waiting_rows(self) -> int:
        """Rows recorded but not yet written to ``telemetry.csv`` (fewer than
        :data:`FLUSH_ROWS`)."""
        return len(self._pending)

    def event(self, values: dict[str, Any]) -> None:
        """Record one event: append it to ``events.jsonl`` and flush the telemetry."""
        self.events.append(values)
        if self._events_file is None:
            return
        with self._writing("events.jsonl"):
            self._events_file.write(to_json(values) + "\n")
            self._events_file.flush()
        self.flush()

    def flush(self) -> None:
        """Write the buffered telemetry rows to the file."""
        self._flushed_at = wallclock.perf_counter()
        if self._telemetry_file is None or not self._pending:
            return
        lines, self._pending = self._pending, []
        with self._writing("telemetry.csv"):
            self._telemetry_file.write("\n".join(lines) + "\n")
            self._telemetry_file.flush()

    def telemetry(self, max_points: int | None = None) -> dict[str, np.ndarray]:
        """The telemetry so far, one array per column.

        From memory when rows are kept, else read back from ``telemetry.csv``.

        Parameters
        ----------
        max_points : int, optional
            Keep at most about this many rows, evenly spaced (the first and the last
            always), for plots.
        """
        if self.keep_rows or self.out_dir is None:
            rows = self.rows[:: _stride(len(self.rows), max_points)]
            return _columns(self.columns, rows)
        self.flush()
        return read_telemetry(self.out_dir / "telemetry.csv", max_points)

    def write_file(self, name: str, text: str) -> None:
        """Write one more file of the run directory (nothing when recording in memory)."""
        if self.out_dir is None:
            return
        with self._writing(name):
            (self.out_dir / name).write_text(text, encoding="utf-8")

    def finish(self, summary: Mapping[str, Any]) -> None:
        """Flush and close the streams, then replace ``summary.json`` with the final one."""
        try:
            self.flush()
        finally:
            self._close()
        if self.out_dir is not None:
            write_summary(self.out_dir, summary)

    def _close(self) -> None:
        for stream in (self._telemetry_file, self._events_file):
            if stream is not None:
                try:
                    stream.close()
                except OSError:
                    pass  # what could be written is on disk; the run already failed
        self._telemetry_file = self._events_file = None

    def _writing(self, name: str) -> _WriteGuard:
        assert self.out_dir is not None  # only a run directory is written to
        return _WriteGuard(self, self.out_dir / name)


class _WriteGuard:
    """Turns an OSError while writing a run file into a :class:`RecordingError`.

    After the first failure the recorder stops writing (what is on disk stays) but keeps
    recording in memory, so the run can end ``failed`` with its reason.
    """

    def __init__(self, recorder: Recorder, path: Path) -> None:
        self.recorder, self.path = recorder, path

    def __enter__(self) -> None:
        return None

    def __exit__(self, kind: type | None, error: BaseException | None, trace: Any) -> None:
        if isinstance(error, OSError):
            recorder = self.recorder
            recorder._close()
            recorder._pending.clear()
            raise RecordingError(f"cannot write {self.path}: {error}") from error


def _stride(rows: int, max_points: int | None) -> int:
    """Step between kept rows so that about ``max_points`` of ``rows`` remain."""
    if max_points is None or rows <= max_points:
        return 1
    return -(-rows // max_points)


def _columns(columns: Sequence[str], rows: Sequence[Mapping[str, Any]]) -> dict[str, np.ndarray]:
    return {c: np.array([r[c] for r in rows]) for c in columns}


def read_telemetry(path: Path, max_points: int | None = None) -> dict[str, np.ndarray]:
    """Read a ``telemetry.csv``, tolerating a last line cut short by a killed run.

    Parameters
    ----------
    path : Path
        The file.
    max_points : int, optional
        Keep about this many rows, evenly spaced, plus the first and last and the rows
        on both sides of every change of ``mode``; the thrusters' duty cycles of a kept
        row are their mean over the rows since the previous kept one. The file is
        streamed, so memory follows ``max_points``, not the file's length.

    Returns
    -------
    dict of str to ndarray
        One array per column, by its row name (the header's name without its unit
        suffix, :func:`column_name`): floats, except ``mode`` (text).
    """
    step = 1 if max_points is None else _stride(count_lines(path) - 1, max_points)
    kept: list[list[str]] = []
    last: list[str] | None = None
    last_kept = False
    with path.open(encoding="utf-8") as stream:
        header = [column_name(h) for h in stream.readline().rstrip("\n").split(",")]
        mode = header.index("mode") if "mode" in header else None
        window = _Window([i for i, name in enumerate(header) if name.startswith("duty_")])
        for index, text in enumerate(stream):
            fields = text.rstrip("\n").split(",")
            if not text.endswith("\n") or len(fields) != len(header):
                continue  # the line a killed run was writing
            switched = mode is not None and last is not None and fields[mode] != last[mode]
            if switched and last is not None and not last_kept:
                kept.append(window.close(last))  # a mode change stays sharp however thin
            window.add(fields)
            last_kept = index % step == 0 or switched
            if last_kept:
                kept.append(window.close(fields))
            last = fields
    if last is not None and not last_kept:
        kept.append(window.close(last))
    return _parse(header, kept)


class _Window:
    """The rows a thinned row stands for: its duty cycles (columns ``duty_i``) become
    their mean over the rows since the previous kept row, so that firings between kept
    rows still show, each with its weight.

    Parameters
    ----------
    columns : list of int
        Positions of the averaged columns in a row.
    """

    def __init__(self, columns: list[int]) -> None:
        self._columns = columns
        self._sums = [0.0] * len(columns)
        self._count = 0

    def add(self, fields: list[str]) -> None:
        """Count one row."""
        if self._columns:
            self._sums = [
                s + float(fields[i]) for s, i in zip(self._sums, self._columns, strict=True)
            ]
            self._count += 1

    def close(self, fields: list[str]) -> list[str]:
        """``fields`` with the averaged columns replaced by the window's means; a new
        window starts."""
        if not self._columns or self._count == 0:
            return fields
        fields = list(fields)
        for total, i in zip(self._sums, self._columns, strict=True):
            fields[i] = repr(total / self._count)
        self._sums, self._count = [0.0] * len(self._columns), 0
        return fields


def count_lines(path: Path) -> int:
    """Number of line ends in a file, read in blocks (the file is not held in memory)."""
    count = 0
    with path.open("rb") as stream:
        while block := stream.read(1 << 20):
            count += block.count(b"\n")
    return count


def _parse(header: Sequence[str], lines: Sequence[Sequence[str]]) -> dict[str, np.ndarray]:
    table: dict[str, np.ndarray] = {}
    for index, name in enumerate(header):
        values = [line[index] for line in lines]
        table[name] = np.array(values) if name in _TEXT_COLUMNS else np.array(values, float)
    return table


def _cell(value: Any) -> str:
    """A telemetry value as CSV text: floats by their shortest round-trip repr."""
    if type(value) is float:  # nearly every cell
        return repr(value)
    if isinstance(value, np.floating):
        return repr(float(value))
    return str(value)
