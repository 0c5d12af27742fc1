"""Pictures of a run: the trajectory (3-D and top view) and a timeline.

The top view outlines each box and cylinder where its path starts and ends (spheres
are drawn by their paths alone).

Drawn with matplotlib's non-interactive Agg backend into the run's ``plots/`` folder.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (the backend must be chosen first)
import numpy as np  # noqa: E402

from dcsim.messages import Shape, ShapeKind  # noqa: E402
from dcsim.motion import MotionSet  # noqa: E402
from dcsim.scenario.model import Scenario  # noqa: E402
from dcsim.shape_outlines import outline  # noqa: E402
from dcsim.world.objects import build_objects  # noqa: E402


def write_plots(
    out_dir: Path,
    scenario: Scenario,
    telemetry: Mapping[str, np.ndarray],
    events: Sequence[Mapping[str, Any]],
    modes: Sequence[str],
    safety_distance: float,
) -> list[Path]:
    """Draw ``trajectory.png`` and ``timeline.png`` into ``out_dir/plots``.

    Parameters
    ----------
    out_dir : Path
        The run directory.
    scenario : Scenario
        The resolved scenario (objects, drop point).
    telemetry : mapping of str to ndarray
        The telemetry columns.
    events : sequence of mapping
        The event log.
    modes : sequence of str
        The mission's modes, in the order the timeline shows them.
    safety_distance : float
        Gap marked on the obstacle-distance panel, m.

    Returns
    -------
    list of Path
        The files written (none if there is no telemetry).
    """
    folder = plots_folder(out_dir, telemetry)
    if folder is None:
        return []
    paths = [folder / "trajectory.png", folder / "timeline.png"]
    _trajectory(paths[0], scenario, telemetry, events)
    _timeline(paths[1], telemetry, tuple(modes), safety_distance)
    return paths


def plots_folder(out_dir: Path, telemetry: Mapping[str, np.ndarray]) -> Path | None:
    """``out_dir/plots``, created; None when the telemetry has no row to draw."""
    if len(telemetry["time"]) == 0:
        return None
    folder = out_dir / "plots"
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def stacked(telemetry: Mapping[str, np.ndarray], names: Sequence[str]) -> np.ndarray:
    """Telemetry columns ``names`` side by side as floats, (rows, len(names))."""
    return np.column_stack([np.asarray(telemetry[name], dtype=float) for name in names])


def _object_paths(scenario: Scenario, times: np.ndarray, events: Sequence[Mapping[str, Any]]):
    """Each object's path over the run, targets cut at their grab."""
    grabbed = {e["target"]: e["t"] for e in events if e["event"] == "grab" and e["success"]}
    objects = build_objects(scenario)
    motions = MotionSet([o.motion for o in objects])
    sampled = [motions.state_at(float(t))[0] for t in times]
    positions = np.stack(sampled, axis=1) if objects else np.zeros((0, len(times), 3))
    for obj, path in zip(objects, positions, strict=True):
        end = grabbed.get(obj.id, np.inf)
        yield obj, path[times <= end]


def _trajectory(path: Path, scenario: Scenario, telemetry, events) -> None:
    times = telemetry["time"]
    step = max(1, len(times) // 400)
    sample = times[::step]
    true = stacked(telemetry, ("x", "y", "z"))
    estimate = stacked(telemetry, ("est_x", "est_y", "est_z"))
    drop = scenario.drop_point.build(scenario.mean_motion).state_at(sample)[0]
    grabs = [e["t"] for e in events if e["event"] == "grab" and e["success"]]
    grab_points = true[np.searchsorted(times, grabs)] if grabs else np.zeros((0, 3))
    figure = plt.figure(figsize=(13, 6))
    ax3d = figure.add_subplot(1, 2, 1, projection="3d")
    top = figure.add_subplot(1, 2, 2)
    for obj, obj_path in _object_paths(scenario, sample, events):
        colour = "tab:green" if obj.kind.value == "target" else "tab:red"
        ax3d.plot(*obj_path.T, color=colour, lw=0.8, alpha=0.7)
        top.plot(obj_path[:, 0], obj_path[:, 1], color=colour, lw=0.8, alpha=0.7)
        if len(obj_path):
            top.annotate(str(obj.id), obj_path[0, :2], fontsize=7, color=colour)
            if obj.shape.kind is not ShapeKind.SPHERE:
                _draw_footprint(top, obj.shape, obj_path[[0, -1], :2], colour)
    ax3d.plot(*true.T, color="tab:blue", lw=1.5, label="collector")
    top.plot(true[:, 0], true[:, 1], color="tab:blue", lw=1.5, label="collector (true)")
    top.plot(
        estimate[:, 0],
        estimate[:, 1],
        color="tab:cyan",
        lw=0.8,
        ls=":",
        label="collector (estimated)",
    )
    for axis in (ax3d, top):
        coords = grab_points.T if axis is ax3d else grab_points[:, :2].T
        axis.scatter(
            *coords, marker="*", s=120, color="gold", edgecolor="k", zorder=5, label="grab"
        )
        drop_coords = drop.T if axis is ax3d else drop[:, :2].T
        axis.plot(*drop_coords, color="k", lw=1)
        axis.scatter(*(c[:1] for c in drop_coords), marker="X", s=90, color="k", label="drop point")
    top.plot([], [], color="tab:green", label="targets")
    top.plot([], [], color="tab:red", label="obstacles")
    ax3d.set(xlabel="x [m]", ylabel="y [m]", zlabel="z [m]", title="Trajectory")
    top.set(xlabel="x [m]", ylabel="y [m]", title="Top view (x-y)", aspect="equal")
    top.legend(fontsize=8, loc="best")
    figure.suptitle(f"{scenario.name}: frame {scenario.world.frame}")
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def _draw_footprint(axis, shape: Shape, centres: np.ndarray, colour: str) -> None:
    """Outline ``shape``'s top view (x-y) about each of ``centres`` (K, 2), m."""
    footprint = outline(shape)
    for centre in np.unique(centres, axis=0):
        axis.fill(*(centre + footprint).T, facecolor=colour, edgecolor=colour, alpha=0.3, lw=0.8)


def _timeline(path: Path, telemetry, modes: tuple[str, ...], safety_distance: float) -> None:
    times = telemetry["time"]
    error = np.linalg.norm(
        np.column_stack(
            [
                telemetry[a] - telemetry[b]
                for a, b in (("x", "est_x"), ("y", "est_y"), ("z", "est_z"))
            ]
        ),
        axis=1,
    )
    converged = telemetry["converged"].astype(bool)
    indices = np.array([modes.index(m) for m in telemetry["mode"]])
    figure, axes = plt.subplots(4, 1, figsize=(11, 9), sharex=True)
    axes[0].step(times, indices, where="post", color="tab:purple")
    axes[0].set_yticks(range(len(modes)), modes, fontsize=7)
    axes[0].set_title("Mission mode")
    axes[1].plot(times, telemetry["fuel_used"], color="tab:orange", label="propellant used [kg]")
    twin = axes[1].twinx()
    twin.plot(times, telemetry["delta_v"], color="tab:brown", ls="--", label="delta-v [m/s]")
    axes[1].set_ylabel("propellant [kg]")
    twin.set_ylabel("delta-v [m/s]")
    axes[1].set_title("Fuel")
    axes[2].semilogy(times[converged], np.maximum(error[converged], 1e-6), color="tab:blue", lw=0.8)
    axes[2].set(ylabel="error [m]", title="Localisation error |true - estimated|")
    obstacle_panel(axes[3], times, telemetry["nearest_obstacle"], safety_distance)
    for axis in axes:
        axis.grid(alpha=0.3)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def obstacle_panel(axis, times: np.ndarray, gap: np.ndarray, safety_distance: float) -> None:
    """Draw the surface gap to the nearest obstacle over time on ``axis``.

    Parameters
    ----------
    axis : matplotlib Axes
        The panel.
    times : ndarray
        Times, s.
    gap : ndarray
        Surface gap to the nearest obstacle at each time, m (infinite with none).
    safety_distance : float
        Gap marked as a dashed line, m; contact (0 m) is marked too.
    """
    finite = np.isfinite(gap)
    axis.plot(times[finite], gap[finite], color="tab:red", lw=0.9, label="nearest obstacle")
    axis.axhline(safety_distance, color="k", ls="--", lw=1, label="safety distance")
    axis.axhline(0.0, color="tab:red", lw=0.6, ls=":", label="contact")
    axis.set(xlabel="time [s]", ylabel="gap [m]", title="Distance to the nearest obstacle")
    if finite.any() and np.max(gap[finite]) > 10 * max(safety_distance, 1.0):
        axis.set_yscale("symlog", linthresh=max(safety_distance, 1.0))
    axis.legend(fontsize=8, loc="upper right")
