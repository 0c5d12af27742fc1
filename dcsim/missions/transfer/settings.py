"""The transfer mission's scenario section: the goal region, bounds, cost weights, retries."""

from __future__ import annotations

from typing import ClassVar, Literal

import numpy as np
from pydantic import Field, model_validator

from dcsim.messages.planning import GoalRegion
from dcsim.params import quantity
from dcsim.scenario.model import MissionSettings, PluginChoice, Section, Vec3


class GoalSection(Section):
    """The goal region of a transfer: a sphere or a box, and what must hold on arrival."""

    position: Vec3 = quantity(unit="m", description="Centre of the goal region.")
    radius: float | None = quantity(
        None, unit="m", gt=0, description="Radius of a spherical region (or give `half_extents`)."
    )
    half_extents: Vec3 | None = quantity(
        None,
        unit="m",
        description="Half side lengths of an axis-aligned box region (instead of `radius`).",
    )
    velocity: Vec3 = quantity((0.0, 0.0, 0.0), unit="m/s", description="Velocity to arrive with.")
    velocity_tolerance: float | None = quantity(
        None,
        unit="m/s",
        ge=0,
        description="Largest arrival velocity error; null: not checked.",
    )
    attitude: tuple[float, float, float, float] | None = quantity(
        None, description="Attitude quaternion [x, y, z, w] to arrive at; null: any."
    )
    attitude_tolerance_deg: float = quantity(
        5.0, unit="deg", gt=0, le=180, description="Largest arrival attitude error."
    )
    arrival_time: float | None = quantity(
        None, unit="s", ge=0, description="Time to arrive at; null: as soon as allowed."
    )
    time_tolerance: float | None = quantity(
        None, unit="s", ge=0, description="Largest arrival time error; null: not checked."
    )

    @model_validator(mode="after")
    def _one_region(self) -> GoalSection:
        """A region is a sphere or a box: exactly one of the two is given."""
        if (self.radius is None) == (self.half_extents is None):
            raise ValueError("give either radius (a sphere) or half_extents (a box)")
        return self

    def build(self) -> GoalRegion:
        """The goal region message."""
        return GoalRegion(
            position=np.array(self.position),
            tolerance=0.0 if self.radius is None else self.radius,
            velocity=np.array(self.velocity),
            time=self.arrival_time,
            half_extents=None if self.half_extents is None else np.array(self.half_extents),
            attitude=None
            if self.attitude is None
            else np.asarray(self.attitude) / np.linalg.norm(self.attitude),
            attitude_tolerance=np.radians(self.attitude_tolerance_deg),
            velocity_tolerance=np.inf
            if self.velocity_tolerance is None
            else self.velocity_tolerance,
            time_tolerance=np.inf if self.time_tolerance is None else self.time_tolerance,
        )


class BoundsSection(Section):
    """An axis-aligned box the path must stay in."""

    lower: Vec3 = quantity(unit="m", description="Lowest corner.")
    upper: Vec3 = quantity(unit="m", description="Highest corner.")


class WeightsSection(Section):
    """Weights of a path's cost J = w_dv Δv + w_L L + w_T T."""

    delta_v: float = quantity(1.0, unit="s/m", ge=0, description="Weight on delta-v.")
    length: float = quantity(0.0, unit="1/m", ge=0, description="Weight on path length.")
    time: float = quantity(0.0, unit="1/s", ge=0, description="Weight on duration.")


class TransferMissionSection(MissionSettings):
    """A transfer: from the robot's initial state to a goal region among obstacles."""

    role_defaults: ClassVar[dict[str, PluginChoice | None]] = {
        "localiser": None,
        "path_planner": PluginChoice(plugin="straight-line"),
    }

    type: Literal["transfer"] = Field(
        "transfer", description="The mission type: a transfer to a goal region."
    )
    goal: GoalSection = Field(description="The goal region and what must hold on arrival.")
    bounds: BoundsSection | None = Field(None, description="Box the path must stay in; null: none.")
    weights: WeightsSection = Field(
        default_factory=WeightsSection, description="Path cost weights given to the planner."
    )
    max_delta_v: float | None = quantity(
        None, unit="m/s", gt=0, description="Largest total delta-v of a plan; null: none."
    )
    acceleration_fraction: float = quantity(
        0.5,
        gt=0,
        le=1,
        description="Fraction of the thrust-limited acceleration that plans may use.",
    )
    planning_budget: float = quantity(
        5.0, unit="s", gt=0, description="Wall time given to a planner call."
    )
    retry: float = quantity(
        5.0, unit="s", gt=0, description='Wait before planning again after "no path".'
    )
    tracking_tolerance: float = quantity(
        2.0,
        unit="m",
        gt=0,
        description="Re-plan from the estimate when it strays this far from the trajectory.",
    )
    safety_distance: float = quantity(
        0.0,
        unit="m",
        ge=0,
        description="Least surface gap to obstacles: the path planner's safety margin "
        "(PathProblem.safety_margin), also given to the controller.",
    )
    max_plan_attempts: int = quantity(
        3,
        ge=1,
        description='"No path" answers in a row after which the run ends stopped.',
    )
