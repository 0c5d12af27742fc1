"""Pictures of a run, and the helpers every mission's pictures share.

A debris run (the default of :meth:`Mission.plot`) draws four pictures into the run's
``plots/`` folder:

``trajectory.png``
    The collector's path, true and estimated, in 3-D and in two side views (in the
    LVLH frame the in-plane view, along-track across and radial up, and along-track
    against orbit normal; otherwise x-y and x-z), with every target's path until its
    grab and every obstacle's path (in the side views each object outlined in its true
    shape where its path starts and ends), the grabs and the drop point.
``timeline.png``
    The mission mode with every grab (GRAB is decided and done within one tick, so no
    row of the telemetry shows it) and every release marked, propellant used, delta-v
    used and the surface gap to the nearest obstacle.
``motion.png``
    Speed, commanded thrust, attitude (the angle turned from the initial attitude) and
    angular rate.
``estimation.png``
    The estimation error per axis with the ±3σ envelope of the localiser's reported
    covariance, and its length.

Axes are named after the scenario's frame (:class:`FrameAxes`: radial, along-track and
orbit-normal in ``lvlh``, x, y and z otherwise) and positions are ticked in km when
they lie :data:`KM_FROM` or further from the origin (the thesis's geocentric field).
Drawn with matplotlib's non-interactive Agg backend.
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
from matplotlib.patches import Patch  # noqa: E402
from matplotlib.ticker import FuncFormatter  # noqa: E402

from dcsim.messages import ObjectKind, Shape  # noqa: E402
from dcsim.motion import MotionSet  # noqa: E402
from dcsim.recording import SIGMA_COLUMNS  # noqa: E402
from dcsim.scenario.model import XYZ_AXES, Scenario, frame_axes  # noqa: E402
from dcsim.shape_outlines import outline  # noqa: E402
from dcsim.world.objects import SpaceObject, build_objects  # noqa: E402

NAMED_OBSTACLES = 20
"""The trajectory picture names obstacles by id when there are at most this many
(targets always)."""

KM_FROM = 10_000.0
"""Positions this far from the origin or further (m) are ticked in km."""

DPI = 110
"""Resolution of the pictures, dots per inch."""

TITLE_ROOM = 0.45
"""Height a figure's title takes at its top, in."""

LEGEND_ROW = 0.35
"""Height of one row of a legend, in."""

_TRUE = "tab:blue"
_ESTIMATED = "tab:orange"
_TARGET = "tab:green"
_OBSTACLE = "tab:red"
_GRAB = "gold"
_COMPONENTS = ("tab:red", "tab:green", "tab:blue")  # x, y, z components


# ---------------------------------------------------------------------- shared helpers
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


def save(figure: Figure, path: Path) -> None:
    """Write ``figure`` to ``path`` (PNG) and free it."""
    try:
        figure.savefig(path, dpi=DPI)
    finally:
        plt.close(figure)


def top_legend(figure: Figure, handles: Sequence[Any]) -> float:
    """Draw a legend of ``handles`` in one row under ``figure``'s title (nothing without
    handles); return the height the title and the legend take at the top, in."""
    if not handles:
        return TITLE_ROOM
    figure.legend(
        handles=handles,
        loc="upper center",
        bbox_to_anchor=(0.5, 1.0 - TITLE_ROOM / figure.get_figheight()),
        ncol=len(handles),
        fontsize=8,
    )
    return TITLE_ROOM + LEGEND_ROW


def stack_layout(
    figure: Figure, rows: int, top: float = TITLE_ROOM, left: float = 1.0, right: float = 0.3
) -> None:
    """Place ``rows`` panels stacked under each other with fixed margins, in inches.

    ``top`` is kept free above the top panel's title (the figure's title and legend),
    ``left`` for the tick labels and axis labels, ``right`` for legends beside the panels.
    Fixed margins cost nothing, where a layout engine draws the whole figure once more.
    """
    width, height = figure.get_size_inches()
    top += 0.3  # the top panel's title
    bottom, gap = 0.55, 0.55  # the time axis below; a panel's ticks and title between
    panel = (height - top - bottom - (rows - 1) * gap) / rows
    figure.subplots_adjust(
        left=left / width,
        right=1.0 - right / width,
        bottom=bottom / height,
        top=1.0 - top / height,
        hspace=gap / panel,
    )


def kilometre_ticks() -> FuncFormatter:
    """A tick formatter that writes lengths given in m as km (150000 → ``150``)."""
    return FuncFormatter(lambda value, _: f"{value / 1e3:g}")


@dataclass(frozen=True)
class FrameAxes:
    """How the pictures name the world's axes and tick its positions.

    Attributes
    ----------
    frame : str
        The scenario's ``world.frame``.
    names : tuple of str
        Each world axis's name (:func:`dcsim.scenario.model.frame_axes`).
    unit : str
        ``km`` when the positions drawn lie :data:`KM_FROM` or further from the origin,
        else ``m``; the data stay in m, the tick labels say km.
    """

    frame: str
    names: tuple[str, str, str]
    unit: str

    @classmethod
    def of(cls, scenario: Scenario, positions: np.ndarray) -> FrameAxes:
        """The axes of ``scenario``'s frame for pictures of ``positions`` (..., 3), m."""
        frame = scenario.world.frame
        farthest = float(np.max(np.abs(positions))) if np.size(positions) else 0.0
        return cls(frame, frame_axes(frame), "km" if farthest >= KM_FROM else "m")

    @property
    def description(self) -> str:
        """The frame and, in LVLH, which axis is which (for titles)."""
        if self.names == XYZ_AXES:
            return f"frame {self.frame}"
        axes = ", ".join(f"{xyz} {name}" for xyz, name in zip(XYZ_AXES, self.names, strict=True))
        return f"frame {self.frame} ({axes})"

    def label(self, index: int) -> str:
        """Axis label of world axis ``index`` with the length unit, e.g. ``radial [m]``."""
        return f"{self.names[index]} [{self.unit}]"

    def name_axes(self, axis: Any, dims: Sequence[int], letters: str = "xyz") -> None:
        """Label the axes ``letters`` of ``axis`` (x, y and, in 3-D, z), which show world
        axes ``dims``, and tick them in :attr:`unit`."""
        for letter, dim in zip(letters, dims, strict=False):
            getattr(axis, f"set_{letter}label")(self.label(dim))
            if self.unit == "km":
                getattr(axis, f"{letter}axis").set_major_formatter(kilometre_ticks())

    def views(self) -> tuple[tuple[int, int], tuple[int, int]]:
        """Two side views by world axes (across, up): in LVLH the in-plane view
        (along-track, radial) and (along-track, orbit-normal); else x-y and x-z."""
        return ((1, 0), (1, 2)) if self.frame == "lvlh" else ((0, 1), (0, 2))


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
    axis.plot(times[finite], gap[finite], color=_OBSTACLE, lw=0.9, label="nearest obstacle")
    axis.axhline(safety_distance, color="k", ls="--", lw=1, label="safety distance")
    axis.axhline(0.0, color=_OBSTACLE, lw=0.6, ls=":", label="contact")
    axis.set(xlabel="time [s]", ylabel="gap [m]", title="Distance to the nearest obstacle")
    if finite.any() and np.max(gap[finite]) > 10 * max(safety_distance, 1.0):
        _symlog_gaps(axis, gap[finite], max(safety_distance, 1.0))
    axis.legend(fontsize=8, loc="best")


def _symlog_gaps(axis, gap: np.ndarray, linear: float) -> None:
    """A log scale above ``linear`` (m) and a linear one below, down to just under the
    least gap (or 0), ticked at 0 and the decades above ``linear`` only: the linear
    stretch is too short to hold more labels."""
    axis.set_yscale("symlog", linthresh=linear)
    axis.set_ylim(bottom=min(float(np.min(gap)), 0.0) - 0.2 * linear)
    decades = np.arange(np.ceil(np.log10(linear)), np.floor(np.log10(np.max(gap))) + 1)
    axis.set_yticks([0.0, *(10.0**decades)])


def limited_panel(
    axis, times: np.ndarray, values: np.ndarray, limit: float, ylabel: str, title: str, name: str
) -> None:
    """A non-negative quantity over time with its limit ``name`` as a dashed line."""
    axis.plot(times, values, color=_TRUE, lw=1.0)
    _limit_line(axis, limit, name)
    axis.set_ylim(0.0, 1.2 * max(limit, float(np.max(values))))
    axis.set(ylabel=ylabel, title=title)


def _limit_line(axis, limit: float, name: str) -> None:
    axis.axhline(limit, color="k", ls="--", lw=0.8)
    axis.annotate(
        f"{name} {limit:.3g}",
        (1.0, limit),
        xycoords=("axes fraction", "data"),
        ha="right",
        va="bottom",
        fontsize=8,
    )


def speed_panel(axis, telemetry: Mapping[str, np.ndarray], max_speed: float) -> None:
    """The true speed |v| (m/s) over time, with ``max_speed`` (m/s) marked."""
    speed = np.linalg.norm(stacked(telemetry, ("vx", "vy", "vz")), axis=1)
    limited_panel(axis, telemetry["time"], speed, max_speed, "speed [m/s]", "Speed", "max_speed")


def thrust_panel(
    axis, telemetry: Mapping[str, np.ndarray], max_force: float, names: Sequence[str]
) -> None:
    """The commanded thrust (N): its components along the world axes ``names`` and its
    magnitude, with ±``max_force`` (N) marked."""
    times = telemetry["time"]
    force = stacked(telemetry, ("fx", "fy", "fz"))
    _components(axis, times, force, names)
    axis.plot(times, np.linalg.norm(force, axis=1), color="k", lw=1.2, label="|F|")
    _limit_line(axis, max_force, "max_force")
    axis.axhline(-max_force, color="k", ls="--", lw=0.8)
    bound = 1.2 * max(max_force, float(np.max(np.abs(force))))
    axis.set_ylim(-bound, bound)
    axis.set(ylabel="thrust [N]", title="Commanded thrust")
    axis.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.0, 0.5))


def attitude_change(telemetry: Mapping[str, np.ndarray]) -> np.ndarray:
    """Angle of the rotation from the first row's attitude to each row's, rad.

    The attitude is the quaternion ``qx qy qz qw``; the angle is in ``[0, π]``.
    """
    quaternions = stacked(telemetry, ("qx", "qy", "qz", "qw"))
    cosine = np.abs(quaternions @ quaternions[0])
    return 2.0 * np.arccos(np.clip(cosine, 0.0, 1.0))


def attitude_panel(axis, telemetry: Mapping[str, np.ndarray]) -> None:
    """The angle turned from the initial attitude over time, degrees."""
    axis.plot(telemetry["time"], np.degrees(attitude_change(telemetry)), color=_TRUE, lw=1.0)
    axis.set(ylabel="angle [deg]", title="Attitude: angle turned from the initial attitude")
    axis.set_ylim(bottom=0.0)


def rate_panel(axis, telemetry: Mapping[str, np.ndarray], names: Sequence[str]) -> None:
    """The true angular velocity (world frame) over time: components along ``names`` and
    magnitude, deg/s."""
    times = telemetry["time"]
    rate = np.degrees(stacked(telemetry, ("wx", "wy", "wz")))
    _components(axis, times, rate, names)
    axis.plot(times, np.linalg.norm(rate, axis=1), color="k", lw=1.2, label="|ω|")
    axis.set(ylabel="rate [deg/s]", title="Angular rate (world frame)")
    axis.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.0, 0.5))


def _components(axis, times: np.ndarray, values: np.ndarray, names: Sequence[str]) -> None:
    for column, name, colour in zip(values.T, names, _COMPONENTS, strict=True):
        axis.plot(times, column, color=colour, lw=0.8, label=name)


def _mode_levels(mode: np.ndarray, modes: Sequence[str]) -> np.ndarray:
    """Each row's mode as its index in ``modes`` (the height a timeline draws it at)."""
    index = {name: i for i, name in enumerate(modes)}
    return np.array([index[str(m)] for m in mode])


# ---------------------------------------------------------------------- debris pictures
def write_plots(
    out_dir: Path,
    scenario: Scenario,
    telemetry: Mapping[str, np.ndarray],
    events: Sequence[Mapping[str, Any]],
    modes: Sequence[str],
    safety_distance: float,
) -> list[Path]:
    """Draw ``trajectory.png``, ``timeline.png``, ``motion.png`` and ``estimation.png``
    into ``out_dir/plots``.

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
    folder = plots_folder(out_dir, telemetry)
    if folder is None:
        return []
    drawings: dict[str, Callable[[], Figure]] = {
        "trajectory.png": lambda: trajectory_figure(scenario, telemetry, events),
        "timeline.png": lambda: timeline_figure(
            scenario, telemetry, events, tuple(modes), safety_distance
        ),
        "motion.png": lambda: motion_figure(scenario, telemetry),
        "estimation.png": lambda: estimation_figure(scenario, telemetry),
    }
    paths = []
    for name, draw in drawings.items():
        save(draw(), folder / name)
        paths.append(folder / name)
    return paths


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
    return _Paths(
        true=true,
        estimated=stacked(telemetry, ("est_x", "est_y", "est_z")),
        grabs=grab_points.reshape(-1, 3),
        drop=scenario.drop_point.build(scenario.mean_motion).state_at(sample)[0],
        objects=list(_object_paths(scenario, sample, events)),
    )


def _draw_paths(axis, paths: _Paths, dims: Sequence[int], annotate: bool = False) -> None:
    """Draw the paths on ``axis`` (2-D or 3-D), showing world axes ``dims``."""
    columns = list(dims)
    flat = len(columns) == 2
    obstacles = sum(obj.kind is ObjectKind.OBSTACLE for obj, _ in paths.objects)
    for obj, obj_path in paths.objects:
        target = obj.kind is ObjectKind.TARGET
        colour = _TARGET if target else _OBSTACLE
        axis.plot(*obj_path[:, columns].T, color=colour, lw=0.8, alpha=0.7)
        if flat and len(obj_path):
            _draw_footprint(axis, obj.shape, obj_path[[0, -1]][:, columns], colour, dims)
        named = target or obstacles <= NAMED_OBSTACLES
        if annotate and named and len(obj_path):
            axis.annotate(str(obj.id), obj_path[0, columns], fontsize=7, color=colour)
    axis.plot(*paths.true[:, columns].T, color=_TRUE, lw=1.8)
    axis.plot(*paths.estimated[:, columns].T, color=_ESTIMATED, lw=0.9, ls="--")
    for point, marker in ((paths.true[0], "o"), (paths.true[-1], "s")):
        axis.plot(*point[columns, None], marker=marker, color=_TRUE, mec="k", ms=7, ls="")
    axis.scatter(
        *paths.grabs[:, columns].T, marker="*", s=140, color=_GRAB, edgecolor="k", zorder=5
    )
    axis.plot(*paths.drop[:, columns].T, color="k", lw=1)
    axis.scatter(*paths.drop[:1, columns].T, marker="X", s=90, color="k", zorder=5)


def _trajectory_legend() -> list:
    return [
        Line2D([], [], color=_TRUE, lw=1.8, label="collector, true"),
        Line2D([], [], color=_ESTIMATED, lw=0.9, ls="--", label="collector, estimated"),
        Line2D([], [], color=_TRUE, marker="o", mec="k", ls="", label="start"),
        Line2D([], [], color=_TRUE, marker="s", mec="k", ls="", label="end"),
        Line2D([], [], color=_TARGET, lw=0.8, label="targets (until grabbed)"),
        Line2D([], [], color=_OBSTACLE, lw=0.8, label="obstacles"),
        Line2D(
            [], [], marker="*", ms=12, color=_GRAB, mec="k", ls="", label="grab (true position)"
        ),
        Line2D([], [], marker="X", ms=9, color="k", ls="", label="drop point (at the start)"),
    ]


def _draw_footprint(
    axis, shape: Shape, centres: np.ndarray, colour: str, view: Sequence[int]
) -> None:
    """Outline ``shape`` in the view of world axes ``view`` about each of ``centres``
    (K, 2), m."""
    footprint = outline(shape, tuple(view))
    for centre in np.unique(centres, axis=0):
        axis.fill(*(centre + footprint).T, facecolor=colour, edgecolor=colour, alpha=0.3, lw=0.8)


def timeline_figure(
    scenario: Scenario,
    telemetry: Mapping[str, np.ndarray],
    events: Sequence[Mapping[str, Any]],
    modes: tuple[str, ...],
    safety_distance: float,
) -> Figure:
    """Mode (grabs and releases marked), propellant, delta-v and obstacle gap over time.

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
    figure, axes = plt.subplots(4, 1, figsize=(11, 10), sharex=True)
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
    for axis in axes:
        axis.grid(alpha=0.3)
    figure.suptitle(f"{scenario.name}: timeline")
    stack_layout(figure, len(axes), top_legend(figure, handles), left=1.3)
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


def motion_figure(scenario: Scenario, telemetry: Mapping[str, np.ndarray]) -> Figure:
    """Speed, commanded thrust, attitude and angular rate over time.

    Parameters
    ----------
    scenario : Scenario
        The resolved scenario (frame, robot limits).
    telemetry : mapping of str to ndarray
        The telemetry columns.
    """
    names = FrameAxes.of(scenario, np.zeros(0)).names
    robot = scenario.robot
    figure, axes = plt.subplots(4, 1, figsize=(11, 11), sharex=True)
    speed_panel(axes[0], telemetry, robot.max_speed)
    thrust_panel(axes[1], telemetry, robot.max_force, names)
    attitude_panel(axes[2], telemetry)
    rate_panel(axes[3], telemetry, names)
    for axis in axes:
        axis.grid(alpha=0.3)
    axes[-1].set_xlabel("time [s]")
    figure.suptitle(f"{scenario.name}: motion")
    stack_layout(figure, len(axes), right=1.3)
    return figure


def estimation_figure(scenario: Scenario, telemetry: Mapping[str, np.ndarray]) -> Figure:
    """The estimation error per axis with its ±3σ envelope, and its length, over time.

    The error is estimated minus true position; σ is the localiser's reported standard
    deviation (:data:`dcsim.recording.SIGMA_COLUMNS`). Until the localiser converges the
    panels are shaded grey, and each panel's scale is set by the converged stretch.

    Parameters
    ----------
    scenario : Scenario
        The resolved scenario (frame, localiser).
    telemetry : mapping of str to ndarray
        The telemetry columns.
    """
    times = telemetry["time"]
    error = stacked(telemetry, ("est_x", "est_y", "est_z")) - stacked(telemetry, ("x", "y", "z"))
    sigma = stacked(telemetry, SIGMA_COLUMNS)
    converged = telemetry["converged"].astype(bool)
    names = FrameAxes.of(scenario, np.zeros(0)).names
    figure, axes = plt.subplots(4, 1, figsize=(11, 11), sharex=True)
    for i, axis in enumerate(axes[:3]):
        envelope = 3.0 * sigma[:, i]
        axis.fill_between(
            times, -envelope, envelope, color=_TRUE, alpha=0.2, lw=0, label="±3σ (reported)"
        )
        axis.plot(times, error[:, i], color=_TRUE, lw=0.8, label="estimated − true")
        axis.set(ylabel=f"{names[i]} [m]", title=f"Estimation error, {names[i]}")
        _scale_to_converged(axis, np.abs(error[:, i]), envelope, converged)
    length = np.linalg.norm(error, axis=1)
    axes[3].semilogy(times, np.maximum(length, 1e-6), color=_TRUE, lw=0.8)
    axes[3].set(ylabel="error [m]", xlabel="time [s]", title="Estimation error |estimated − true|")
    handles = [*axes[0].get_legend_handles_labels()[0]]
    for axis in axes:
        _shade_unconverged(axis, times, converged)
        axis.grid(alpha=0.3)
    if not converged.all():
        handles.append(Patch(color="0.85", label="not converged"))
    figure.suptitle(f"{scenario.name}: estimation ({_localiser(scenario)})")
    stack_layout(figure, len(axes), top_legend(figure, handles))
    return figure


def _localiser(scenario: Scenario) -> str:
    choice = scenario.localiser
    return "no localiser: the true state" if choice is None else f"localiser {choice.plugin}"


def _scale_to_converged(
    axis, error: np.ndarray, envelope: np.ndarray, converged: np.ndarray
) -> None:
    """Fit the panel's scale to the converged rows (the prior's spread would flatten them)."""
    if not converged.any():
        return
    largest = float(np.max(np.maximum(error[converged], envelope[converged])))
    if np.isfinite(largest) and largest > 0.0:
        axis.set_ylim(-1.3 * largest, 1.3 * largest)


def _shade_unconverged(axis, times: np.ndarray, converged: np.ndarray) -> None:
    """Shade each stretch of rows whose estimate is not converged."""
    edges = np.flatnonzero(np.diff(np.concatenate([[1], converged.astype(int), [1]])))
    for start, end in zip(edges[::2], edges[1::2], strict=True):
        last = min(end, len(times) - 1)
        axis.axvspan(times[start], times[last], color="0.85", lw=0, zorder=0)
