"""The reach mission's scenario section: the end-effector target and the path's limits."""

from __future__ import annotations

import math
from typing import ClassVar, Literal

from pydantic import Field, field_validator

from dcsim.params import quantity
from dcsim.scenario.model import MissionSettings, PluginChoice, Vec3


class ReachMissionSection(MissionSettings):
    """A reach: a manipulator's end effector from where it starts to a target."""

    role_defaults: ClassVar[dict[str, PluginChoice | None]] = {
        "localiser": None,
        "path_planner": PluginChoice(plugin="end-effector-line"),
        "controller": PluginChoice(plugin="computed-torque"),
    }

    type: Literal["reach"] = Field(
        "reach", description="The mission type: a manipulator's end effector to a target."
    )
    target: Vec3 = quantity(unit="m", description="End-effector target, world frame.")
    tolerance: float = quantity(
        1e-3,
        unit="m",
        gt=0,
        description="End-effector distance to the target that counts as "
        "reached, once the path has ended.",
    )
    max_speed: float = quantity(
        0.1, unit="m/s", gt=0, description="End-effector speed the path may reach."
    )
    max_acceleration: float = quantity(
        0.1, unit="m/s^2", gt=0, description="End-effector acceleration the path may reach."
    )
    facing_axis: Vec3 | None = quantity(
        None,
        description="Base-frame direction of the base's side that must face the target; "
        "null: the base axis (±x, ±y, ±z) nearest the target's direction at the start.",
    )
    ik_gain: float = quantity(
        20.0,
        unit="1/s",
        gt=0,
        description="Gain pulling the joint references' inverse kinematics back onto the "
        "end-effector path.",
    )
    planning_budget: float = quantity(
        5.0, unit="s", gt=0, description="Wall time given to the path planner."
    )

    @field_validator("facing_axis")
    @classmethod
    def _nonzero_axis(cls, axis: Vec3 | None) -> Vec3 | None:
        if axis is not None and math.hypot(*axis) < 1e-12:
            raise ValueError("the facing axis must not be zero")
        return axis
