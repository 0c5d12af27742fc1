"""What a run records: telemetry rows, the event log, the summary.

Telemetry and events are written deterministically (floats in their shortest
round-trip form), so the same scenario and seed give byte-identical files.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import IO, Any

import numpy as np

_LEADING_COLUMNS = (
    "time",
    "x", "y", "z", "vx", "vy", "vz",
    "est_x", "est_y", "est_z", "est_vx", "est_vy", "est_vz",
    "qx", "qy", "qz", "qw",
    "mode", "converged",
)  # fmt: skip
_TRAILING_COLUMNS = ("fuel_used", "delta_v", "nearest_obstacle", "fx", "fy", "fz")


def telemetry_columns(mission_columns: Sequence[str]) -> tuple[str, ...]:
    """Columns of ``telemetry.csv`` for a mission with its own ``mission_columns``.

    Every run records time (s); true and estimated position (m) and velocity (m/s);
    the attitude quaternion; the mission mode; localiser converged (0/1); then the
    mission's own columns (the debris mission's: targets carried and delivered); then
    propellant used (kg), delta-v (m/s), the surface gap to the nearest obstacle (m)
    and the commanded thrust (N).
    """
    return (*_LEADING_COLUMNS, *mission_columns, *_TRAILING_COLUMNS)


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


class Recorder:
    """Collects telemetry rows and events, and writes them into a run directory.

    Parameters
    ----------
    out_dir : Path or None
        Run directory; None keeps everything in memory only.
    columns : sequence of str
        The telemetry columns (:func:`telemetry_columns`).
    """

    def __init__(self, out_dir: Path | None, columns: Sequence[str]) -> None:
        self.out_dir = out_dir
        self.columns = tuple(columns)
        self.rows: list[dict[str, Any]] = []
        self.events: list[dict[str, Any]] = []
        self._events_file: IO[str] | None = None
        if out_dir is not None:
            out_dir.mkdir(parents=True, exist_ok=True)
            self._events_file = (out_dir / "events.jsonl").open("w", encoding="utf-8")

    def row(self, values: dict[str, Any]) -> None:
        """Keep one telemetry row (a value for every column)."""
        self.rows.append(values)

    def event(self, values: dict[str, Any]) -> None:
        """Keep one event and append it to ``events.jsonl`` straight away."""
        self.events.append(values)
        if self._events_file is not None:
            self._events_file.write(to_json(values) + "\n")
            self._events_file.flush()

    def telemetry(self) -> dict[str, np.ndarray]:
        """The telemetry so far as one array per column."""
        return {c: np.array([r[c] for r in self.rows]) for c in self.columns}

    def write(self, summary: Mapping[str, Any], scenario_yaml: str) -> None:
        """Write ``scenario.yaml``, ``telemetry.csv`` and ``summary.json``; close the log."""
        if self._events_file is not None:
            self._events_file.close()
            self._events_file = None
        if self.out_dir is None:
            return
        (self.out_dir / "scenario.yaml").write_text(scenario_yaml, encoding="utf-8")
        with (self.out_dir / "telemetry.csv").open("w", encoding="utf-8") as out:
            out.write(",".join(self.columns) + "\n")
            for row in self.rows:
                out.write(",".join(_cell(row[c]) for c in self.columns) + "\n")
        text = json.dumps({k: _json_value(v) for k, v in summary.items()}, indent=2)
        (self.out_dir / "summary.json").write_text(text + "\n", encoding="utf-8")


def _cell(value: Any) -> str:
    if isinstance(value, float | np.floating):
        return repr(float(value))
    return str(value)
