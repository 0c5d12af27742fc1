"""Pictures of a reach run, after the space manipulator thesis's Figs 7.5–7.10 and 7.14–7.20.

``path.png``: the end effector's path in 3-D, flown and reference, from its start (blue)
to the target (green), with the base's centre of mass drifting beside it, and the three
components over time.

``timeline.png``: the end-effector tracking error and distance to the target, det(J Jᵀ)
of the arm's position Jacobian (zero at a singularity), the angle between the base's
target-facing side and the target (60° is the thesis's sight limit), the base's
displacement against half the end effector's (the thesis's criterion), the commanded
base torque and joint torques, and the change of total linear and angular momentum; then
the base's attitude error, when its reference holds an attitude (the panels every
timeline ends with, :mod:`dcsim.report.hardware`, and the wheel momenta and thruster
duty cycles of a base with that hardware).

``joints.png``: every joint angle and its reference (±90° are the thesis's mechanical
limits) and the largest joint tracking error.

A dotted vertical line marks the end of the planned path. Drawn with matplotlib's
non-interactive Agg backend, as :mod:`dcsim.report.plots` is.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (the backend must be chosen first)
import numpy as np  # noqa: E402

from dcsim.missions.reach.settings import ReachMissionSection  # noqa: E402
from dcsim.report.hardware import hardware_panels  # noqa: E402
from dcsim.report.plots import (  # noqa: E402
    FrameAxes,
    numbered_columns,
    plots_folder,
    save,
    stacked,
)
from dcsim.scenario.model import Scenario  # noqa: E402

SIGHT_LIMIT_DEG = 60.0
"""Largest angle between the base's target-facing side and the target (thesis §5.4)."""

JOINT_LIMIT_DEG = 90.0
"""Joint angle magnitude the thesis's planner keeps within (§5.4)."""

_FLOWN = "tab:blue"
_REFERENCE = "k"
_START = "tab:blue"
_TARGET = "tab:green"
_BASE = "tab:red"


def write_reach_plots(
    out_dir: Path,
    scenario: Scenario,
    telemetry: Mapping[str, np.ndarray],
    events: Sequence[Mapping[str, Any]],
) -> list[Path]:
    """Draw ``path.png``, ``timeline.png`` and ``joints.png`` into ``out_dir/plots``.

    Parameters
    ----------
    out_dir : Path
        The run directory.
    scenario : Scenario
        The resolved scenario of a ``reach`` mission.
    telemetry : mapping of str to ndarray
        The telemetry columns (thinned for plotting).
    events : sequence of mapping
        The event log: the planned path's duration comes from its ``path`` event.

    Returns
    -------
    list of Path
        The files written (none if there is no telemetry).
    """
    folder = plots_folder(out_dir, telemetry)
    if folder is None:
        return []
    path_end = _path_end(events)
    title = f"{scenario.name} ({scenario.controller.plugin})"
    paths = [folder / "path.png", folder / "timeline.png", folder / "joints.png"]
    _path_figure(paths[0], scenario, telemetry, path_end, title)
    _timeline_figure(paths[1], scenario, telemetry, path_end, title)
    _joints_figure(paths[2], telemetry, path_end, title)
    return paths


def _path_end(events: Sequence[Mapping[str, Any]]) -> float | None:
    """When the planned path ends, s (None without a path)."""
    for event in events:
        if event.get("event") == "path":
            return float(event["t"]) + float(event["duration"])
    return None


def _mark_end(axis, path_end: float | None) -> None:
    if path_end is not None:
        axis.axvline(path_end, color="0.4", ls=":", lw=1.0)


def _path_figure(
    path: Path,
    scenario: Scenario,
    telemetry: Mapping[str, np.ndarray],
    path_end: float | None,
    title: str,
) -> None:
    times = telemetry["time"]
    flown = stacked(telemetry, ("ee_x", "ee_y", "ee_z"))
    reference = stacked(telemetry, ("ref_ee_x", "ref_ee_y", "ref_ee_z"))
    base = stacked(telemetry, ("x", "y", "z"))
    target = np.asarray(scenario.mission_as(ReachMissionSection).target, dtype=float)
    figure = plt.figure(figsize=(13, 6))
    axis = figure.add_subplot(1, 2, 1, projection="3d")
    axis.plot(*reference.T, color=_REFERENCE, ls="--", lw=1.0, label="reference")
    axis.plot(*flown.T, color=_FLOWN, lw=1.5, label="end effector (flown)")
    drift = base - base[0] + flown[0]
    axis.plot(*drift.T, color=_BASE, lw=1.0, label="base displacement (from the start point)")
    axis.scatter(*flown[0], color=_START, s=40, label="start")
    axis.scatter(*target, color=_TARGET, s=40, label="target")
    frame = FrameAxes.of(scenario, flown)
    frame.name_axes(axis, (0, 1, 2))
    axis.set_title("End-effector path")
    axis.legend(loc="upper center", bbox_to_anchor=(0.5, 0.0), ncol=3, fontsize=8)
    for row in range(3):
        component = figure.add_subplot(3, 2, 2 * row + 2)
        component.plot(times, reference[:, row], color=_REFERENCE, ls="--", lw=1.0)
        component.plot(times, flown[:, row], color=_FLOWN, lw=1.2)
        component.axhline(target[row], color=_TARGET, lw=0.8)
        _mark_end(component, path_end)
        frame.name_axes(component, (row,), letters="y")
        component.grid(alpha=0.3)
    component.set_xlabel("time [s]")
    figure.suptitle(f"{title}: end effector (dashed: reference; green: target)")
    figure.tight_layout()
    save(figure, path)


def _timeline_figure(
    path: Path,
    scenario: Scenario,
    telemetry: Mapping[str, np.ndarray],
    path_end: float | None,
    title: str,
) -> None:
    times = telemetry["time"]
    extra = hardware_panels(telemetry, scenario)
    rows = 4 + -(-len(extra) // 2)
    figure, axes = plt.subplots(rows, 2, figsize=(13, 12 + 2.4 * (rows - 4)), sharex=True)
    axes = axes.ravel()
    for axis, draw in zip(axes[8:], extra, strict=False):
        draw(axis)
    axes[0].semilogy(times, np.maximum(telemetry["ee_error"], 1e-12), color=_FLOWN)
    axes[0].set(ylabel="error [m]", title="End-effector tracking error |flown - reference|")
    axes[1].semilogy(times, np.maximum(telemetry["target_distance"], 1e-12), color=_FLOWN)
    axes[1].axhline(scenario.mission_as(ReachMissionSection).tolerance, color="k", ls="--", lw=0.8)
    axes[1].set(ylabel="distance [m]", title="End effector to target (dashed: tolerance)")
    axes[2].plot(times, telemetry["det_jjt"], color=_FLOWN)
    axes[2].set(ylabel="det(J Jᵀ) [m⁶]", title="Singularity measure (0: singular)")
    axes[2].set_ylim(bottom=0.0)
    axes[3].plot(times, np.degrees(telemetry["target_angle"]), color=_FLOWN)
    axes[3].axhline(SIGHT_LIMIT_DEG, color="k", ls="--", lw=0.8)
    axes[3].set(ylabel="angle [deg]", title="Base's target-facing side to target (limit 60°)")
    axes[4].plot(times, telemetry["base_displacement"], color=_BASE, label="base")
    axes[4].plot(
        times, 0.5 * telemetry["ee_displacement"], color=_FLOWN, label="half the end effector's"
    )
    axes[4].set(ylabel="displacement [m]", title="Displacement from the start")
    axes[4].legend(fontsize=8)
    _torques(axes[5], telemetry)
    _momentum(axes[6], axes[7], telemetry)
    for axis in axes[8 + len(extra) :]:
        axis.set_visible(False)
    for axis in axes[: 8 + len(extra)]:
        _mark_end(axis, path_end)
        axis.grid(alpha=0.3)
    for axis in axes[8 + len(extra) - 2 : 8 + len(extra)]:  # the bottom of each column
        axis.xaxis.set_tick_params(labelbottom=True)
        axis.set_xlabel("time [s]")
    figure.suptitle(f"{title}: timeline (dotted: end of the planned path)")
    figure.tight_layout()
    save(figure, path)


def _torques(axis, telemetry: Mapping[str, np.ndarray]) -> None:
    times = telemetry["time"]
    base = np.linalg.norm(stacked(telemetry, ("tx", "ty", "tz")), axis=1)
    axis.plot(times, base, color="k", lw=1.4, label="base |τ|")
    for i, name in enumerate(numbered_columns(telemetry, "joint_torque_"), 1):
        axis.plot(times, telemetry[name], lw=0.9, label=f"joint {i}")
    thrust = np.linalg.norm(stacked(telemetry, ("fx", "fy", "fz")), axis=1)
    axis.plot(times, thrust, color="0.5", ls="--", lw=1.0, label="base thrust |F| [N]")
    axis.set(ylabel="torque [N·m]", title="Commands")
    axis.legend(fontsize=7, ncol=3)


def _momentum(linear_axis, angular_axis, telemetry: Mapping[str, np.ndarray]) -> None:
    times = telemetry["time"]
    for axis, names, unit, what in (
        (linear_axis, ("px", "py", "pz"), "kg·m/s", "linear"),
        (angular_axis, ("hx", "hy", "hz"), "kg·m²/s", "angular (about the origin)"),
    ):
        values = stacked(telemetry, names)
        change = np.linalg.norm(values - values[0], axis=1)
        axis.plot(times, change, color=_FLOWN)
        axis.set(ylabel=f"change [{unit}]", title=f"Total {what} momentum: change from the start")


def _joints_figure(
    path: Path, telemetry: Mapping[str, np.ndarray], path_end: float | None, title: str
) -> None:
    times = telemetry["time"]
    joints = numbered_columns(telemetry, "joint_")
    figure, axes = plt.subplots(2, 1, figsize=(11, 9), sharex=True)
    colours = plt.get_cmap("tab10")
    for i, name in enumerate(joints):
        axes[0].plot(times, np.degrees(telemetry[f"ref_{name}"]), color=colours(i), ls="--", lw=1.0)
        axes[0].plot(
            times, np.degrees(telemetry[name]), color=colours(i), lw=1.2, label=f"joint {i + 1}"
        )
    for limit in (-JOINT_LIMIT_DEG, JOINT_LIMIT_DEG):
        axes[0].axhline(limit, color="k", ls=":", lw=0.8)
    axes[0].set(ylabel="angle [deg]", title="Joint angles (dashed: reference; dotted: ±90°)")
    axes[0].legend(loc="lower center", fontsize=8, ncol=len(joints))
    axes[1].semilogy(times, np.maximum(np.degrees(telemetry["joint_error"]), 1e-12), color=_FLOWN)
    axes[1].set(ylabel="error [deg]", xlabel="time [s]", title="Largest joint tracking error")
    for axis in axes:
        _mark_end(axis, path_end)
        axis.grid(alpha=0.3)
    figure.suptitle(f"{title}: joints")
    figure.tight_layout()
    save(figure, path)
