"""``dcsim new-plugin``: write an out-of-tree plugin or mission package that works as generated.

The package has a ``pyproject.toml`` declaring its entry point (in its kind's group, such
as ``dcsim.controllers``, for a plugin; ``dcsim.missions`` for a mission), the plugin
class with its parameter model (a simple but real algorithm of the kind) or the mission
with its settings (flying to a point and holding it), a test file running dcsim's
conformance suite (for a mission, on an example scenario it ships), and a README. It
installs with ``pip install -e``.
"""

from __future__ import annotations

import re
from importlib import resources
from pathlib import Path
from string import Template

from dcsim import __version__
from dcsim.errors import DcsimError
from dcsim.registry.discovery import PluginRegistry, kind_group
from dcsim.registry.interfaces import PLUGIN_KINDS

MISSION = "mission"
"""The kind ``dcsim new-plugin`` writes a mission package for."""

KINDS = (*PLUGIN_KINDS, MISSION)
"""What ``dcsim new-plugin`` can write a package for."""

_NAME = re.compile(r"^[a-z][a-z0-9_-]*$")
_SUMMARIES = {
    "sensor": "A star tracker with white noise",
    "tracker": "Constant-velocity Kalman filter per object, by identity",
    "localiser": "Gauss-Newton multilateration on beacon ranges",
    "task_planner": "Targets in order of distance, drop visits when full",
    "path_planner": "Straight segment, trapezoidal speed, obstacle-checked",
    "controller": "Proportional position control with velocity damping",
    MISSION: "Fly to a point and hold it there",
}
_SUFFIXES = {
    "sensor": "Sensor",
    "tracker": "Tracker",
    "localiser": "Localiser",
    "task_planner": "TaskPlanner",
    "path_planner": "PathPlanner",
    "controller": "Controller",
    MISSION: "Mission",
}
_CONTRACTS = {
    "sensor": "SensorModelContract",
    "tracker": "TrackerContract",
    "localiser": "LocaliserContract",
    "task_planner": "TaskPlannerContract",
    "path_planner": "PathPlannerContract",
    "controller": "ControllerContract",
}


class ScaffoldError(DcsimError):
    """The plugin package cannot be written as asked."""


def _template(name: str) -> Template:
    text = (resources.files("dcsim") / "templates" / "plugin" / name).read_text(encoding="utf-8")
    return Template(text)


def new_plugin(
    kind: str, name: str, directory: Path, registry: PluginRegistry | None = None
) -> Path:
    """Write the package of a new ``kind`` plugin called ``name`` under ``directory``.

    Parameters
    ----------
    kind, name : str
        The plugin's kind (``controller``...) or ``mission``, and its name
        (``my-controller``; a mission's name is its ``mission.type``).
    directory : Path
        The folder the package's folder is made in.
    registry : PluginRegistry, optional
        The installed plugins: a name one of them has for ``kind`` is refused, as the
        two could not be told apart in a scenario (for a mission: an installed
        mission's type).

    Returns
    -------
    Path
        The package's root folder, ``directory/dcsim-NAME``.

    Raises
    ------
    ScaffoldError
        For an unknown kind, a name that is not a plugin name or is taken, or an
        existing folder.
    """
    if kind not in KINDS:
        raise ScaffoldError(f"unknown plugin kind '{kind}' (kinds: {', '.join(KINDS)})")
    if not _NAME.match(name):
        raise ScaffoldError(
            f"'{name}' is not a plugin name: use lower-case letters, digits, '-' and '_', "
            "starting with a letter (e.g. my-controller)"
        )
    _refuse_taken(kind, name, registry)
    module = "dcsim_" + name.replace("-", "_")
    class_name = "".join(p.capitalize() for p in re.split("[-_]", name)) + _SUFFIXES[kind]
    values = {
        "kind": kind,
        "name": name,
        "module": module,
        "distribution": f"dcsim-{name}",
        "class_name": class_name,
        "contract": _CONTRACTS.get(kind, ""),
        "summary": _SUMMARIES[kind],
        "dcsim_version": __version__,
        "entry_point": _entry_point(kind, name, module, class_name),
        "usage": _usage(kind, name),
    }
    root = directory / values["distribution"]
    if root.exists():
        raise ScaffoldError(f"{root} already exists; choose another name or --dir")
    for target, template in _files(kind, module).items():
        path = root / target
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(_template(template).substitute(values), encoding="utf-8")
    return root


def _refuse_taken(kind: str, name: str, registry: PluginRegistry | None) -> None:
    """Refuse a name an installed plugin of ``kind`` (or an installed mission) has."""
    if kind == MISSION:
        from dcsim.missions import mission_types  # the missions load the world engine

        known = mission_types().get(name)
        if known is not None:
            raise ScaffoldError(
                f"an installed mission already has the type '{name}' "
                f"({known.__module__}.{known.__qualname__}); choose another name"
            )
        return
    taken = [e for e in (registry.entries(kind) if registry else ()) if e.name == name]
    if taken:
        raise ScaffoldError(
            f"an installed {kind} plugin is already named '{name}' ({taken[0].origin}); "
            "choose another name"
        )


def _entry_point(kind: str, name: str, module: str, class_name: str) -> str:
    """The ``pyproject.toml`` entry point through which dcsim finds the package's class."""
    if kind == MISSION:
        return f'[project.entry-points."dcsim.missions"]\n{name} = "{module}:{class_name}"'
    return f'[project.entry-points."{kind_group(kind)}"]\n{name} = "{module}"'


def _usage(kind: str, name: str) -> str:
    """The scenario lines that fly the plugin: a sensor model is given to its sensor
    under ``sensors:`` (the template's is a star tracker), any other plugin fills its
    kind's role."""
    if kind == "sensor":
        return f"sensors:\n  star_tracker:\n    model: {name}\n    params: {{}}"
    return f"{kind}:\n  plugin: {name}\n  params: {{}}"


def _files(kind: str, module: str) -> dict[str, str]:
    """The package's files (path in the package) and the template each is written from."""
    if kind == MISSION:
        return {
            "pyproject.toml": "pyproject.toml.tmpl",
            "README.md": "mission_README.md.tmpl",
            f"{module}/__init__.py": "mission.py.tmpl",
            f"tests/test_{module}.py": "mission_test.py.tmpl",
            "tests/scenario.yaml": "mission_scenario.yaml.tmpl",
        }
    return {
        "pyproject.toml": "pyproject.toml.tmpl",
        "README.md": "README.md.tmpl",
        f"{module}/__init__.py": f"{kind}.py.tmpl",
        f"tests/test_{module}.py": "test.py.tmpl",
    }
