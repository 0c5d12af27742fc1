"""Pictures of a transfer run: the path in 3-D and in three side views, and a timeline.

``path.png`` shows the flown path (true position), the reference the controller
tracked, the last planned trajectory (the run's ``trajectory.csv``), the start, the
goal region, the path's bounds and every obstacle in its true shape. A moving
obstacle is drawn at the start, the middle and the end of the run, lighter than the
fixed ones and darker as time goes on, with the path it follows. Obstacles are drawn
when they come within :data:`SCENE_MARGIN` (or half the flight's size) of the flight.

``timeline.png`` shows speed, commanded thrust, attitude (the angle turned from the
initial attitude), angular rate, delta-v, tracking error and the surface gap to the
nearest obstacle against time, then the attitude error, the reaction wheels' momenta and
the thrusters' duty cycles when the telemetry has them (:mod:`dcsim.report.hardware`),
with the mission's modes shaded behind, each change of mode marked and the path
planner's answers (a plan, or "no path") along the top.

Axes are named and ticked as :class:`dcsim.report.plots.FrameAxes` says (radial, along-track
and orbit-normal in the LVLH frame). Drawn with matplotlib's non-interactive Agg
backend, as :mod:`dcsim.report.plots` is.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
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

from dcsim.messages import ObjectKind, Shape, ShapeKind  # noqa: E402
from dcsim.missions.transfer.settings import TransferMissionSection  # noqa: E402
from dcsim.report.hardware import timeline_axes  # noqa: E402
from dcsim.report.outlines import outline, wireframe  # noqa: E402
from dcsim.report.plots import (  # noqa: E402
    LEGEND_ROW,
    TITLE_ROOM,
    FrameAxes,
    attitude_panel,
    label_time,
    obstacle_panel,
    plots_folder,
    rate_panel,
    save,
    speed_panel,
    stack_layout,
    stacked,
    thrust_panel,
    top_title,
)
from dcsim.scenario.model import Scenario  # noqa: E402
from dcsim.world.objects import build_objects  # noqa: E402

SCENE_MARGIN = 10.0
"""Obstacles this close to the flight's box (m), or within half its diagonal, are drawn."""

VIEWS = ((0, 1), (0, 2), (1, 2))
"""The side views, by world axes: x-y, x-z, y-z."""

VIEW_PADDING = 0.03
"""Space left around the scene in each view, as a fraction of its largest side."""

INSTANT_ALPHAS = (0.12, 0.22, 0.35)
"""Fill opacity of a moving obstacle at the start, middle and end of the run."""

_FIXED = "0.45"  # colour of fixed obstacles
_MOVING = "tab:purple"
_GOAL = "tab:green"
_FLOWN = "tab:blue"
_PLANNED = "tab:orange"
_REFERENCE = "k"
_DIRECT = "tab:red"


@dataclass(frozen=True)
class Placed:
    """A shape drawn at one or more places.

    Attributes
    ----------
    shape : Shape
        The shape, about its centre.
    centres : ndarray (K, 3)
        Where it is drawn, m.
    alphas : tuple of float
        Fill opacity at each centre.
    colour : str
        Matplotlib colour.
    path : ndarray (S, 3)
        The path between the centres (a moving obstacle's), m; empty for a fixed one.
    """

    shape: Shape
    centres: np.ndarray
    alphas: tuple[float, ...]
    colour: str
    path: np.ndarray


@dataclass(frozen=True)
class Scene:
    """Everything ``path.png`` draws, in world coordinates (m).

    Attributes
    ----------
    flown, reference : ndarray (N, 3)
        True position and reference position over the run.
    planned : ndarray (M, 3)
        Positions of the last planned trajectory (empty without one).
    goal : Placed
        The goal region.
    bounds : Placed or None
        The box the path must stay in, if the mission has one.
    obstacles : list of Placed
        The obstacles near the flight.
    instants : ndarray (3,)
        Start, middle and end of the run, s: when moving obstacles are drawn.
    lower, upper : ndarray (3,)
        Corners of the box the views show.
    """

    flown: np.ndarray
    reference: np.ndarray
    planned: np.ndarray
    goal: Placed
    bounds: Placed | None
    obstacles: list[Placed]
    instants: np.ndarray
    lower: np.ndarray
    upper: np.ndarray


def write_transfer_plots(
    out_dir: Path,
    scenario: Scenario,
    telemetry: Mapping[str, np.ndarray],
    events: Sequence[Mapping[str, Any]],
    modes: Sequence[str],
    safety_distance: float,
) -> list[Path]:
    """Draw ``path.png`` and ``timeline.png`` of a transfer run into ``out_dir/plots``.

    Parameters
    ----------
    out_dir : Path
        The run directory; its ``trajectory.csv``, if present, is the planned path.
    scenario : Scenario
        The resolved scenario of a ``transfer`` mission.
    telemetry : mapping of str to ndarray
        The telemetry columns (thinned for plotting).
    events : sequence of mapping
        The event log: its mode changes and the planner's answers are marked.
    modes : sequence of str
        The mission's modes, in the order the timeline's legend lists them.
    safety_distance : float
        Gap marked on the clearance panel, m.

    Returns
    -------
    list of Path
        The files written (none if there is no telemetry).
    """
    folder = plots_folder(out_dir, telemetry)
    if folder is None:
        return []
    paths = [folder / "path.png", folder / "timeline.png"]
    scene = build_scene(scenario, telemetry, read_planned(out_dir / "trajectory.csv"))
    save(path_figure(scenario, scene), paths[0])
    save(timeline_figure(scenario, telemetry, events, tuple(modes), safety_distance), paths[1])
    return paths


def read_planned(path: Path) -> np.ndarray:
    """Positions (M, 3), m, of a ``trajectory.csv``; empty (0, 3) if there is no file."""
    if not path.is_file():
        return np.zeros((0, 3))
    with path.open(encoding="utf-8") as stream:
        header = stream.readline().strip().split(",")
        columns = [header.index(name) for name in ("x_m", "y_m", "z_m")]
        rows = [line.split(",") for line in stream if line.strip()]
    return np.array([[float(row[c]) for c in columns] for row in rows]).reshape(-1, 3)


def build_scene(
    scenario: Scenario, telemetry: Mapping[str, np.ndarray], planned: np.ndarray
) -> Scene:
    """What ``path.png`` draws: the paths, the goal, the bounds and the nearby obstacles.

    Parameters
    ----------
    scenario : Scenario
        The resolved scenario of a ``transfer`` mission.
    telemetry : mapping of str to ndarray
        The telemetry columns.
    planned : ndarray (M, 3)
        Positions of the planned trajectory, m.
    """
    times = telemetry["time"]
    flown = stacked(telemetry, ("x", "y", "z"))
    reference = stacked(telemetry, ("ref_x", "ref_y", "ref_z"))
    goal = _goal(scenario)
    bounds = _bounds(scenario)
    core = np.vstack([flown, reference, planned, *_corners(goal)])
    lower, upper = core.min(axis=0), core.max(axis=0)
    margin = max(SCENE_MARGIN, 0.5 * float(np.linalg.norm(upper - lower)))
    instants = np.array([times[0], 0.5 * (times[0] + times[-1]), times[-1]])
    candidates = _obstacles(scenario, times, instants)
    near = [p for p in candidates if _near(p, lower - margin, upper + margin)]
    lower, upper = _extent([core, *(c for p in [*near, bounds] for c in _corners(p))])
    shown = [p for p in candidates if _near(p, lower, upper)]  # also what the view holds
    lower, upper = _extent([core, *(c for p in [*shown, bounds] for c in _corners(p))])
    pad = np.maximum(VIEW_PADDING * (upper - lower).max(), 0.5)
    return Scene(flown, reference, planned, goal, bounds, shown, instants, lower - pad, upper + pad)


def _extent(points: Sequence[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Lowest and highest coordinates of arrays of points (each (K, 3))."""
    stacked = np.vstack(points)
    return stacked.min(axis=0), stacked.max(axis=0)


def _goal(scenario: Scenario) -> Placed:
    goal = scenario.mission_as(TransferMissionSection).goal.build()
    shape = (
        Shape(ShapeKind.SPHERE, radius=goal.tolerance)
        if goal.half_extents is None
        else Shape(ShapeKind.BOX, half_extents=goal.half_extents)
    )
    return Placed(shape, np.array([goal.position], float), (0.3,), _GOAL, np.zeros((0, 3)))


def _bounds(scenario: Scenario) -> Placed | None:
    bounds = scenario.mission_as(TransferMissionSection).bounds
    if bounds is None:
        return None
    lower, upper = np.asarray(bounds.lower, float), np.asarray(bounds.upper, float)
    shape = Shape(ShapeKind.BOX, half_extents=0.5 * (upper - lower))
    return Placed(shape, (0.5 * (lower + upper))[None], (0.0,), "0.6", np.zeros((0, 3)))


def _obstacles(scenario: Scenario, times: np.ndarray, instants: np.ndarray) -> list[Placed]:
    """Every obstacle: fixed ones once, moving ones at ``instants`` with their path."""
    placed = []
    for obj in build_objects(scenario):
        if obj.kind is not ObjectKind.OBSTACLE:
            continue
        path = obj.motion.state_at(times)[0]
        if np.ptp(path, axis=0).max() < 1e-6:
            placed.append(Placed(obj.shape, path[:1], (0.35,), _FIXED, np.zeros((0, 3))))
        else:
            centres = obj.motion.state_at(instants)[0]
            placed.append(Placed(obj.shape, centres, INSTANT_ALPHAS, _MOVING, path))
    return placed


def _corners(placed: Placed | None) -> list[np.ndarray]:
    """Lowest and highest corners (each (K, 3)) of the axis-aligned boxes that hold
    ``placed``'s shape at each of its centres."""
    if placed is None:
        return []
    reach = np.abs(np.vstack(wireframe(placed.shape))).max(axis=0)
    return [placed.centres - reach, placed.centres + reach]


def _near(placed: Placed, lower: np.ndarray, upper: np.ndarray) -> bool:
    """Whether the shape, at one of its centres, overlaps the box ``lower``-``upper``."""
    low, high = _corners(placed)
    return bool(np.any(np.all((high >= lower) & (low <= upper), axis=1)))


# ---------------------------------------------------------------------- path.png
def path_figure(scenario: Scenario, scene: Scene) -> Figure:
    """The scene in 3-D and in the three side views :data:`VIEWS`, axes named after
    ``scenario``'s frame.

    Parameters
    ----------
    scenario : Scenario
        The resolved scenario (its name and frame).
    scene : Scene
        What to draw (:func:`build_scene`).
    """
    frame = FrameAxes.of(scenario, np.vstack([scene.lower, scene.upper]))
    figure = plt.figure(figsize=(13, 11))
    _draw_3d(figure.add_subplot(2, 2, 1, projection="3d"), scene, frame)
    for index, view in enumerate(VIEWS, start=2):
        _draw_view(figure.add_subplot(2, 2, index), scene, view, frame)
    figure.legend(handles=_legend(scene), loc="lower center", ncol=4, fontsize=9)
    figure.suptitle(f"{scenario.name}: path, {frame.description}")
    figure.tight_layout(rect=(0.0, 0.06, 1.0, 0.97))
    figure.subplots_adjust(wspace=0.35)  # room for the 3-D view's z label
    return figure


def _draw_3d(axis, scene: Scene, frame: FrameAxes) -> None:
    """The scene in 3-D: wireframes, paths and markers, with equal scales."""
    for placed in [*scene.obstacles, scene.goal]:
        _wireframes(axis, placed)
    if scene.bounds is not None:
        _wireframes(axis, scene.bounds, ls="--")
    _paths(axis, scene, range(3))
    axis.set(
        xlim=(scene.lower[0], scene.upper[0]),
        ylim=(scene.lower[1], scene.upper[1]),
        zlim=(scene.lower[2], scene.upper[2]),
        title="3-D view",
    )
    frame.name_axes(axis, (0, 1, 2))
    axis.set_box_aspect(np.maximum(scene.upper - scene.lower, 1e-3))
    axis.locator_params(nbins=5)  # a short side would crowd its ticks


def _wireframes(axis, placed: Placed, ls: str = "-") -> None:
    lines = wireframe(placed.shape)
    for centre, alpha in zip(placed.centres, placed.alphas, strict=True):
        opacity = min(1.0, 0.25 + 1.5 * alpha)  # lines show fainter than fills
        for line in lines:
            axis.plot(*(centre + line).T, color=placed.colour, lw=0.6, ls=ls, alpha=opacity)
    if len(placed.path):
        axis.plot(*placed.path.T, color=placed.colour, lw=0.8, ls=":")


def _draw_view(axis, scene: Scene, view: tuple[int, int], frame: FrameAxes) -> None:
    """One side view: outlines filled, paths and markers, equal scales."""
    if scene.bounds is not None:
        _outlines(axis, scene.bounds, view, ls="--")
    for placed in [scene.goal, *scene.obstacles]:  # the goal under the obstacles
        _outlines(axis, placed, view)
    _paths(axis, scene, view)
    a, b = view
    axis.set(
        xlim=(scene.lower[a], scene.upper[a]),
        ylim=(scene.lower[b], scene.upper[b]),
        title=f"{frame.names[a]} / {frame.names[b]} view",
        aspect="equal",
    )
    frame.name_axes(axis, view)
    axis.grid(alpha=0.3)


def _outlines(axis, placed: Placed, view: tuple[int, int], ls: str = "-") -> None:
    shape = outline(placed.shape, view)
    for centre, alpha in zip(placed.centres[:, list(view)], placed.alphas, strict=True):
        axis.fill(*(centre + shape).T, facecolor=placed.colour, alpha=alpha, lw=0)
        axis.fill(*(centre + shape).T, fill=False, edgecolor=placed.colour, lw=0.7, ls=ls)
    if len(placed.path):
        axis.plot(*placed.path[:, list(view)].T, color=placed.colour, lw=0.8, ls=":")


def _paths(axis, scene: Scene, axes: Sequence[int]) -> None:
    """The planned (or, without a plan, the direct segment), reference and flown paths,
    the start and the end."""
    columns = list(axes)
    if len(scene.planned):
        axis.plot(*scene.planned[:, columns].T, color=_PLANNED, lw=3.5, alpha=0.55)
    else:
        direct = np.vstack([scene.flown[0], scene.goal.centres[0]])
        axis.plot(*direct[:, columns].T, color=_DIRECT, lw=1.2, ls="-.")
    axis.plot(*scene.reference[:, columns].T, color=_REFERENCE, lw=0.8, ls=":")
    axis.plot(*scene.flown[:, columns].T, color=_FLOWN, lw=1.4)
    for point, marker in ((scene.flown[0], "o"), (scene.flown[-1], "s")):
        axis.plot(*point[columns, None], marker=marker, color=_FLOWN, mec="k", ms=7, ls="")


def _legend(scene: Scene) -> list:
    handles = [
        Line2D([], [], color=_FLOWN, lw=1.4, label="flown (true position)"),
        Line2D([], [], color=_REFERENCE, lw=0.8, ls=":", label="reference"),
        Line2D([], [], color=_PLANNED, lw=3.5, alpha=0.55, label="planned (last plan)")
        if len(scene.planned)
        else Line2D([], [], color=_DIRECT, lw=1.2, ls="-.", label="direct segment (no plan)"),
        Line2D([], [], color=_FLOWN, marker="o", mec="k", ls="", label="start"),
        Line2D([], [], color=_FLOWN, marker="s", mec="k", ls="", label="end"),
        Patch(facecolor=_GOAL, alpha=0.3, edgecolor=_GOAL, label="goal region"),
        Patch(facecolor=_FIXED, alpha=0.35, edgecolor=_FIXED, label="obstacle"),
    ]
    if any(len(p.path) for p in scene.obstacles):
        when = ", ".join(f"{t:.0f}" for t in scene.instants)
        label = f"moving obstacle at t = {when} s (darker later)"
        handles.append(Patch(facecolor=_MOVING, alpha=0.3, edgecolor=_MOVING, label=label))
    if scene.bounds is not None:
        handles.append(Patch(fill=False, edgecolor="0.6", ls="--", label="bounds"))
    return handles


# ---------------------------------------------------------------------- timeline.png
def timeline_figure(
    scenario: Scenario,
    telemetry: Mapping[str, np.ndarray],
    events: Sequence[Mapping[str, Any]],
    modes: tuple[str, ...],
    safety_distance: float,
) -> Figure:
    """Speed, thrust, attitude, angular rate, delta-v, tracking error and clearance over
    time, then the hardware panels the telemetry has data for
    (:mod:`dcsim.report.hardware`), the modes shaded and the planner's answers marked.

    Parameters
    ----------
    scenario : Scenario
        The resolved scenario of a ``transfer`` mission.
    telemetry : mapping of str to ndarray
        The telemetry columns.
    events : sequence of mapping
        The event log: its mode changes and the planner's answers are marked.
    modes : tuple of str
        The mission's modes, in the order the legend lists them.
    safety_distance : float
        Gap marked on the clearance panel, m.
    """
    times = telemetry["time"]
    robot = scenario.robot
    names = FrameAxes.of(scenario, np.zeros(0)).names
    figure, axes, right = timeline_axes(scenario, telemetry, 7, 16.0)
    speed_panel(axes[0], telemetry, robot.max_speed)
    thrust_panel(axes[1], telemetry, robot.max_force, names)
    attitude_panel(axes[2], telemetry)
    rate_panel(axes[3], telemetry, names)
    axes[4].plot(times, telemetry["delta_v"], color="tab:brown")
    axes[4].set(ylabel="delta-v [m/s]", title="Delta-v used")
    axes[5].plot(times, telemetry["tracking_error"], color=_FLOWN, lw=1.0)
    axes[5].set(ylabel="error [m]", title="Tracking error |reference - estimate|")
    obstacle_panel(axes[6], times, telemetry["nearest_obstacle"], safety_distance)
    axes[6].set_title("Clearance: surface gap to the nearest obstacle")
    label_time(axes)
    for axis in axes:
        _shade_modes(axis, times, telemetry["mode"], modes)
        axis.grid(alpha=0.3)
    _mark_changes(axes, _mode_changes(events))
    _mark_answers(axes[0], events)
    figure.legend(
        handles=[*_mode_legend(modes), *_ANSWER_HANDLES],
        loc="upper center",
        ncol=len(modes) + len(_ANSWER_HANDLES),
        fontsize=9,
        title="mode (shaded; a dash-dot line marks each change) and the planner's answers",
        bbox_to_anchor=(0.5, 1.0 - TITLE_ROOM / figure.get_figheight()),
    )
    top_title(figure, f"{scenario.name}: timeline")
    stack_layout(figure, len(axes), top=TITLE_ROOM + 2 * LEGEND_ROW, right=max(right, 1.3))
    return figure


def _mode_colour(mode: str, modes: tuple[str, ...]) -> tuple:
    return plt.get_cmap("Pastel1")(modes.index(mode) % 9)


def _shade_modes(axis, times: np.ndarray, mode: np.ndarray, modes: tuple[str, ...]) -> None:
    """Shade each stretch of one mode as the telemetry records it."""
    changes = np.flatnonzero(mode[1:] != mode[:-1]) + 1
    starts = np.concatenate([[0], changes])
    ends = np.concatenate([changes, [len(times) - 1]])
    for start, end in zip(starts, ends, strict=True):
        colour = _mode_colour(str(mode[start]), modes)
        axis.axvspan(times[start], times[end], color=colour, alpha=0.5, lw=0, zorder=0)


def _mode_changes(events: Sequence[Mapping[str, Any]]) -> list[tuple[float, str]]:
    """Times of the mode events and what changed then, e.g. ``HOLD→PLAN→HOLD``.

    Changes within one tick (a plan asked for and refused) share a time, so they are
    joined into one label; the telemetry, one row per tick, cannot show them.
    """
    changes: dict[float, list[str]] = {}
    for event in events:
        if event["event"] == "mode":
            chain = changes.setdefault(float(event["t"]), [event["previous"]])
            chain.append(event["mode"])
    return [(t, "→".join(chain)) for t, chain in changes.items()]


def _mark_changes(axes, changes: list[tuple[float, str]]) -> None:
    """A dash-dot line on every panel at each mode change, labelled on the top one."""
    for t, label in changes:
        for axis in axes:
            axis.axvline(t, color="0.4", lw=0.7, ls="-.", zorder=1)
        text = axes[0].text(
            t,
            0.04,
            label,
            transform=axes[0].get_xaxis_transform(),
            rotation=90,
            ha="right",
            va="bottom",
            fontsize=7,
            color="0.3",
        )
        text.set_in_layout(False)  # a long label must not squeeze the panels


_ANSWERS = {"path": ("^", "tab:green", "plan"), "no_path": ("x", "tab:red", "no path")}
"""Planner answers marked on the top panel: event name -> (marker, colour, label)."""

_ANSWER_HANDLES = [
    Line2D([], [], marker=marker, color=colour, ls="", label=label)
    for marker, colour, label in _ANSWERS.values()
]


def _mark_answers(axis, events: Sequence[Mapping[str, Any]]) -> None:
    """The path planner's answers, at their times, along the top of ``axis``."""
    for name, (marker, colour, _) in _ANSWERS.items():
        times = [float(e["t"]) for e in events if e["event"] == name]
        (line,) = axis.plot(
            times,
            [0.9] * len(times),
            marker,
            color=colour,
            ms=8,
            mew=2,
            transform=axis.get_xaxis_transform(),
        )
        line.set_in_layout(False)


def _mode_legend(modes: tuple[str, ...]) -> list[Patch]:
    return [Patch(color=_mode_colour(mode, modes), alpha=0.5, label=mode) for mode in modes]
