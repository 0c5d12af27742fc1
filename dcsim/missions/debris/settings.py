"""The debris mission's scenario section: how the executer flies the collection."""

from __future__ import annotations

from typing import ClassVar, Literal

from pydantic import Field

from dcsim.missions.debris.rules import RULES
from dcsim.params import quantity
from dcsim.scenario.loader import Rule
from dcsim.scenario.model import MissionSettings


class DebrisMissionSection(MissionSettings):
    """How the executer flies the debris-collection mission (the thesis's §5.2 and §5.4)."""

    rules: ClassVar[tuple[Rule, ...]] = RULES

    type: Literal["debris"] = Field(
        "debris",
        description="The mission type: debris collection (the debris collector thesis).",
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
