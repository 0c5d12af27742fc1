"""The ``hold`` mission: keep a position and an attitude for the whole run.

Station keeping, and the simplest closed loop dcsim flies: every control tick the
reference is the held position at rest and the held attitude at rest, and the run goes
on until ``world.duration``. With ``hold_position: false`` translation is left free:
the reference's position and velocity are the estimate's own, so a controller that
tracks them (``pd``) asks for no force, and only the attitude is held. No planner is
asked; a localiser is used only when the scenario names one (otherwise the true state
is fed).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from dcsim.geometry import attitude_error, length
from dcsim.messages import Observations, Reference, StateEstimate
from dcsim.missions.base import Emit, Mission, MissionWorld
from dcsim.missions.hold.settings import HoldMissionSection
from dcsim.registry.interfaces import Plugin
from dcsim.scenario.model import Scenario, point_to_cartesian


class HoldMission(Mission):
    """Holds a position (or leaves translation free) and an attitude until the run ends.

    Parameters
    ----------
    scenario : Scenario
        The resolved scenario; ``scenario.mission`` is a :class:`HoldMissionSection`.
    world : MissionWorld
        The world.
    plugins : mapping of str to Plugin
        The controller and, if the scenario names one, the localiser.
    emit : callable
        ``emit(event_name, **data)`` records an event.

    Attributes
    ----------
    position : ndarray (3,)
        The position held, world frame, m (the initial one unless the section gives one).
    attitude : ndarray (4,)
        The attitude held ``[x, y, z, w]``, unit length.
    """

    type = "hold"
    summary = "hold a position and an attitude (station keeping)"
    Settings = HoldMissionSection
    roles = ("controller",)
    modes = ("HOLD",)
    columns = ("position_error", "tx", "ty", "tz")
    units = {"position_error": "m", "tx": "Nm", "ty": "Nm", "tz": "Nm"}
    summary_names = (
        "final_position_error_m",
        "final_attitude_error_deg",
        "max_position_error_m",
    )
    settings: HoldMissionSection

    def __init__(
        self, scenario: Scenario, world: MissionWorld, plugins: Mapping[str, Plugin], emit: Emit
    ) -> None:
        super().__init__(scenario, world, plugins, emit)
        initial = scenario.robot.initial
        settings = self.settings
        self.position = point_to_cartesian(
            initial.position if settings.position is None else settings.position
        )
        attitude = np.asarray(
            initial.attitude if settings.attitude is None else settings.attitude, dtype=float
        )
        self.attitude = attitude / length(attitude)
        self.position_error = 0.0
        self.attitude_error = 0.0
        self.max_position_error = 0.0

    @property
    def mode(self) -> str:
        """Always HOLD."""
        return "HOLD"

    def tick(self, time: float, estimate: StateEstimate, observations: Observations) -> Reference:
        """The held position (or the estimate's, translation free) and attitude, at rest."""
        if self.settings.hold_position:
            return Reference(time=time, position=self.position, attitude=self.attitude)
        return Reference(
            time=time,
            position=estimate.position,
            velocity=estimate.velocity,
            attitude=self.attitude,
        )

    def telemetry(self, outputs: Mapping[str, Any]) -> dict[str, Any]:
        """True distance to the held position (m) and the commanded torque (world frame,
        N·m); every run records the angle to the held attitude (``attitude_error``)."""
        self.position_error = length(outputs["position"] - self.position)
        self.attitude_error = attitude_error(outputs["attitude"], self.attitude)
        self.max_position_error = max(self.max_position_error, self.position_error)
        tx, ty, tz = (float(v) for v in outputs["command"].torque)
        return {
            "position_error": self.position_error,
            "tx": tx,
            "ty": ty,
            "tz": tz,
        }

    def plot(
        self,
        out_dir: Path,
        telemetry: Mapping[str, np.ndarray],
        events: Sequence[Mapping[str, Any]],
    ) -> list[Path]:
        """Draw ``timeline.png`` (position error, commanded torque and the hardware panels
        the telemetry has data for), then the motion and the estimation error
        (:func:`dcsim.missions.hold.plots.write_hold_plots`)."""
        from dcsim.missions.hold.plots import write_hold_plots  # loads matplotlib

        return write_hold_plots(out_dir, self.scenario, telemetry)

    def progress(self) -> str:
        """The latest attitude and position errors."""
        return (
            f"holding: attitude error {np.degrees(self.attitude_error):.3g} deg, "
            f"position error {self.position_error:.3g} m"
        )

    def summary_fields(self) -> dict[str, Any]:
        """The last recorded errors and the largest distance from the held position."""
        return {
            "final_position_error_m": self.position_error,
            "final_attitude_error_deg": float(np.degrees(self.attitude_error)),
            "max_position_error_m": self.max_position_error,
        }
