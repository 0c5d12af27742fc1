"""The capture mission's scenario section: the tumbling target and the capture's limits."""

from __future__ import annotations

from typing import ClassVar, Literal

from pydantic import Field

from dcsim.missions.capture.rules import RULES
from dcsim.params import quantity
from dcsim.scenario.loader import Rule
from dcsim.scenario.model import MissionSettings, PluginChoice, TumblingBodySpec


class CaptureMissionSection(MissionSettings):
    """A capture: a manipulator grasps a tumbling body's grapple fixture and detumbles it."""

    rules: ClassVar[tuple[Rule, ...]] = RULES
    body_key: ClassVar[str | None] = "target"
    role_defaults: ClassVar[dict[str, PluginChoice | None]] = {
        "localiser": None,
        "approach_planner": PluginChoice(plugin="straight-line"),
        "path_planner": PluginChoice(plugin="fixture-intercept"),
        "controller": PluginChoice(plugin="capture-detumble"),
    }

    type: Literal["capture"] = Field(
        "capture", description="The mission type: grasp and detumble a tumbling body."
    )
    target: TumblingBodySpec = Field(description="The tumbling body and its grapple fixture.")
    standoff: float = quantity(
        3.0,
        unit="m",
        gt=0,
        description="Distance from the target's centre of mass at which the base stops.",
    )
    standoff_height: float = quantity(
        0.3,
        unit="m",
        description="Height of the target's centre of mass above the base's centre at the "
        "standoff, along the base's z axis: an arm reaching straight ahead at its shoulder's "
        "height is near a singularity.",
    )
    acquisition_time: float = quantity(
        10.0,
        unit="s",
        gt=0,
        description="Time the tracker follows the target from the start before the standoff "
        "is chosen from its track (no wait when the track is exact, under ideal object "
        "sensing).",
    )
    approach_clearance: float = quantity(
        0.5,
        unit="m",
        gt=0,
        description="Least gap the approach planner keeps between the robot's sphere (its "
        "base and its arm as held) and the target's bounding sphere; the approach gate, where "
        "the planned flight ends and the straight move in along the momentum axis begins, "
        "lies twice this gap out (or at the standoff, if that is farther). A robot that "
        "starts inside the keep-out must be within this distance of the line from the "
        "standoff to the gate.",
    )
    approach_speed: float = quantity(
        0.1, unit="m/s", gt=0, description="Largest speed of the base's approach."
    )
    approach_acceleration: float = quantity(
        0.01, unit="m/s^2", gt=0, description="Largest acceleration of the base's approach."
    )
    observation_time: float = quantity(
        5.0,
        unit="s",
        ge=0,
        description="Time the target is watched at the standoff before the arm's path is planned.",
    )
    arm_speed: float = quantity(
        0.2, unit="m/s", gt=0, description="Largest end-effector speed of the arm's transfer."
    )
    arm_acceleration: float = quantity(
        0.05,
        unit="m/s^2",
        gt=0,
        description="Largest end-effector acceleration of the arm's transfer.",
    )
    grasp_tolerance: float = quantity(
        0.005,
        unit="m",
        gt=0,
        description="Largest distance the arm's joints may fall behind the planned path.",
    )
    hold_time: float = quantity(
        0.5,
        unit="s",
        gt=0,
        description="Time both pads must press on the bar with it not slipping before the "
        "grip counts as holding and the latch closes.",
    )
    slip_speed: float = quantity(
        0.005,
        unit="m/s",
        gt=0,
        description="Speed of the bar relative to the pads above which the grip is slipping.",
    )
    detumbled_rate_deg_s: float = quantity(
        0.1,
        unit="deg/s",
        gt=0,
        description="Angular rate of the stack (base and target) below which it is detumbled.",
    )
    max_base_excursion_deg: float = quantity(
        5.0,
        unit="deg",
        gt=0,
        description="Largest turn of the base from its attitude at the standoff that counts "
        "as held.",
    )
    planning_budget: float = quantity(
        5.0,
        unit="s",
        gt=0,
        description="Wall time given to each planner: the approach's and the intercept's.",
    )
