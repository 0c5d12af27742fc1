"""``dcsim new-plugin``: every kind's generated plugin, and a generated mission, passes
its conformance suite."""

from __future__ import annotations

import importlib
import sys

import pytest

from dcsim.registry.scaffold import ScaffoldError, new_plugin
from dcsim.testing import check_plugin
from dcsim.testing.missions import check_mission


@pytest.mark.parametrize(
    "kind", ["sensor", "tracker", "localiser", "task_planner", "path_planner", "controller"]
)
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
        assert f'[project.entry-points."dcsim.{kind}s"]' in pyproject
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


def test_a_generated_mission_flies_its_scenario_and_conforms(tmp_path, monkeypatch):
    root = new_plugin("mission", "fresh-mission", tmp_path)
    monkeypatch.syspath_prepend(str(root))
    module = importlib.import_module("dcsim_fresh_mission")
    try:
        mission = module.FreshMissionMission
        assert mission.type == "fresh-mission"
        scenario = root / "tests" / "scenario.yaml"
        failures = [str(r) for r in check_mission(mission, scenario) if not r.passed]
        assert failures == []
        pyproject = (root / "pyproject.toml").read_text()
        assert '[project.entry-points."dcsim.missions"]' in pyproject
        assert 'fresh-mission = "dcsim_fresh_mission:FreshMissionMission"' in pyproject
        assert "MissionContract" in (root / "tests" / "test_dcsim_fresh_mission.py").read_text()
    finally:
        sys.modules.pop("dcsim_fresh_mission", None)


def test_a_mission_type_already_installed_is_refused(tmp_path):
    with pytest.raises(ScaffoldError, match="an installed mission already has the type 'hold'"):
        new_plugin("mission", "hold", tmp_path)


def test_a_generated_sensor_model_s_readme_gives_it_to_its_sensor(tmp_path, monkeypatch):
    root = new_plugin("sensor", "fresh-star", tmp_path)
    monkeypatch.syspath_prepend(str(root))
    try:
        sensor = importlib.import_module("dcsim_fresh_star").FreshStarSensor
        readme = (root / "README.md").read_text()
        assert f"sensors:\n  {sensor.measures}:\n    model: fresh-star\n" in readme
        assert (
            "TrackerContract"
            in (
                new_plugin("tracker", "fresh-follower", tmp_path)
                / "tests"
                / "test_dcsim_fresh_follower.py"
            ).read_text()
        )
    finally:
        sys.modules.pop("dcsim_fresh_star", None)
