"""Pictures of a run, and the helpers every mission's pictures share.

Every run draws two pictures into the run's ``plots/`` folder (:func:`write_plots`, the
default of :meth:`Mission.plot`); a mission adds its own (the debris mission's
trajectory and timeline: :mod:`dcsim.missions.debris.plots`):

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

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (the backend must be chosen first)
import numpy as np  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402
from matplotlib.ticker import FuncFormatter  # noqa: E402

from dcsim.run.recording import SIGMA_COLUMNS  # noqa: E402
from dcsim.scenario.model import XYZ_AXES, Scenario, frame_axes  # noqa: E402

KM_FROM = 10_000.0
"""Positions this far from the origin or further (m) are ticked in km."""

DPI = 110
"""Resolution of the pictures, dots per inch."""

TITLE_ROOM = 0.45
"""Height a figure's title takes at its top, in."""

LEGEND_ROW = 0.35
"""Height of one row of a legend, in."""

TRUE_COLOUR = "tab:blue"
"""Colour of true states (the robot's path, its speed)."""
ESTIMATED_COLOUR = "tab:orange"
"""Colour of estimated states."""
OBSTACLE_COLOUR = "tab:red"
"""Colour of obstacles and of the gap to them."""
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


def numbered_columns(telemetry: Mapping[str, np.ndarray], prefix: str) -> list[str]:
    """The telemetry columns ``prefix1``, ``prefix2``, … in the order of their numbers."""
    names = [
        name for name in telemetry if name.startswith(prefix) and name[len(prefix) :].isdigit()
    ]
    return sorted(names, key=lambda name: int(name[len(prefix) :]))


def save(figure: Figure, path: Path) -> None:
    """Write ``figure`` to ``path`` (PNG) and free it."""
    try:
        figure.savefig(path, dpi=DPI)
    finally:
        plt.close(figure)


def top_title(figure: Figure, text: str) -> None:
    """Title ``figure`` with ``text`` 0.2 in under its top edge, however tall it is (the
    legend :func:`top_legend` draws under it keeps clear)."""
    figure.suptitle(text, y=1.0 - 0.2 / figure.get_figheight())


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


def label_time(axes: Sequence[Any] | np.ndarray) -> None:
    """Name the time axis (s) under the bottom panel of stacked ``axes`` only."""
    for axis in axes[:-1]:
        axis.set_xlabel("")
    axes[-1].set_xlabel("time [s]")


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
    axis.plot(times[finite], gap[finite], color=OBSTACLE_COLOUR, lw=0.9, label="nearest obstacle")
    axis.axhline(safety_distance, color="k", ls="--", lw=1, label="safety distance")
    axis.axhline(0.0, color=OBSTACLE_COLOUR, lw=0.6, ls=":", label="contact")
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
    axis.plot(times, values, color=TRUE_COLOUR, lw=1.0)
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
    vector_lines(axis, times, force, names, "|F|")
    _limit_line(axis, max_force, "max_force")
    axis.axhline(-max_force, color="k", ls="--", lw=0.8)
    bound = 1.2 * max(max_force, float(np.max(np.abs(force))))
    axis.set_ylim(-bound, bound)
    axis.set(ylabel="thrust [N]", title="Commanded thrust")


def attitude_change(telemetry: Mapping[str, np.ndarray]) -> np.ndarray:
    """Angle of the rotation from the first row's attitude to each row's, rad.

    The attitude is the quaternion ``qx qy qz qw``; the angle is in ``[0, π]``.
    """
    quaternions = stacked(telemetry, ("qx", "qy", "qz", "qw"))
    cosine = np.abs(quaternions @ quaternions[0])
    return 2.0 * np.arccos(np.clip(cosine, 0.0, 1.0))


def attitude_panel(axis, telemetry: Mapping[str, np.ndarray]) -> None:
    """The angle turned from the initial attitude over time, degrees."""
    axis.plot(telemetry["time"], np.degrees(attitude_change(telemetry)), color=TRUE_COLOUR, lw=1.0)
    axis.set(ylabel="angle [deg]", title="Attitude: angle turned from the initial attitude")
    axis.set_ylim(bottom=0.0)


def rate_panel(axis, telemetry: Mapping[str, np.ndarray], names: Sequence[str]) -> None:
    """The true angular velocity (world frame) over time: components along ``names`` and
    magnitude, deg/s."""
    times = telemetry["time"]
    rate = np.degrees(stacked(telemetry, ("wx", "wy", "wz")))
    vector_lines(axis, times, rate, names, "|ω|")
    axis.set(ylabel="rate [deg/s]", title="Angular rate (world frame)")


def vector_lines(
    axis, times: np.ndarray, values: np.ndarray, names: Sequence[str], magnitude: str
) -> None:
    """Vectors over time on ``axis``: their components along the world axes ``names``
    and their magnitude (labelled ``magnitude``), named in a legend right of the panel.

    Parameters
    ----------
    axis : matplotlib Axes
        The panel.
    times : ndarray (N,)
        Times, s.
    values : ndarray (N, 3)
        The vectors, world frame, in the panel's unit.
    names : sequence of str
        The world axes' names.
    magnitude : str
        The magnitude's label, e.g. ``|F|``.
    """
    for column, name, colour in zip(values.T, names, _COMPONENTS, strict=True):
        axis.plot(times, column, color=colour, lw=0.8, label=name)
    axis.plot(times, np.linalg.norm(values, axis=1), color="k", lw=1.2, label=magnitude)
    axis.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.0, 0.5))


# ---------------------------------------------------------------------- debris pictures
def write_plots(
    out_dir: Path,
    scenario: Scenario,
    telemetry: Mapping[str, np.ndarray],
    drawings: Mapping[str, Callable[[], Figure]] | None = None,
) -> list[Path]:
    """Draw a run's pictures into ``out_dir/plots``: ``motion.png`` and
    ``estimation.png`` (what every mission's run shows), then ``drawings``.

    Parameters
    ----------
    out_dir : Path
        The run directory.
    scenario : Scenario
        The resolved scenario (frame, robot limits, localiser).
    telemetry : mapping of str to ndarray
        The telemetry columns.
    drawings : mapping of str to callable, optional
        A mission's own pictures: file name to a function drawing the figure.

    Returns
    -------
    list of Path
        The files written (none if there is no telemetry).
    """
    folder = plots_folder(out_dir, telemetry)
    if folder is None:
        return []
    every: dict[str, Callable[[], Figure]] = {
        **(drawings or {}),
        "motion.png": lambda: motion_figure(scenario, telemetry),
        "estimation.png": lambda: estimation_figure(scenario, telemetry),
    }
    paths = []
    for name, draw in every.items():
        save(draw(), folder / name)
        paths.append(folder / name)
    return paths


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
    deviation (:data:`dcsim.run.recording.SIGMA_COLUMNS`). Until the localiser converges the
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
            times, -envelope, envelope, color=TRUE_COLOUR, alpha=0.2, lw=0, label="±3σ (reported)"
        )
        axis.plot(times, error[:, i], color=TRUE_COLOUR, lw=0.8, label="estimated − true")
        axis.set(ylabel=f"{names[i]} [m]", title=f"Estimation error, {names[i]}")
        _scale_to_converged(axis, np.abs(error[:, i]), envelope, converged)
    length = np.linalg.norm(error, axis=1)
    axes[3].semilogy(times, np.maximum(length, 1e-6), color=TRUE_COLOUR, lw=0.8)
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
