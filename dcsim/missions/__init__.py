"""Mission types, selected in a scenario by ``mission.type``.

Built in: ``debris`` (:class:`~dcsim.missions.debris.DebrisMission`), ``transfer``
(:class:`~dcsim.missions.transfer.TransferMission`), ``reach``
(:class:`~dcsim.missions.reach.ReachMission`) and ``hold``
(:class:`~dcsim.missions.hold.HoldMission`). A new mission
derives from :class:`~dcsim.missions.base.Mission`, declares its ``Settings`` section,
and is added with :func:`register_mission`.
"""

from __future__ import annotations

from dcsim.interfaces import PLUGIN_KINDS
from dcsim.missions.base import Mission
from dcsim.missions.debris import DebrisMission
from dcsim.missions.hold import HoldMission
from dcsim.missions.reach import ReachMission
from dcsim.missions.transfer import TransferMission
from dcsim.scenario.model import Scenario

_MISSIONS: dict[str, type[Mission]] = {
    DebrisMission.type: DebrisMission,
    TransferMission.type: TransferMission,
    ReachMission.type: ReachMission,
    HoldMission.type: HoldMission,
}


def register_mission(cls: type[Mission]) -> type[Mission]:
    """Make mission class ``cls`` selectable as ``mission.type: <cls.type>``.

    Returns ``cls``, so that it can be used as a class decorator.

    Raises
    ------
    ValueError
        If another class already has that type.
    """
    known = _MISSIONS.get(cls.type)
    if known is not None and known is not cls:
        raise ValueError(f"mission type '{cls.type}' is already taken by {known.__qualname__}")
    _MISSIONS[cls.type] = cls
    return cls


def mission_types() -> dict[str, type[Mission]]:
    """Every mission class by its type."""
    return dict(_MISSIONS)


def scenario_roles(scenario: Scenario) -> tuple[str, ...]:
    """The plugin roles a scenario's run uses, in data-flow order.

    Those its mission needs, and the optional ones (``role_defaults`` of None in the
    mission's settings) for which the scenario names a plugin.
    """
    mission = mission_class(scenario.mission.type)
    optional = [role for role, default in mission.Settings.role_defaults.items() if default is None]
    used = set(mission.roles) | {role for role in optional if getattr(scenario, role) is not None}
    return tuple(role for role in PLUGIN_KINDS if role in used)


def mission_class(mission_type: str) -> type[Mission]:
    """The mission class of ``mission_type``.

    Raises
    ------
    KeyError
        If no mission has that type.
    """
    return _MISSIONS[mission_type]


__all__ = [
    "DebrisMission",
    "HoldMission",
    "Mission",
    "ReachMission",
    "TransferMission",
    "mission_class",
    "mission_types",
    "register_mission",
    "scenario_roles",
]
