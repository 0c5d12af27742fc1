"""The framework and the built-in plugins meet only where a third party's plugins do:
``dcsim/`` never imports ``dcsim_plugins`` (the built-ins reach it through entry points
and hooks), and every module of ``plugins/`` uses nothing of dcsim but ``dcsim.api``."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from tests.conftest import REPO

PLUGIN_PACKAGE = "dcsim_plugins"
"""The name ``plugins/`` installs as."""


def imported(path: Path) -> list[tuple[int, str]]:
    """Line and absolute module name of every import in a file, and every string
    constant naming the plugin package (an ``importlib`` or entry-point reference)."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            found.append((node.lineno, node.module))
        elif isinstance(node, ast.Constant) and isinstance(node.value, str):
            if node.value.startswith(PLUGIN_PACKAGE):
                found.append((node.lineno, node.value))
    return found


def modules(folder: str) -> list[Path]:
    return sorted((REPO / folder).rglob("*.py"))


@pytest.mark.parametrize("path", modules("dcsim"), ids=lambda p: str(p.relative_to(REPO)))
def test_the_framework_never_imports_the_builtin_plugins(path):
    wrong = [
        f"line {line}: {name}"
        for line, name in imported(path)
        if name.split(".")[0] in (PLUGIN_PACKAGE, "plugins")
    ]
    assert not wrong, f"{path.relative_to(REPO)} reaches into the plugins: {wrong}"


@pytest.mark.parametrize("path", modules("plugins"), ids=lambda p: str(p.relative_to(REPO)))
def test_every_plugin_module_uses_only_the_public_api(path):
    wrong = [
        f"line {line}: {name}"
        for line, name in imported(path)
        if name.split(".")[0] == "dcsim" and name != "dcsim.api"
    ]
    assert not wrong, f"{path.relative_to(REPO)} imports dcsim's internals: {wrong}"


def test_the_scan_sees_a_plugin_import(tmp_path):
    framework = tmp_path / "module.py"
    framework.write_text(
        "import importlib\n"
        "from dcsim_plugins.path_planners import ant_colony\n"
        "importlib.import_module('dcsim_plugins.path_planners.q_learning.planner')\n"
    )
    assert [line for line, _ in imported(framework)] == [1, 2, 3]
