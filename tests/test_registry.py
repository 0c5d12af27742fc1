"""The plugin registry in-process: built-ins through entry points, checks, lookup, loading
when used."""

from __future__ import annotations

import importlib.metadata as md
import sys
import types

import numpy as np
import pytest

from dcsim.api import (
    Command,
    Controller,
    DuplicatePluginError,
    PluginInterfaceError,
    PluginLoadWarning,
    PluginNotFoundError,
    PluginParameterError,
    PluginParams,
    PluginRegistry,
    hookimpl,
    quantity,
)
from dcsim.registry.discovery import PluginEntry, PluginOrigin, check_plugin_class

ORIGIN = PluginOrigin("test-dist", "0.0", "test")


class GainParams(PluginParams):
    gain: float = quantity(2.0, unit="1/s", gt=0, le=10, description="A gain.")


class ThrowAwayController(Controller):
    name = "throw-away"
    summary = "Registered by a test"
    Params = GainParams

    def reset(self, robot):
        self.robot = robot

    def command(self, time, estimate, reference, surroundings):
        return Command()


def test_builtins_come_from_the_dcsim_distribution_entry_points():
    registry = PluginRegistry.discover()
    found = {(p.kind, p.name): p.origin for p in registry.plugins()}
    expected = {
        ("localiser", "trilateration"),
        ("task_planner", "nearest"),
        ("path_planner", "straight-line"),
        ("controller", "pd"),
    }
    assert expected <= set(found)
    for key in expected:
        assert found[key].distribution == "dcsim"
        assert found[key].entry_point.split(" = ")[1].startswith("dcsim_plugins.")


def test_a_throw_away_module_registers_through_the_hook():
    module = types.ModuleType("throw_away_plugins")
    module.dcsim_plugin_classes = hookimpl(lambda: [ThrowAwayController])
    registry = PluginRegistry()
    registry.register_module(module, ORIGIN)
    entry = registry.get("controller", "throw-away")
    assert entry.cls is ThrowAwayController and entry.origin == ORIGIN
    plugin = registry.create("controller", "throw-away", {"gain": 3.0}, np.random.default_rng(1))
    assert plugin.params.gain == 3.0


def test_a_name_in_the_wrong_case_is_suggested_in_the_right_one():
    registry = PluginRegistry.discover()
    with pytest.raises(PluginNotFoundError, match=r"did you mean 'ekf'\?"):
        registry.get("localiser", "EKF")


def test_unknown_name_suggests_the_closest():
    registry = PluginRegistry.discover()
    with pytest.raises(
        PluginNotFoundError,
        match=r"available: ant-colony, end-effector-line, fixture-intercept, grid-astar, multi-burn, "
        r"ompl-control, "
        r"ompl-geometric, q-learning, straight-line\); "
        r"did you mean 'straight-line'\?",
    ):
        registry.get("path_planner", "straight_line")


def test_unknown_kind_lists_the_kinds():
    with pytest.raises(
        PluginNotFoundError,
        match="kinds: sensor, tracker, localiser, task_planner, path_planner, controller",
    ):
        PluginRegistry().plugins("navigator")


def test_duplicate_names_warn_then_fail_on_use_naming_both_origins():
    registry = PluginRegistry()
    registry.register_class(ThrowAwayController, ORIGIN)
    with pytest.warns(
        PluginLoadWarning, match="two plugins register the controller name 'throw-away'"
    ):
        registry.register_class(ThrowAwayController, PluginOrigin("other-dist", "9", "x"))
    with pytest.raises(DuplicatePluginError, match=r"test-dist 0\.0 .* and other-dist 9"):
        registry.get("controller", "throw-away")


class Incomplete(Controller):
    name = "incomplete"
    summary = "Forgets command()"

    def reset(self, robot):
        pass


@pytest.mark.parametrize(
    "obj, message",
    [
        (
            Incomplete,
            r"plugin 'incomplete' .* does not implement command\(\) of the controller interface",
        ),
        (
            int,
            "is not a plugin class: derive it from one of SensorModel, Tracker, Localiser, TaskPlanner, PathPlanner, Controller",
        ),
        (
            type("Nameless", (ThrowAwayController,), {"name": "Bad Name"}),
            "must set `name` to a lower-case identifier",
        ),
        (type("Quiet", (ThrowAwayController,), {"summary": ""}), "must set `summary` to one line"),
        (type("NoParams", (ThrowAwayController,), {"Params": dict}), "`Params` must be a subclass"),
    ],
)
def test_incomplete_classes_are_rejected_saying_why(obj, message):
    with pytest.raises(PluginInterfaceError, match=message):
        check_plugin_class(obj)


def test_register_warns_instead_of_raising_for_broken_classes():
    registry = PluginRegistry()
    with pytest.warns(PluginLoadWarning, match=r"does not implement command\(\)"):
        registry.register(Incomplete, ORIGIN)
    assert registry.plugins() == []
    assert len(registry.warnings) == 1


def test_invalid_parameters_name_parameter_value_and_range():
    with pytest.raises(PluginParameterError) as info:
        ThrowAwayController({"gain": 12.0})
    text = str(info.value)
    assert "throw-away" in text and "gain" in text and "12.0" in text
    assert "allowed: > 0, <= 10 1/s" in text


def test_parameters_reject_strings_for_numbers_and_unknown_names():
    with pytest.raises(PluginParameterError, match="gian: unknown key"):
        GainParams.parse("throw-away", {"gian": 1})
    with pytest.raises(PluginParameterError, match="'fast' is not allowed"):
        GainParams.parse("throw-away", {"gain": "fast"})


def test_parameters_round_trip():
    params = GainParams.parse("throw-away", {"gain": 4})
    assert GainParams.parse("throw-away", params.model_dump(mode="json")) == params


def _declared_module(monkeypatch, classes, name="lazy_throw_away"):
    """A module importable as ``name`` whose hook gives ``classes``, counting its calls."""
    module = types.ModuleType(name)
    calls = []

    @hookimpl
    def dcsim_plugin_classes():
        calls.append(1)
        return classes

    module.dcsim_plugin_classes = dcsim_plugin_classes
    monkeypatch.setitem(sys.modules, name, module)
    return md.EntryPoint("throw-away", name, "dcsim.controllers"), calls


def test_a_declared_plugin_is_listed_from_metadata_and_loaded_once_when_looked_up(monkeypatch):
    entry_point, calls = _declared_module(monkeypatch, [ThrowAwayController])
    registry = PluginRegistry()
    registry.declare(PluginEntry("controller", "throw-away", ORIGIN), entry_point)
    assert registry.names("controller") == ["throw-away"]
    assert [e.name for e in registry.entries()] == ["throw-away"] and calls == []
    assert registry.get("controller", "throw-away").cls is ThrowAwayController
    assert registry.create("controller", "throw-away").params.gain == 2.0
    assert calls == [1]


def test_a_declared_plugin_whose_module_gives_another_name_fails_when_used(monkeypatch):
    entry_point, _ = _declared_module(monkeypatch, [ThrowAwayController])
    used, listed = PluginRegistry(), PluginRegistry()
    for registry in (used, listed):
        registry.declare(PluginEntry("controller", "other", ORIGIN), entry_point)
    with pytest.raises(
        PluginInterfaceError,
        match=r"declares the controller plugin 'other', but its module gives no controller class "
        r"with name = 'other'",
    ):
        used.get("controller", "other")
    with pytest.warns(PluginLoadWarning, match="declares the controller plugin 'other'"):
        assert listed.plugins() == []


def test_a_module_in_the_dcsim_group_and_its_kinds_group_registers_its_plugin_once(monkeypatch):
    entry_point, _ = _declared_module(monkeypatch, [ThrowAwayController])
    registry = PluginRegistry()
    registry.register_module(sys.modules[entry_point.value], ORIGIN)
    registry.declare(PluginEntry("controller", "throw-away", ORIGIN), entry_point)
    assert [e.name for e in registry.entries("controller")] == ["throw-away"]
    assert registry.get("controller", "throw-away").cls is ThrowAwayController
    assert registry.warnings == [] and len(registry.plugins()) == 1
