"""``dcsim new-plugin``: every kind's generated plugin passes the conformance suite."""

from __future__ import annotations

import importlib
import sys

import pytest

from dcsim.scaffold import ScaffoldError, new_plugin
from dcsim.testing import check_plugin


@pytest.mark.parametrize("kind", ["localiser", "task_planner", "path_planner", "controller"])
def test_generated_plugin_of_every_kind_conforms(kind, tmp_path, monkeypatch):
    root = new_plugin(kind, f"fresh-{kind.replace('_', '-')}", tmp_path)
    module_name = f"dcsim_fresh_{kind}"
    monkeypatch.syspath_prepend(str(root))
    module = importlib.import_module(module_name)
    try:
        (plugin,) = module.dcsim_plugin_classes()
        assert plugin.kind == kind and plugin.name == f"fresh-{kind.replace('_', '-')}"
        failures = [str(r) for r in check_plugin(plugin) if not r.passed]
        assert failures == []
        pyproject = (root / "pyproject.toml").read_text()
        assert f'fresh-{kind.replace("_", "-")} = "{module_name}"' in pyproject
    finally:
        sys.modules.pop(module_name, None)


@pytest.mark.parametrize(
    "kind, name, message",
    [
        ("navigator", "x", "unknown plugin kind 'navigator'"),
        ("controller", "My Controller", "is not a plugin name"),
    ],
)
def test_bad_requests_are_refused(kind, name, message, tmp_path):
    with pytest.raises(ScaffoldError, match=message):
        new_plugin(kind, name, tmp_path)
