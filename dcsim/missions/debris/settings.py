"""The debris mission's scenario section: how the executer flies the collection."""

from __future__ import annotations

from typing import ClassVar, Literal

from pydantic import Field

from dcsim.missions.debris.rules import RULES
from dcsim.motion import MotionModel, StaticMotion
from dcsim.params import quantity
from dcsim.scenario.loader import Rule
from dcsim.scenario.model import (
    MissionSettings,
    MotionSpec,
    PluginChoice,
    Point,
    Section,
    SpaceObjectSpec,
    point_to_cartesian,
)


class DropPointSection(Section):
    """Where targets are delivered: a fixed ``position`` or a ``motion``."""

    position: Point | None = quantity(
        None, unit="m", description="Fixed position (or give `motion`)."
    )
    motion: MotionSpec | None = Field(
        None, description="Motion of a moving drop point (or give `position`)."
    )
    tolerance: float = quantity(
        2.0, unit="m", gt=0, description="Distance within which cargo is released."
    )

    def build(self, mean_motion: float) -> MotionModel:
        """The drop point's motion model."""
        if self.motion is not None:
            return self.motion.build(mean_motion)
        return StaticMotion(point_to_cartesian(self.position or (0.0, 0.0, 0.0)))


class DebrisMissionSection(MissionSettings):
    """How the executer flies the debris-collection mission (the thesis's §5.2 and §5.4)."""

    role_defaults: ClassVar[dict[str, PluginChoice | None]] = {
        "path_planner": PluginChoice(plugin="straight-line"),
    }
    rules: ClassVar[tuple[Rule, ...]] = RULES
    targets_key: ClassVar[str | None] = "targets"
    moved_keys: ClassVar[dict[tuple[str, ...], tuple[str, ...]]] = {
        ("targets",): ("mission", "targets"),
        ("drop_point",): ("mission", "drop_point"),
        ("stop", "on_all_delivered"): ("mission", "stop_on_all_delivered"),
    }

    type: Literal["debris"] = Field(
        "debris",
        description="The mission type: debris collection (the debris collector thesis).",
    )
    targets: list[SpaceObjectSpec] = Field(default_factory=list, description="Objects to collect.")
    drop_point: DropPointSection = Field(
        default_factory=DropPointSection, description="Where the targets are delivered."
    )
    stop_on_all_delivered: bool = Field(
        True, description="End the run once every target is delivered."
    )

    reach: float = quantity(
        0.5,
        unit="m",
        gt=0,
        description="Surface gap to a target at which GRAB is entered with an empty hold "
        "(REACH; the collector holds at half of it); at most robot.grab_distance. With cargo "
        "on board the collector holds clear of the cargo (docs/architecture.md, Mission).",
    )
    safety_distance: float = quantity(
        2.0,
        unit="m",
        ge=0,
        description="Least surface gap to keep from obstacles (SAFETY_DISTANCE): the path "
        "planner's safety margin (PathProblem.safety_margin), also given to the controller and "
        "marked on the run's plots.",
    )
    drop_speed: float = quantity(
        0.0,
        unit="m/s",
        ge=0,
        description="Speed limit on the way to the drop point (DROP_SPEED); 0 for robot.max_speed.",
    )
    attitude: Literal["hold", "free"] = Field(
        "hold",
        description="The collector's attitude reference: `hold` keeps the attitude it "
        "starts with (robot.initial.attitude), fixed in the world frame (LVLH-fixed in an "
        "`lvlh` world), through grabs and releases; `free` leaves it free (no torque is "
        "asked for).",
    )
    pickup_slack: float = quantity(
        30.0, unit="s", ge=0, description="How late a pickup may be before the plan is remade."
    )
    acceleration_fraction: float = quantity(
        0.5,
        gt=0,
        le=1,
        description="Fraction of the thrust-limited acceleration that plans may use; "
        "the rest is left to the controller.",
    )
    planning_budget: float = quantity(
        1.0, unit="s", gt=0, description="Wall time given to a planner call."
    )
    path_retry: float = quantity(
        5.0,
        unit="s",
        gt=0,
        description="Wait before asking again after the path planner found no path.",
    )
    max_plan_attempts: int = quantity(
        3,
        ge=1,
        description='"No path" answers in a row after which the run ends stopped.',
    )
    release_fraction: float = quantity(
        0.5,
        gt=0,
        le=1,
        description="Fraction of the drop tolerance within which the collector releases its cargo.",
    )
