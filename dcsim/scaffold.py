"""``dcsim new-plugin``: write an out-of-tree plugin package that works as generated.

The package has a ``pyproject.toml`` declaring the ``dcsim`` entry point, the plugin
class with its parameter model (a simple but real algorithm of the kind), a test file
running dcsim's conformance suite, and a README. It installs with ``pip install -e``.
"""

from __future__ import annotations

import re
from importlib import resources
from pathlib import Path
from string import Template

from dcsim import __version__
from dcsim.errors import DcsimError
from dcsim.interfaces import PLUGIN_KINDS
from dcsim.registry import PluginRegistry

_NAME = re.compile(r"^[a-z][a-z0-9_-]*$")
_SUMMARIES = {
    "localiser": "Gauss-Newton multilateration on beacon ranges",
    "task_planner": "Targets in order of distance, drop visits when full",
    "path_planner": "Straight segment, trapezoidal speed, obstacle-checked",
    "controller": "Proportional position control with velocity damping",
}
_SUFFIXES = {
    "localiser": "Localiser",
    "task_planner": "TaskPlanner",
    "path_planner": "PathPlanner",
    "controller": "Controller",
}
_CONTRACTS = {
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
        The plugin's kind (``controller``...) and name (``my-controller``).
    directory : Path
        The folder the package's folder is made in.
    registry : PluginRegistry, optional
        The installed plugins: a name one of them has for ``kind`` is refused, as the
        two could not be told apart in a scenario.

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
    if kind not in PLUGIN_KINDS:
        raise ScaffoldError(f"unknown plugin kind '{kind}' (kinds: {', '.join(PLUGIN_KINDS)})")
    if not _NAME.match(name):
        raise ScaffoldError(
            f"'{name}' is not a plugin name: use lower-case letters, digits, '-' and '_', "
            "starting with a letter (e.g. my-controller)"
        )
    taken = [p for p in (registry.plugins(kind) if registry else ()) if p.name == name]
    if taken:
        raise ScaffoldError(
            f"an installed {kind} plugin is already named '{name}' ({taken[0].origin}); "
            "choose another name"
        )
    module = "dcsim_" + name.replace("-", "_")
    values = {
        "kind": kind,
        "name": name,
        "module": module,
        "distribution": f"dcsim-{name}",
        "class_name": "".join(p.capitalize() for p in re.split("[-_]", name)) + _SUFFIXES[kind],
        "contract": _CONTRACTS[kind],
        "summary": _SUMMARIES[kind],
        "dcsim_version": __version__,
    }
    root = directory / values["distribution"]
    if root.exists():
        raise ScaffoldError(f"{root} already exists; choose another name or --dir")
    files = {
        "pyproject.toml": "pyproject.toml.tmpl",
        "README.md": "README.md.tmpl",
        f"{module}/__init__.py": f"{kind}.py.tmpl",
        f"tests/test_{module}.py": "test.py.tmpl",
    }
    for target, template in files.items():
        path = root / target
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(_template(template).substitute(values), encoding="utf-8")
    return root
