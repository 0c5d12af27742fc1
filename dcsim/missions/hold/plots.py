"""A hold run's own picture, drawn into its ``plots/`` folder beside ``motion.png`` and
``estimation.png`` (:mod:`dcsim.report.plots`):

``timeline.png``
    The distance from the held position and the commanded torque, then the attitude
    error, the reaction wheels' momenta and the thrusters' duty cycles when the telemetry
    has them (:mod:`dcsim.report.hardware`).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from dcsim.report.hardware import timeline_axes
from dcsim.report.plots import (
    TRUE_COLOUR,
    FrameAxes,
    label_time,
    stack_layout,
    stacked,
    top_title,
    vector_lines,
    write_plots,
)
from dcsim.scenario.model import Scenario


def write_hold_plots(
    out_dir: Path, scenario: Scenario, telemetry: Mapping[str, np.ndarray]
) -> list[Path]:
    """Draw ``timeline.png``, then the pictures every run has
    (:func:`dcsim.report.plots.write_plots`), into ``out_dir/plots``.

    Parameters
    ----------
    out_dir : Path
        The run directory.
    scenario : Scenario
        The resolved scenario of a ``hold`` mission.
    telemetry : mapping of str to ndarray
        The telemetry columns.

    Returns
    -------
    list of Path
        The files written (none if there is no telemetry).
    """
    drawings = {"timeline.png": lambda: timeline_figure(scenario, telemetry)}
    return write_plots(out_dir, scenario, telemetry, drawings)


def timeline_figure(scenario: Scenario, telemetry: Mapping[str, np.ndarray]) -> Figure:
    """Distance from the held position and commanded torque over time, then the hardware
    panels the telemetry has data for.

    Parameters
    ----------
    scenario : Scenario
        The resolved scenario (frame, name).
    telemetry : mapping of str to ndarray
        The telemetry columns.
    """
    times = telemetry["time"]
    figure, axes, right = timeline_axes(scenario, telemetry, 2, 5.5)
    axes[0].plot(times, telemetry["position_error"], color=TRUE_COLOUR, lw=1.0)
    axes[0].set(ylabel="distance [m]", title="Distance from the held position")
    axes[0].set_ylim(bottom=0.0)
    names = FrameAxes.of(scenario, np.zeros(0)).names
    vector_lines(axes[1], times, stacked(telemetry, ("tx", "ty", "tz")), names, "|τ|")
    axes[1].set(ylabel="torque [N·m]", title="Commanded torque (world frame)")
    label_time(axes)
    for axis in axes:
        axis.grid(alpha=0.3)
    top_title(figure, f"{scenario.name}: timeline")
    stack_layout(figure, len(axes), left=1.1, right=max(right, 1.3))
    return figure
