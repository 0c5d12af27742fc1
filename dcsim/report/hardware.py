"""Timeline panels of the spacecraft hardware, shared by every mission's timeline.

:func:`hardware_panels` says which panels a run's telemetry has data for, and
:func:`timeline_axes` makes a timeline's figure with the mission's own panels on top and
those below, drawn:

attitude error
    The angle from the true attitude to the one the reference holds (``attitude_error``),
    degrees; shown whenever the reference held an attitude at some time (the column is not
    all NaN), with ideal torque too: a flat line at zero then says the attitude was held.
wheel momenta
    Each reaction wheel's momentum about its spin axis (``wheel_h_i``), N·m·s, with the
    wheels' ±``max_momentum`` dashed and, when thrusters unload them, the momentum at which
    unloading starts dotted; only with reaction wheels.
thruster duty cycles
    A heat-map strip, one row per thruster (``duty_i``: the fraction of the control period
    it fired, pale to dark; blank while idle), each row named by its number and, when the
    scenario says, the body axis it pushes along; only with thrusters.

Runs without the hardware get the attitude-error panel alone, or none when the reference
never held an attitude. Drawn with matplotlib's non-interactive Agg backend, as
:mod:`dcsim.report.plots` is.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (the backend must be chosen first)
import numpy as np  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from dcsim.report.plots import TRUE_COLOUR, numbered_columns  # noqa: E402
from dcsim.scenario.model import ActuatorsSpec, Scenario  # noqa: E402

PANEL_HEIGHT = 2.2
"""Height a hardware panel adds to a timeline, with the gap above it, in."""

LEGEND_RIGHT = 1.6
"""Room kept right of the panels for the wheels' legend and the duty cycles' colour bar, in."""

DUTY_COLOURS = ListedColormap(plt.get_cmap("Oranges")(np.linspace(0.3, 1.0, 256)))
"""Colours of the duty cycles, 0 to 1: matplotlib's Oranges from its 30 % on, so that a
short firing still shows against the blank of an idle thruster."""

Panel = Callable[[Any], None]
"""Draws one panel on the matplotlib Axes it is given."""


def hardware_panels(
    telemetry: Mapping[str, np.ndarray], scenario: Scenario | None = None
) -> list[Panel]:
    """The hardware panels ``telemetry`` has data for, top to bottom.

    Parameters
    ----------
    telemetry : mapping of str to ndarray
        The telemetry columns.
    scenario : Scenario, optional
        The resolved scenario: it gives the wheels' momentum limits and the thrusters'
        directions; without it the panels show the telemetry alone.

    Returns
    -------
    list of callable
        One drawing function per panel: attitude error (when ``attitude_error`` is finite
        somewhere), wheel momenta (``wheel_h_i`` columns), thruster duty cycles (``duty_i``
        columns).
    """
    return [panel for panel, _ in _panels(telemetry, scenario)]


def _panels(
    telemetry: Mapping[str, np.ndarray], scenario: Scenario | None
) -> list[tuple[Panel, float]]:
    """The panels of :func:`hardware_panels`, each with the room it takes right of the
    panels (its legend or colour bar), in."""
    actuators = _actuators(scenario)
    panels: list[tuple[Panel, float]] = []
    error = telemetry.get("attitude_error")
    if error is not None and np.isfinite(np.asarray(error, dtype=float)).any():
        panels.append((lambda axis: attitude_error_panel(axis, telemetry), 0.0))
    if numbered_columns(telemetry, "wheel_h_"):
        panels.append((lambda axis: wheel_panel(axis, telemetry, actuators), LEGEND_RIGHT))
    if numbered_columns(telemetry, "duty_"):
        panels.append((lambda axis: duty_panel(axis, telemetry, actuators), LEGEND_RIGHT))
    return panels


def timeline_axes(
    scenario: Scenario,
    telemetry: Mapping[str, np.ndarray],
    panels: int,
    height: float,
    width: float = 11.0,
) -> tuple[Figure, np.ndarray, float]:
    """A timeline's figure: ``panels`` stacked panels sharing the time axis, then the
    hardware panels :func:`hardware_panels` gives, drawn.

    Parameters
    ----------
    scenario : Scenario
        The resolved scenario.
    telemetry : mapping of str to ndarray
        The telemetry columns.
    panels : int
        The mission's own panels, drawn by the caller on the first ``panels`` axes.
    height : float
        The figure's height with the mission's panels alone, in; each hardware panel adds
        :data:`PANEL_HEIGHT`.
    width : float
        The figure's width, in.

    Returns
    -------
    figure : Figure
        The figure.
    axes : ndarray of Axes
        Every panel's axes, the mission's first.
    right : float
        Room the hardware panels need right of the panels (legends, colour bar), in.
    """
    extra = _panels(telemetry, scenario)
    figure, axes = plt.subplots(
        panels + len(extra), 1, figsize=(width, height + PANEL_HEIGHT * len(extra)), sharex=True
    )
    for axis, (draw, _) in zip(axes[panels:], extra, strict=True):
        draw(axis)
    return figure, axes, max((room for _, room in extra), default=0.0)


def attitude_error_panel(axis, telemetry: Mapping[str, np.ndarray]) -> None:
    """The angle from the true attitude to the reference's over time, degrees (gaps where
    the reference left the attitude free)."""
    error = np.degrees(np.asarray(telemetry["attitude_error"], dtype=float))
    axis.plot(telemetry["time"], error, color=TRUE_COLOUR, lw=1.0)
    axis.set(ylabel="error [deg]", title="Attitude error: angle to the reference's attitude")
    peak = float(np.nanmax(error))
    axis.set_ylim(
        bottom=0.0, top=1.2 * peak if peak > 0.0 else 1e-3
    )  # the tick labels say how small


def wheel_panel(axis, telemetry: Mapping[str, np.ndarray], actuators: ActuatorsSpec | None) -> None:
    """Each reaction wheel's momentum over time (N·m·s), with its limits when
    ``actuators`` (the scenario's) gives the wheels."""
    times = telemetry["time"]
    names = numbered_columns(telemetry, "wheel_h_")
    colours = plt.get_cmap("tab10")
    for i, name in enumerate(names):
        axis.plot(times, telemetry[name], color=colours(i % 10), lw=1.0, label=f"wheel {i + 1}")
    wheels = None if actuators is None else actuators.reaction_wheels
    if wheels is not None and len(wheels) == len(names):
        limits = sorted({wheel.max_momentum for wheel in wheels})
        for limit in limits:
            for sign in (1.0, -1.0):
                axis.axhline(sign * limit, color="k", ls="--", lw=0.8)
        axis.plot([], [], color="k", ls="--", lw=0.8, label="±max_momentum")
        if actuators is not None and actuators.thrusters is not None:
            start = actuators.unloading.start_fraction
            for limit in limits:
                for sign in (1.0, -1.0):
                    axis.axhline(sign * start * limit, color="0.4", ls=":", lw=0.8)
            axis.plot([], [], color="0.4", ls=":", lw=0.8, label="unloading starts")
        axis.set_ylim(-1.15 * limits[-1], 1.15 * limits[-1])
    axis.set(ylabel="momentum [N·m·s]", title="Reaction wheels: momentum about each spin axis")
    axis.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.0, 0.5))


def duty_panel(axis, telemetry: Mapping[str, np.ndarray], actuators: ActuatorsSpec | None) -> None:
    """Each thruster's duty cycle over time as a heat-map strip, one row per thruster,
    with a colour bar (0 to 1) to the right."""
    times = np.asarray(telemetry["time"], dtype=float)
    names = numbered_columns(telemetry, "duty_")
    duty = np.column_stack([np.asarray(telemetry[name], dtype=float) for name in names])
    step = float(times[-1] - times[-2]) if len(times) > 1 else 1.0
    edges = np.append(times, times[-1] + step)  # a row's duty holds until the next row
    firing = np.ma.masked_less_equal(duty.T, 0.0)  # idle cells left blank
    rows = np.arange(len(names) + 1) - 0.5
    mesh = axis.pcolormesh(edges, rows, firing, cmap=DUTY_COLOURS, vmin=0.0, vmax=1.0)
    axis.set_yticks(range(len(names)), thruster_labels(len(names), actuators), fontsize=6)
    axis.set_ylim(len(names) - 0.5, -0.5)  # thruster 1 on top
    axis.set(ylabel="thruster", title="Thrusters: duty cycle (fraction of each control period)")
    bar = axis.figure.colorbar(mesh, cax=axis.inset_axes((1.01, 0.0, 0.015, 1.0)))
    bar.set_label("duty", fontsize=8)
    bar.ax.tick_params(labelsize=7)


def thruster_labels(count: int, actuators: ActuatorsSpec | None) -> list[str]:
    """Names of ``count`` thrusters: their numbers and, when ``actuators`` (the scenario's)
    gives them, the body direction each pushes along (``3 -x``; rounded components when it
    is not along a body axis)."""
    thrusters = None if actuators is None else actuators.thrusters
    if thrusters is None or len(thrusters) != count:
        return [str(i) for i in range(1, count + 1)]
    return [f"{i} {_direction(t.direction)}" for i, t in enumerate(thrusters, 1)]


def _direction(direction: Sequence[float]) -> str:
    vector = np.asarray(direction, dtype=float)
    vector = vector / np.linalg.norm(vector)
    along = np.flatnonzero(np.abs(vector) > 1e-9)
    if len(along) == 1:
        sign = "+" if vector[along[0]] > 0 else "-"
        return f"{sign}{'xyz'[along[0]]}"
    return "[" + " ".join(f"{v:.2g}" for v in vector) + "]"


def _actuators(scenario: Scenario | None) -> ActuatorsSpec | None:
    """The base's actuators of ``scenario``'s robot (None without a scenario)."""
    if scenario is None:
        return None
    return scenario.robot.actuators
