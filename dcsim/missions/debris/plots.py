"""A debris run's own pictures, drawn into its ``plots/`` folder beside
``motion.png`` and ``estimation.png`` (:mod:`dcsim.report.plots`):

``trajectory.png``
    The collector's path, true and estimated, in 3-D and in two side views (in the
    LVLH frame the in-plane view, along-track across and radial up, and along-track
    against orbit normal; otherwise x-y and x-z), with every target's path until its
    grab and every obstacle's path (in the side views each object outlined in its true
    shape where its path starts and ends), the grabs and the drop point.
``timeline.png``
    The mission mode with every grab (GRAB is decided and done within one tick, so no
    row of the telemetry shows it) and every release marked, propellant used, delta-v
    used and the surface gap to the nearest obstacle; below them the attitude error, the
    reaction wheels' momenta and the thrusters' duty cycles when the telemetry has them
    (:mod:`dcsim.report.hardware`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (the backend must be chosen first)
import numpy as np  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

from dcsim.messages import ObjectKind, Shape  # noqa: E402
from dcsim.missions.debris.settings import DebrisMissionSection  # noqa: E402
from dcsim.motion import MotionSet  # noqa: E402
from dcsim.report.hardware import timeline_axes  # noqa: E402
from dcsim.report.outlines import outline  # noqa: E402
from dcsim.report.plots import (  # noqa: E402
    ESTIMATED_COLOUR,
    OBSTACLE_COLOUR,
    TRUE_COLOUR,
    FrameAxes,
    label_time,
    obstacle_panel,
    stack_layout,
    stacked,
    top_legend,
    top_title,
    write_plots,
)
from dcsim.scenario.model import Scenario  # noqa: E402
from dcsim.world.objects import SpaceObject, build_objects  # noqa: E402

NAMED_OBSTACLES = 20
"""The trajectory picture names obstacles by id when there are at most this many
(targets always)."""

_TARGET = "tab:green"
_GRAB = "gold"


def write_debris_plots(
    out_dir: Path,
    scenario: Scenario,
    telemetry: Mapping[str, np.ndarray],
    events: Sequence[Mapping[str, Any]],
    modes: Sequence[str],
    safety_distance: float,
) -> list[Path]:
    """Draw ``trajectory.png`` and ``timeline.png``, then the pictures every run has
    (:func:`dcsim.report.plots.write_plots`), into ``out_dir/plots``.

    Parameters
    ----------
    out_dir : Path
        The run directory.
    scenario : Scenario
        The resolved scenario (objects, drop point, frame, robot limits).
    telemetry : mapping of str to ndarray
        The telemetry columns.
    events : sequence of mapping
        The event log (grabs and releases are marked).
    modes : sequence of str
        The mission's modes, in the order the timeline shows them.
    safety_distance : float
        Gap marked on the obstacle-distance panel, m.

    Returns
    -------
    list of Path
        The files written (none if there is no telemetry).
    """
    drawings: dict[str, Callable[[], Figure]] = {
        "trajectory.png": lambda: trajectory_figure(scenario, telemetry, events),
        "timeline.png": lambda: timeline_figure(
            scenario, telemetry, events, tuple(modes), safety_distance
        ),
    }
    return write_plots(out_dir, scenario, telemetry, drawings)


def _object_paths(
    scenario: Scenario, times: np.ndarray, events: Sequence[Mapping[str, Any]]
) -> Iterator[tuple[SpaceObject, np.ndarray]]:
    """Each object's path (K, 3), m, over ``times``, targets cut at their grab."""
    grabbed = {e["target"]: e["t"] for e in events if e["event"] == "grab" and e["success"]}
    objects = build_objects(scenario)
    motions = MotionSet([o.motion for o in objects])
    sampled = [motions.state_at(float(t))[0] for t in times]
    positions = np.stack(sampled, axis=1) if objects else np.zeros((0, len(times), 3))
    for obj, path in zip(objects, positions, strict=True):
        end = grabbed.get(obj.id, np.inf)
        yield obj, path[times <= end]


@dataclass(frozen=True)
class _Paths:
    """What the trajectory picture draws, world frame, m."""

    true: np.ndarray
    estimated: np.ndarray
    grabs: np.ndarray
    drop: np.ndarray
    objects: list[tuple[SpaceObject, np.ndarray]]


def trajectory_figure(
    scenario: Scenario,
    telemetry: Mapping[str, np.ndarray],
    events: Sequence[Mapping[str, Any]],
) -> Figure:
    """The collector's path, true and estimated, with the objects, in 3-D and two views.

    Parameters
    ----------
    scenario : Scenario
        The resolved scenario.
    telemetry : mapping of str to ndarray
        The telemetry columns.
    events : sequence of mapping
        The event log (successful grabs cut the targets' paths and are marked).
    """
    paths = _trajectory_paths(scenario, telemetry, events)
    frame = FrameAxes.of(scenario, paths.true)
    figure = plt.figure(figsize=(17, 7))
    grid = figure.add_gridspec(1, 3, width_ratios=(1.15, 1.0, 1.0), wspace=0.3)
    ax3d = figure.add_subplot(grid[0], projection="3d")
    _draw_paths(ax3d, paths, (0, 1, 2))
    frame.name_axes(ax3d, (0, 1, 2))
    ax3d.set_title("3-D view")
    for index, view in enumerate(frame.views(), start=1):
        axis = figure.add_subplot(grid[index])
        _draw_paths(axis, paths, view, annotate=index == 1)
        frame.name_axes(axis, view)
        axis.set_title(f"{frame.names[view[0]]} / {frame.names[view[1]]} view")
        axis.set_aspect("equal", adjustable="datalim")
        axis.grid(alpha=0.3)
    figure.legend(handles=_trajectory_legend(), loc="lower center", ncol=8, fontsize=9)
    figure.suptitle(f"{scenario.name}: trajectory, {frame.description}")
    figure.subplots_adjust(left=0.02, right=0.98, bottom=0.16, top=0.9)
    return figure


def _trajectory_paths(
    scenario: Scenario, telemetry: Mapping[str, np.ndarray], events: Sequence[Mapping[str, Any]]
) -> _Paths:
    times = telemetry["time"]
    sample = times[:: max(1, len(times) // 400)]
    true = stacked(telemetry, ("x", "y", "z"))
    grabs = [e["t"] for e in events if e["event"] == "grab" and e["success"]]
    grab_points = true[np.searchsorted(times, grabs).clip(0, len(times) - 1)]
    drop_point = scenario.mission_as(DebrisMissionSection).drop_point
    return _Paths(
        true=true,
        estimated=stacked(telemetry, ("est_x", "est_y", "est_z")),
        grabs=grab_points.reshape(-1, 3),
        drop=drop_point.build(scenario.mean_motion).state_at(sample)[0],
        objects=list(_object_paths(scenario, sample, events)),
    )


def _draw_paths(axis, paths: _Paths, dims: Sequence[int], annotate: bool = False) -> None:
    """Draw the paths on ``axis`` (2-D or 3-D), showing world axes ``dims``."""
    columns = list(dims)
    flat = len(columns) == 2
    obstacles = sum(obj.kind is ObjectKind.OBSTACLE for obj, _ in paths.objects)
    for obj, obj_path in paths.objects:
        target = obj.kind is ObjectKind.TARGET
        colour = _TARGET if target else OBSTACLE_COLOUR
        axis.plot(*obj_path[:, columns].T, color=colour, lw=0.8, alpha=0.7)
        if flat and len(obj_path):
            view = (columns[0], columns[1])
            _draw_footprint(axis, obj.shape, obj_path[[0, -1]][:, columns], colour, view)
        named = target or obstacles <= NAMED_OBSTACLES
        if annotate and named and len(obj_path):
            axis.annotate(str(obj.id), obj_path[0, columns], fontsize=7, color=colour)
    axis.plot(*paths.true[:, columns].T, color=TRUE_COLOUR, lw=1.8)
    axis.plot(*paths.estimated[:, columns].T, color=ESTIMATED_COLOUR, lw=0.9, ls="--")
    for point, marker in ((paths.true[0], "o"), (paths.true[-1], "s")):
        axis.plot(*point[columns, None], marker=marker, color=TRUE_COLOUR, mec="k", ms=7, ls="")
    axis.scatter(
        *paths.grabs[:, columns].T, marker="*", s=140, color=_GRAB, edgecolor="k", zorder=5
    )
    axis.plot(*paths.drop[:, columns].T, color="k", lw=1)
    axis.scatter(*paths.drop[:1, columns].T, marker="X", s=90, color="k", zorder=5)


def _trajectory_legend() -> list:
    return [
        Line2D([], [], color=TRUE_COLOUR, lw=1.8, label="collector, true"),
        Line2D([], [], color=ESTIMATED_COLOUR, lw=0.9, ls="--", label="collector, estimated"),
        Line2D([], [], color=TRUE_COLOUR, marker="o", mec="k", ls="", label="start"),
        Line2D([], [], color=TRUE_COLOUR, marker="s", mec="k", ls="", label="end"),
        Line2D([], [], color=_TARGET, lw=0.8, label="targets (until grabbed)"),
        Line2D([], [], color=OBSTACLE_COLOUR, lw=0.8, label="obstacles"),
        Line2D(
            [], [], marker="*", ms=12, color=_GRAB, mec="k", ls="", label="grab (true position)"
        ),
        Line2D([], [], marker="X", ms=9, color="k", ls="", label="drop point (at the start)"),
    ]


def _draw_footprint(
    axis, shape: Shape, centres: np.ndarray, colour: str, view: tuple[int, int]
) -> None:
    """Outline ``shape`` in the view of world axes ``view`` about each of ``centres``
    (K, 2), m."""
    footprint = outline(shape, view)
    for centre in np.unique(centres, axis=0):
        axis.fill(*(centre + footprint).T, facecolor=colour, edgecolor=colour, alpha=0.3, lw=0.8)


def timeline_figure(
    scenario: Scenario,
    telemetry: Mapping[str, np.ndarray],
    events: Sequence[Mapping[str, Any]],
    modes: tuple[str, ...],
    safety_distance: float,
) -> Figure:
    """Mode (grabs and releases marked), propellant, delta-v and obstacle gap over time,
    then the hardware panels the telemetry has data for (:mod:`dcsim.report.hardware`).

    Parameters
    ----------
    scenario : Scenario
        The resolved scenario (its name titles the picture).
    telemetry : mapping of str to ndarray
        The telemetry columns.
    events : sequence of mapping
        The event log: its ``grab`` and ``release`` events are marked.
    modes : tuple of str
        The mission's modes, bottom to top.
    safety_distance : float
        Gap marked on the obstacle-distance panel, m.
    """
    times = telemetry["time"]
    figure, axes, right = timeline_axes(scenario, telemetry, 4, 10.0)
    axes[0].step(times, _mode_levels(telemetry["mode"], modes), where="post", color="tab:purple")
    axes[0].set_yticks(range(len(modes)), modes, fontsize=7)
    axes[0].set_ylim(-0.5, len(modes) - 0.3)
    axes[0].set_title("Mission mode (grabs and releases marked)")
    axes[1].plot(times, telemetry["fuel_used"], color="tab:orange")
    axes[1].set(ylabel="propellant [kg]", title="Propellant used")
    axes[2].plot(times, telemetry["delta_v"], color="tab:brown")
    axes[2].set(ylabel="delta-v [m/s]", title="Delta-v used")
    obstacle_panel(axes[3], times, telemetry["nearest_obstacle"], safety_distance)
    handles = _mark_captures(axes, events, modes)
    label_time(axes)
    for axis in axes:
        axis.grid(alpha=0.3)
    top_title(figure, f"{scenario.name}: timeline")
    stack_layout(figure, len(axes), top_legend(figure, handles), left=1.3, right=max(right, 0.3))
    return figure


_CAPTURES = (
    # event, kept when, mode level, marker, face colour, label
    ("grab", lambda e: bool(e["success"]), "GRAB", "*", _GRAB, "grab"),
    ("grab", lambda e: not e["success"], "GRAB", "X", "tab:red", "failed grab"),
    ("release", lambda e: bool(e["delivered"]), "MOVE_TO_DROP", "v", "k", "release (delivered)"),
)
"""Events marked on the timeline's mode panel, at the level of the mode they happen in."""


def _mark_captures(axes, events: Sequence[Mapping[str, Any]], modes: tuple[str, ...]) -> list:
    """Mark grabs and releases on the mode panel (at their mode's level, the targets
    named) and as dotted lines across every panel; return the legend's handles."""
    handles = []
    for name, kept, level_mode, marker, colour, label in _CAPTURES:
        chosen = [e for e in events if e["event"] == name and kept(e)]
        if not chosen:
            continue
        times = [float(e["t"]) for e in chosen]
        level = modes.index(level_mode) if level_mode in modes else len(modes) - 1
        (line,) = axes[0].plot(
            times, [level] * len(times), marker, ms=12, mfc=colour, mec="k", ls="", zorder=5
        )
        line.set_label(label)
        handles.append(line)
        for event, t in zip(chosen, times, strict=True):
            axes[0].annotate(
                _targets(event),
                (t, level),
                xytext=(0, 8),
                textcoords="offset points",
                ha="center",
                fontsize=7,
            )
            for axis in axes:
                axis.axvline(t, color="0.5", lw=0.6, ls=":", zorder=1)
    return handles


def _targets(event: Mapping[str, Any]) -> str:
    """The target(s) an event is about, as text."""
    if "target" in event:
        return str(event["target"])
    return ",".join(str(t) for t in event.get("delivered", []))


def _mode_levels(mode: np.ndarray, modes: Sequence[str]) -> np.ndarray:
    """Each row's mode as its index in ``modes`` (the height a timeline draws it at)."""
    index = {name: i for i, name in enumerate(modes)}
    return np.array([index[str(m)] for m in mode])
