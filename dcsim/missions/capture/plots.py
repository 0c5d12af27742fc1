"""A capture run's own picture, drawn into its ``plots/`` folder beside ``motion.png`` and
``estimation.png`` (:mod:`dcsim.report.plots`):

``capture.png``
    The bar's distance and speed from the point between the pads (log scale), the pads'
    normal forces and the peak force on the body against the gripper's limit, the
    target's and the base's angular rates, and the base's turn from its attitude at the
    standoff; contact, latch and detumble are marked.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from dcsim.report.plots import label_time, stack_layout, stacked, top_title, write_plots
from dcsim.scenario.model import Scenario

_OFFSET = ("fixture_dx", "fixture_dy", "fixture_dz")
_SPEED = ("fixture_dvx", "fixture_dvy", "fixture_dvz")
_MARKED = {"contact": "tab:orange", "latched": "tab:green", "detumbled": "tab:purple"}
"""Events drawn as vertical lines, with their colours."""


def write_capture_plots(
    out_dir: Path,
    scenario: Scenario,
    telemetry: Mapping[str, np.ndarray],
    events: Sequence[Mapping[str, Any]],
) -> list[Path]:
    """Draw ``capture.png``, then the pictures every run has
    (:func:`dcsim.report.plots.write_plots`), into ``out_dir/plots``.

    Returns
    -------
    list of Path
        The files written (none if there is no telemetry).
    """
    drawings = {"capture.png": lambda: capture_figure(scenario, telemetry, events)}
    return write_plots(out_dir, scenario, telemetry, drawings)


def capture_figure(
    scenario: Scenario,
    telemetry: Mapping[str, np.ndarray],
    events: Sequence[Mapping[str, Any]],
) -> Figure:
    """The capture's four panels over time (see the module)."""
    import matplotlib.pyplot as plt

    times = telemetry["time"]
    figure, axes = plt.subplots(4, 1, figsize=(8.0, 10.0), sharex=True)
    offset = np.linalg.norm(stacked(telemetry, ("fixture_dx", "fixture_dy", "fixture_dz")), axis=1)
    speed = np.linalg.norm(
        stacked(telemetry, ("fixture_dvx", "fixture_dvy", "fixture_dvz")), axis=1
    )
    axes[0].semilogy(times, np.maximum(offset, 1e-6), label="distance [m]")
    axes[0].semilogy(times, np.maximum(speed, 1e-6), label="speed [m/s]")
    axes[0].set(title="The bar from the point between the pads")
    axes[1].plot(times, telemetry["pad_force_left"], label="left pad (normal)")
    axes[1].plot(times, telemetry["pad_force_right"], label="right pad (normal)")
    axes[1].plot(times, telemetry["contact_force"], label="peak on the body", alpha=0.7)
    gripper = getattr(scenario.robot, "gripper", None)
    if gripper is not None:
        axes[1].axhline(gripper.force_limit, color="tab:red", ls="--", label="force limit")
    axes[1].set(ylabel="force [N]", title="Grip")
    axes[2].plot(times, np.degrees(telemetry["target_rate"]), label="target")
    axes[2].plot(times, np.degrees(telemetry["base_rate"]), label="base")
    axes[2].set(ylabel="rate [deg/s]", title="Angular rates")
    axes[3].plot(times, np.degrees(telemetry["base_turn"]), color="black", lw=1.0)
    axes[3].set(ylabel="turn [deg]", title="Base's turn from its attitude at the standoff")
    for event in events:
        colour = _MARKED.get(str(event.get("event")))
        if colour is not None:
            for axis in axes:
                axis.axvline(float(event["t"]), color=colour, lw=0.8, ls=":")
    for axis in axes:
        axis.grid(alpha=0.3)
    for axis in axes[:3]:
        axis.legend(loc="upper right", fontsize=7)
    label_time(axes)
    top_title(figure, f"{scenario.name}: capture")
    stack_layout(figure, len(axes), left=1.1)
    return figure
