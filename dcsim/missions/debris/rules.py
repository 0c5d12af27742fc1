"""The debris mission's rules across keys, checked with the scenario schema's."""

from __future__ import annotations

from dcsim.scenario.document import KeyPath
from dcsim.scenario.loader import ScenarioValues, cw_motion_rule


def reach_rule(get: ScenarioValues) -> list[tuple[KeyPath, str]]:
    """The collector holds off a target within its grab distance."""
    reach, grab = get("mission", "reach"), get("robot", "grab_distance")
    if reach <= grab:
        return []
    return [(("mission", "reach"), f"{reach:g} m is beyond robot.grab_distance ({grab:g} m)")]


def drop_point_rule(get: ScenarioValues) -> list[tuple[KeyPath, str]]:
    """A drop point is fixed or moving, not both."""
    position, motion = (
        get("mission", "drop_point", "position"),
        get("mission", "drop_point", "motion"),
    )
    if position is not None and motion is not None:
        return [(("mission", "drop_point", "motion"), "give either position or motion, not both")]
    return []


def drop_point_motion_rule(get: ScenarioValues) -> list[tuple[KeyPath, str]]:
    """A drop point on a ``cw`` motion needs the LVLH frame."""
    return cw_motion_rule(get, ("mission", "drop_point", "motion", "type"))


RULES = (reach_rule, drop_point_rule, drop_point_motion_rule)
"""The debris mission's rules, in the order their messages are listed."""
