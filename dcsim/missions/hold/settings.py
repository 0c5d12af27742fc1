"""The hold mission's scenario section: the position and attitude held."""

from __future__ import annotations

from typing import ClassVar, Literal

from pydantic import Field

from dcsim.params import quantity
from dcsim.scenario.model import MissionSettings, PluginChoice, Quaternion, Vec3


class HoldMissionSection(MissionSettings):
    """A hold: keep a position and an attitude for the whole run (station keeping)."""

    role_defaults: ClassVar[dict[str, PluginChoice | None]] = {"localiser": None}

    type: Literal["hold"] = Field(
        "hold", description="The mission type: hold a position and an attitude."
    )
    position: Vec3 | None = quantity(
        None, unit="m", description="Position held, world frame; null: the initial position."
    )
    attitude: Quaternion | None = quantity(
        None,
        description="Attitude held [x, y, z, w] (normalised; not zero); null: the initial "
        "attitude.",
    )
    hold_position: bool = Field(
        True,
        description="Hold the position; false leaves translation free (the reference "
        "follows the estimate, so no force is asked for) and holds the attitude only.",
    )
