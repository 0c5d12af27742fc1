"""The words beside the viewer's scene: title, key numbers at every frame, the event log."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from dcsim.report.viewer.objects import Handling
from dcsim.report.viewer.robot import Thrusters
from dcsim.scenario.model import ManipulatorSection, Scenario

COLUMN_READOUTS = (
    ("fuel_used", "propellant used", "{:.3f} of {total} kg"),
    ("delta_v", "delta-v", "{:.3f} m/s"),
    ("nearest_obstacle", "nearest obstacle", "{:.2f} m"),
    ("goal_distance", "distance to goal", "{:.2f} m"),
    ("tracking_error", "tracking error", "{:.3f} m"),
    ("target_distance", "end effector to target", "{:.4f} m"),
    ("ee_error", "end-effector error", "{:.4f} m"),
)
"""Telemetry columns read out when present (and finite somewhere): column, label,
format (``{total}``: the propellant on board at the start, kg)."""

MAX_EVENTS = 2000
"""Events the page lists at most (the first ones)."""

_QUIET_EVENTS = frozenset({"mode"})


def title(scenario: Scenario) -> str:
    """The page's title: scenario, mission and robot."""
    return f"{scenario.name}: {scenario.mission.type} mission, {scenario.robot.type}"


def subtitle(summary: Mapping[str, Any]) -> str:
    """How the run ended and its outcome, from ``summary.json`` (empty without one)."""
    if not summary:
        return ""
    reason = f" ({summary['reason']})" if summary.get("reason") else ""
    outcome = f"; {summary['outcome']}" if summary.get("outcome") else ""
    return f"{summary.get('status', '')}{reason}{outcome}"


def readouts(
    scenario: Scenario,
    telemetry: Mapping[str, np.ndarray],
    rows: np.ndarray,
    handling: Handling,
    thrusters: Thrusters | None = None,
) -> list[dict[str, Any]]:
    """The key numbers at the frames' telemetry ``rows``, formatted with their units.

    Parameters
    ----------
    scenario : Scenario
        The run's scenario (mission, targets, propellant on board).
    telemetry : mapping of str to ndarray
        The run's telemetry.
    rows : ndarray (F,) of int
        The frames' rows.
    handling : Handling
        Grab and delivery times (targets captured and delivered).
    thrusters : Thrusters, optional
        The thrusters and their duty cycles at the frames.

    Returns
    -------
    list of dict
        ``{"label": str, "values": [str] * F}`` each: time, mode, speed (the base's for
        a manipulator), targets captured, delivered and carried (debris), then the
        columns of :data:`COLUMN_READOUTS` the telemetry has, the attitude error (degrees,
        when the reference held an attitude) and the thrusters firing (their numbers).
    """
    times = np.asarray(telemetry["time"], dtype=float)[rows]
    out = [_readout("time", times, "{:.2f} s")]
    if "mode" in telemetry:
        out.append({"label": "mode", "values": [str(m) for m in telemetry["mode"][rows]]})
    if all(name in telemetry for name in ("vx", "vy", "vz")):
        velocity = np.column_stack([telemetry[name][rows] for name in ("vx", "vy", "vz")])
        label = "base speed" if isinstance(scenario.robot, ManipulatorSection) else "speed"
        out.append(_readout(label, np.linalg.norm(velocity, axis=1), "{:.3f} m/s"))
    out += _handling(scenario, telemetry, rows, times, handling)
    total = f"{scenario.robot.propellant_mass:g}"
    for column, label, pattern in COLUMN_READOUTS:
        if column in telemetry and np.isfinite(telemetry[column][rows]).any():
            values = telemetry[column][rows]
            out.append(_readout(label, values, pattern.replace("{total}", total)))
    if "attitude_error" in telemetry and np.isfinite(telemetry["attitude_error"][rows]).any():
        error = np.degrees(telemetry["attitude_error"][rows])
        out.append(_readout("attitude error", error, "{:.3f} deg"))
    if thrusters is not None:
        out.append({"label": "thrusters firing", "values": _firing(thrusters.duty)})
    return out


def _firing(duty: np.ndarray) -> list[str]:
    """The numbers of the thrusters that fired at each frame (``duty`` (F, N)), or none."""
    return [", ".join(str(n + 1) for n in np.flatnonzero(row > 0)) or "none" for row in duty]


def _readout(label: str, values: np.ndarray, pattern: str) -> dict[str, Any]:
    texts = [pattern.format(v) if np.isfinite(v) else "none" for v in values.tolist()]
    return {"label": label, "values": texts}


def _handling(
    scenario: Scenario,
    telemetry: Mapping[str, np.ndarray],
    rows: np.ndarray,
    times: np.ndarray,
    handling: Handling,
) -> list[dict[str, Any]]:
    """Targets captured, delivered and carried, for missions that collect them."""
    total = len(scenario.mission.target_specs())
    if scenario.mission.type != "debris" or total == 0:
        return []
    captured, delivered = handling.counts(times)
    out = [
        {"label": "captured", "values": [f"{c} of {total}" for c in captured.tolist()]},
        {"label": "delivered", "values": [f"{d} of {total}" for d in delivered.tolist()]},
    ]
    if "carried" in telemetry:
        carried = telemetry["carried"][rows]
        out.append({"label": "carried", "values": [f"{c:.0f}" for c in carried.tolist()]})
    return out


def event_log(events: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """The event log as short lines ``{"t": s, "text": str}``, the first
    :data:`MAX_EVENTS` (mode changes left out: the mode is read out)."""
    shown = [e for e in events if e["event"] not in _QUIET_EVENTS][:MAX_EVENTS]
    return [{"t": float(e["t"]), "text": _event_text(e)} for e in shown]


def _event_text(event: Mapping[str, Any]) -> str:
    name = event["event"]
    if name == "plan":
        return (
            f"plan: {len(event.get('tasks') or ())} pickups, "
            f"{len(event.get('drops') or ())} drop visits"
        )
    if name == "grab":
        return f"grab target {event.get('target')}: {event.get('reason', '')}"
    if name == "path" and "duration" in event:
        delta_v = event.get("delta_v")
        delta_v = "" if delta_v is None else f", delta-v {delta_v:.3g} m/s"
        return f"path: {event['duration']:.1f} s, {event.get('length', 0.0):.1f} m{delta_v}"
    if name == "release":
        delivered = event.get("delivered") or []
        if delivered:
            return "delivered " + ", ".join(str(t) for t in delivered)
        return f"release refused: {event.get('reason', '')}"
    details = ", ".join(
        f"{k.replace('_', ' ')} {_short(v)}"
        for k, v in event.items()
        if k not in ("t", "event") and _short(v)
    )
    return f"{name.replace('_', ' ')}: {details}" if details else name.replace("_", " ")


def _short(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, dict | list):
        return ""
    return str(value)[:80]
