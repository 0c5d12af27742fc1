"""Mission types, selected in a scenario by ``mission.type``, found as plugins are.

A mission is a package: its scenario section (a
:class:`~dcsim.scenario.model.MissionSettings` subclass, with its rules across keys),
its :class:`~dcsim.missions.base.Mission` subclass (roles, modes, telemetry columns and
units, summary fields, plots, end) and its docs. Missions are found through the entry
point group ``dcsim.missions``: the entry point's name is the mission type and its value
the mission class, so a third party adds a mission in its own distribution::

    [project.entry-points."dcsim.missions"]
    capture = "my_package.capture:CaptureMission"

dcsim's own missions are found the same way: ``debris``
(:mod:`dcsim.missions.debris`), ``transfer`` (:mod:`dcsim.missions.transfer`), ``reach``
(:mod:`dcsim.missions.reach`) and ``hold`` (:mod:`dcsim.missions.hold`). A mission class
defined at run time (a test, a notebook) is added with :func:`register_mission`.
"""

from __future__ import annotations

import functools
import importlib.metadata as md
import warnings

from dcsim.errors import PluginLoadWarning
from dcsim.missions.base import Mission, RoleKind
from dcsim.registry.discovery import BUILTIN_DISTRIBUTION
from dcsim.registry.interfaces import PLUGIN_KINDS
from dcsim.scenario.model import Scenario
from dcsim.scenario.sensors import sensor_choices

MISSION_GROUP = "dcsim.missions"
"""The entry point group missions are found in."""

_REGISTERED: dict[str, type[Mission]] = {}


@functools.cache
def _installed() -> dict[str, type[Mission]]:
    """The missions of every installed distribution's ``dcsim.missions`` entry points
    (dcsim's own first); one that fails to load, or names no mission class of its own
    type, is skipped with a :class:`~dcsim.errors.PluginLoadWarning`."""
    found: dict[str, type[Mission]] = {}
    entry_points = sorted(
        md.entry_points(group=MISSION_GROUP),
        key=lambda e: e.dist is None or e.dist.name != BUILTIN_DISTRIBUTION,
    )
    for ep in entry_points:
        where = f"entry point '{ep.name}' = {ep.value}" + (f" of {ep.dist.name}" if ep.dist else "")
        try:
            cls = ep.load()
        except Exception as error:  # any import failure of a third-party package
            _skip(f"mission {where} failed to load: {type(error).__name__}: {error}")
            continue
        problem = _class_problem(cls, ep.name)
        if problem is None and ep.name in found:
            problem = f"type '{ep.name}' is already taken by {found[ep.name].__qualname__}"
        if problem is not None:
            _skip(f"mission {where} was skipped: {problem}")
            continue
        found[ep.name] = cls
    return found


def _class_problem(cls: object, mission_type: str) -> str | None:
    """Why ``cls`` cannot be the mission of ``mission_type`` (None if it can)."""
    if not (isinstance(cls, type) and issubclass(cls, Mission)):
        return f"{cls!r} is not a subclass of dcsim.api.Mission"
    if getattr(cls, "type", None) != mission_type:
        return f"{cls.__qualname__}.type is {getattr(cls, 'type', None)!r}, not '{mission_type}'"
    return None


def _skip(message: str) -> None:
    warnings.warn(message, PluginLoadWarning, stacklevel=3)


def register_mission(cls: type[Mission]) -> type[Mission]:
    """Make mission class ``cls`` selectable as ``mission.type: <cls.type>`` in this process.

    For a class made at run time; a distribution declares its missions in the
    ``dcsim.missions`` entry point group instead. Returns ``cls``, so that it can be
    used as a class decorator.

    Raises
    ------
    ValueError
        If another class already has that type.
    """
    known = mission_types().get(cls.type)
    if known is not None and known is not cls:
        raise ValueError(f"mission type '{cls.type}' is already taken by {known.__qualname__}")
    _REGISTERED[cls.type] = cls
    return cls


def mission_types() -> dict[str, type[Mission]]:
    """Every mission class by its type: the installed ones, then those registered."""
    return {**_installed(), **_REGISTERED}


def scenario_roles(scenario: Scenario) -> dict[str, RoleKind]:
    """The plugin roles a scenario's run uses, in data-flow order.

    Those its mission uses for which the scenario names a plugin (a role the mission's
    ``role_defaults`` list may be null: none), and the tracker when an object sensor
    has a model. Roles of one kind keep the mission's order.

    Returns
    -------
    dict of str to RoleKind
        Each role's plugin kind and the robot type its plugin must support.
    """
    mission = mission_class(scenario.mission.type)
    roles = dict.fromkeys((*mission.roles, *mission.Settings.role_defaults))
    used = [role for role in roles if getattr(scenario, role, None) is not None]
    if sensor_choices(scenario.sensors)["objects"] is not None:
        used.append("tracker")  # detections become tracks
    kinds = {role: _role_kind(mission, role, scenario.robot.type) for role in used}
    order = list(PLUGIN_KINDS)
    return dict(sorted(kinds.items(), key=lambda item: order.index(item[1].kind)))


def _role_kind(mission: type[Mission], role: str, robot: str) -> RoleKind:
    """The plugin kind of a mission's role and the robot type its plugin must support.

    Parameters
    ----------
    mission : type of Mission
        The mission class.
    role : str
        One of its roles: a plugin kind's name, or a name of its ``role_kinds``.
    robot : str
        The scenario's robot type, which the role's plugin supports unless the mission
        names another.

    Returns
    -------
    RoleKind
        The kind, and the robot type (never None).
    """
    kind = mission.role_kinds.get(role, RoleKind(role))
    return RoleKind(kind.kind, kind.robot or robot)


def mission_class(mission_type: str) -> type[Mission]:
    """The mission class of ``mission_type``.

    Raises
    ------
    KeyError
        If no mission has that type.
    """
    return mission_types()[mission_type]


__all__ = [
    "MISSION_GROUP",
    "Mission",
    "RoleKind",
    "mission_class",
    "mission_types",
    "register_mission",
    "scenario_roles",
]
