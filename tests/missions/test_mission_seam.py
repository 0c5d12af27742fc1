"""The mission seam: a mission the framework has never seen runs through the same runner."""

from __future__ import annotations

import csv
import textwrap
from typing import Literal

import numpy as np
import pytest
from pydantic import Field

from dcsim.api import Controller, Reference, ScenarioError
from dcsim.missions import Mission, mission_class, register_mission
from dcsim.registry.discovery import PluginOrigin, PluginRegistry
from dcsim.run.loop import SUMMARY_FIGURES, Runner
from dcsim.run.setup import setup_run
from dcsim.scenario.model import MissionSettings
from tests.conftest import REPO

TEST_ORIGIN = PluginOrigin("tests", "0", "test module")


class HoldSettings(MissionSettings):
    """Hold the start position for a while."""

    type: Literal["hold-test"] = "hold-test"
    hold_for: float = Field(3.0, gt=0, description="How long to hold, s.")


class HoldMission(Mission):
    """Holds the estimated start position, then reports itself done."""

    type = "hold-test"
    summary = "hold still (test)"
    Settings = HoldSettings
    roles = ("localiser", "controller")
    modes = ("WAIT", "HOLD")
    columns = ("hold_error",)

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.home: np.ndarray | None = None
        self.time = 0.0
        self.estimate = None
        self.worst = 0.0

    @property
    def mode(self) -> str:
        return "WAIT" if self.home is None else "HOLD"

    def tick(self, time, estimate, observations):
        self.time, self.estimate = time, estimate
        if self.home is None and estimate.converged:
            self.home = np.array(estimate.position)
            self.emit("holding", position=self.home)
        target = estimate.position if self.home is None else self.home
        return Reference(time=time, position=target)

    def telemetry(self, outputs):
        error = 0.0 if self.home is None else np.linalg.norm(self.estimate.position - self.home)
        self.worst = max(self.worst, float(error))
        return {"hold_error": float(error)}

    def finished(self):
        if self.time >= self.settings.hold_for:
            return "completed", f"held for {self.settings.hold_for:g} s"
        return None

    def summary_fields(self):
        return {"worst_hold_error_m": self.worst}


register_mission(HoldMission)


def scenario_file(tmp_path, text: str):
    path = tmp_path / "scenario.yaml"
    path.write_text(textwrap.dedent(text))
    return path


HOLD_SCENARIO = """\
    name: hold
    world: {frame: geocentric, duration: 60}
    beacons:
      positions: [[100, 0, 0], [0, 100, 0], [0, 0, 100], [-100, -100, -100]]
    localiser: {plugin: ekf}
    mission: {type: hold-test, hold_for: 4}
"""


def test_a_registered_mission_flies_through_the_runner(tmp_path):
    setup = setup_run(scenario_file(tmp_path, HOLD_SCENARIO), registry=PluginRegistry.discover())
    assert set(setup.plugins) == {"localiser", "controller"}
    out = tmp_path / "run"
    summary = Runner(setup, out).run()
    assert summary["status"] == "completed" and summary["reason"] == "held for 4 s"
    assert summary["mission"] == "hold-test"
    assert 0.0 < summary["worst_hold_error_m"] < 1.0
    with (out / "telemetry.csv").open() as stream:
        rows = list(csv.DictReader(stream))
    assert list(rows[0])[17:20] == ["mode", "converged", "hold_error"]
    assert {row["mode"] for row in rows} <= {"WAIT", "HOLD"}
    assert "mission:\n  type: hold-test\n  hold_for: 4.0\n" in (out / "scenario.yaml").read_text()


def test_a_mission_section_is_validated_by_its_own_settings(tmp_path):
    path = scenario_file(tmp_path, HOLD_SCENARIO.replace("hold_for: 4", "hold_for: -1, reach: 2"))
    with pytest.raises(ScenarioError) as error:
        setup_run(path, registry=PluginRegistry.discover())
    text = str(error.value)
    assert "mission.hold_for: -1 is not allowed" in text
    assert "mission.reach: unknown key" in text


def test_an_unknown_mission_type_names_the_known_ones(tmp_path):
    path = scenario_file(tmp_path, "mission: {type: rescue}\n")
    with pytest.raises(
        ScenarioError, match=r"mission.type: unknown mission type 'rescue'; known: capture, debris"
    ):
        setup_run(path, registry=PluginRegistry.discover())


def test_a_mission_type_cannot_be_taken_twice():
    class Impostor(HoldMission):
        pass

    with pytest.raises(ValueError, match="mission type 'hold-test' is already taken"):
        register_mission(Impostor)
    assert mission_class("hold-test") is HoldMission


class ArmOnlyController(Controller):
    name = "arm-only"
    summary = "Supports manipulators only (test)"
    robots = ("manipulator",)

    def reset(self, robot):
        pass

    def command(self, time, estimate, reference, surroundings):
        raise AssertionError("never run")


def test_a_plugin_that_does_not_support_the_robot_is_refused(tmp_path):
    registry = PluginRegistry.discover()
    registry.register_class(ArmOnlyController, TEST_ORIGIN)
    path = scenario_file(tmp_path, "controller: {plugin: arm-only}\n")
    with pytest.raises(ScenarioError) as error:
        setup_run(path, registry=registry)
    assert (
        "controller.plugin: controller plugin 'arm-only' does not support robot type "
        "'free-flyer' (it supports: manipulator)"
    ) in str(error.value)


@pytest.mark.parametrize(
    "scenario",
    ["default.yaml", "station_inspection.yaml", "space_manipulator_reach.yaml"],
)
def test_a_mission_declares_the_fields_of_its_summary(scenario):
    runner = Runner(setup_run(REPO / "scenarios" / scenario, ["world.duration=1"]))
    runner.open()
    mission = runner.mission
    assert tuple(mission.summary_fields()) == type(mission).summary_names
    summary = runner.close()
    assert set(SUMMARY_FIGURES) | set(type(mission).summary_names) <= set(summary)
