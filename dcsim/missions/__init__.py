"""Mission types, selected in a scenario by ``mission.type``.

Built in: ``debris`` (:class:`~dcsim.missions.debris.DebrisMission`). A new mission
derives from :class:`~dcsim.missions.base.Mission`, declares its ``Settings`` section,
and is added with :func:`register_mission`.
"""

from __future__ import annotations

from dcsim.missions.base import Mission
from dcsim.missions.debris import DebrisMission

_MISSIONS: dict[str, type[Mission]] = {DebrisMission.type: DebrisMission}


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


def mission_class(mission_type: str) -> type[Mission]:
    """The mission class of ``mission_type``.

    Raises
    ------
    KeyError
        If no mission has that type.
    """
    return _MISSIONS[mission_type]


__all__ = ["DebrisMission", "Mission", "mission_class", "mission_types", "register_mission"]
