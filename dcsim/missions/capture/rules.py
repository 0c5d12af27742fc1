"""The capture mission's rules across keys, checked with the scenario schema's."""

from __future__ import annotations

from dcsim.scenario.document import KeyPath
from dcsim.scenario.loader import ScenarioValues


def gripper_rule(get: ScenarioValues) -> list[tuple[KeyPath, str]]:
    """A capture needs a gripper at the end effector."""
    if get("robot", "type") != "manipulator" or get.given("robot", "gripper"):
        return []  # another robot type is refused by the mission's robot check
    return [(("robot", "gripper"), "a capture needs a gripper: add `gripper: {}` for the defaults")]


def frame_rule(get: ScenarioValues) -> list[tuple[KeyPath, str]]:
    """A capture flies in free space (no orbital relative accelerations)."""
    if get("world", "frame") != "lvlh":
        return []
    return [
        (
            ("world", "frame"),
            "a capture's tumbling body moves in free space, without the LVLH frame's "
            "relative accelerations: use `geocentric`",
        )
    ]


def planner_rule(get: ScenarioValues) -> list[tuple[KeyPath, str]]:
    """A capture plans its base's approach and its arm's intercept: it needs both planners."""
    needs = {
        "approach_planner": "a capture needs an approach planner for its base's flight to the "
        "approach gate: `straight-line` (the default), `ompl-geometric` or one of your own",
        "path_planner": "a capture needs a path planner for the arm's intercept of the "
        "fixture: `fixture-intercept` (the default) or one of your own",
    }
    return [((role,), message) for role, message in needs.items() if get(role) is None]


RULES = (gripper_rule, frame_rule, planner_rule)
"""The capture mission's rules, in the order their messages are listed."""
