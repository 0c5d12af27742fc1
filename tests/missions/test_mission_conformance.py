"""The mission conformance suite: dcsim's missions keep the seam's contract, and broken
missions are caught by the check that names what they did."""

from __future__ import annotations

import copy
import importlib
import re
import sys
from typing import Any, ClassVar, Literal

import numpy as np
import pytest
import yaml
from pydantic import ConfigDict, Field

from dcsim.api import (
    Mission,
    MissionSettings,
    Reference,
    RoleKind,
    register_mission,
)
from dcsim.missions import mission_class
from dcsim.testing.missions import MISSION_CHECKS, MissionContract, check_mission
from tests.conftest import REPO


def shipped(name: str, duration: float) -> dict:
    """A shipped scenario's data, flown for ``duration`` s."""
    data = yaml.safe_load((REPO / "scenarios" / f"{name}.yaml").read_text())
    data["world"]["duration"] = duration
    return data


SCENARIOS = {
    "debris": shipped("default", 20.0),
    "transfer": shipped("ffsr_obstacles", 10.0),
    "reach": shipped("space_manipulator_reach", 1.0),
    "hold": {"world": {"frame": "geocentric", "duration": 5}, "mission": {"type": "hold"}},
    "capture": shipped("debris_capture", 1.0),
}


@pytest.mark.parametrize("mission_type", sorted(SCENARIOS))
def test_dcsim_s_missions_keep_the_contract(mission_type):
    results = check_mission(mission_class(mission_type), SCENARIOS[mission_type])
    assert [r.check for r in results] == [c.name for c in MISSION_CHECKS]
    assert [str(r) for r in results if not r.passed] == []


class StillSettings(MissionSettings):
    """Stay where the robot starts (test)."""

    type: Literal["still"] = "still"
    wobble: bool = Field(False, description="Pull the reference by an unseeded random amount.")
    stray_mode: bool = Field(False, description="Report a mode it does not declare.")


class StillMission(Mission):
    type = "still"
    summary = "stay where it starts (test)"
    Settings = StillSettings
    roles = ("controller",)
    modes = ("STILL",)
    columns = ("offset",)

    @property
    def mode(self):
        return "ASTRAY" if self.settings.stray_mode else "STILL"

    def tick(self, time, estimate, observations):
        wobble = np.random.default_rng().normal(0, 1, 3) if self.settings.wobble else 0.0
        return Reference(time=time, position=np.add(self.scenario.robot.initial.position, wobble))

    def telemetry(self, outputs):
        return {"offset": 0.0}


register_mission(StillMission)  # the mislabelled mission's scenario flies this one


class LenientSettings(StillSettings):
    model_config = ConfigDict(extra="ignore")

    type: Literal["lenient"] = "lenient"


class LenientMission(StillMission):
    type = "lenient"
    Settings = LenientSettings


class FaultySettings(StillSettings):
    type: Literal["faulty"] = "faulty"


class FaultyMission(StillMission):
    type = "faulty"
    Settings = FaultySettings

    def tick(self, time, estimate, observations):
        raise ArithmeticError("the mission's own bug")


class MislabelledMission(StillMission):
    type = "mislabelled"  # its Settings' type is still "still"


class UnnamedRoleSettings(StillSettings):
    type: Literal["unnamed-role"] = "unnamed-role"


class UnnamedRoleMission(StillMission):
    type = "unnamed-role"
    Settings = UnnamedRoleSettings
    roles = ("controller", "docking_planner")  # not a kind, and no role_kinds entry


class UnknownKindSettings(StillSettings):
    type: Literal["unknown-kind"] = "unknown-kind"


class UnknownKindMission(StillMission):
    type = "unknown-kind"
    Settings = UnknownKindSettings
    roles = ("controller", "docking_planner")
    role_kinds = {"docking_planner": RoleKind("docking_planner")}  # no such kind


class KeylessRoleSettings(StillSettings):
    type: Literal["keyless-role"] = "keyless-role"


class KeylessRoleMission(StillMission):
    type = "keyless-role"
    Settings = KeylessRoleSettings  # no role_defaults entry: the role has no scenario key
    roles = ("controller", "docking_planner")
    role_kinds = {"docking_planner": RoleKind("path_planner", "free-flyer")}


class UnknownRobotSettings(StillSettings):
    type: Literal["unknown-robot"] = "unknown-robot"
    role_defaults: ClassVar[dict[str, Any]] = {"docking_planner": None}


class UnknownRobotMission(StillMission):
    type = "unknown-robot"
    Settings = UnknownRobotSettings
    roles = ("controller", "docking_planner")
    role_kinds = {"docking_planner": RoleKind("path_planner", "rover")}  # no such robot


class StrayDefaultSettings(StillSettings):
    type: Literal["stray-default"] = "stray-default"
    role_defaults: ClassVar[dict[str, Any]] = {"docking_planner": None}


class StrayDefaultMission(StillMission):
    type = "stray-default"
    Settings = StrayDefaultSettings  # a scenario key for a role it never names


STILL = {"world": {"frame": "geocentric", "duration": 3}, "mission": {"type": "still"}}


def scenario(mission_type: str = "still", **settings) -> dict:
    data = copy.deepcopy(STILL)
    data["mission"] = {"type": mission_type, **settings}
    return data


@pytest.mark.parametrize(
    ("mission", "data", "failing", "said"),
    [
        (StillMission, scenario(), set(), ""),
        (StillMission, scenario(wobble=True), {"deterministic"}, "telemetry.csv differs"),
        (
            StillMission,
            scenario(stray_mode=True),
            {"flies_its_scenario"},
            "records modes ['ASTRAY']",
        ),
        (LenientMission, scenario("lenient"), {"validates_its_section"}, "was accepted"),
        (
            FaultyMission,
            scenario("faulty"),
            {"flies_its_scenario", "deterministic"},
            "raised ArithmeticError: the mission's own bug while flying its scenario",
        ),
        (
            MislabelledMission,
            scenario(),
            {"declares_its_seam"},
            "its Settings' type defaults to 'still', not to its type 'mislabelled'",
        ),
        (
            UnnamedRoleMission,
            scenario("unnamed-role"),
            {"declares_its_seam"},
            "roles ['docking_planner'] are neither plugin kinds",
        ),
        (
            UnknownKindMission,
            scenario("unknown-kind"),
            {"declares_its_seam"},
            "role_kinds {'docking_planner': 'docking_planner'} name no plugin kind",
        ),
        (
            KeylessRoleMission,
            scenario("keyless-role"),
            {"declares_its_seam"},
            "roles ['docking_planner'] of its role_kinds have no scenario key",
        ),
        (
            UnknownRobotMission,
            scenario("unknown-robot"),
            {"declares_its_seam"},
            "role_kinds {'docking_planner': 'rover'} name no robot type",
        ),
        (
            StrayDefaultMission,
            scenario("stray-default"),
            {"declares_its_seam"},
            "role_defaults ['docking_planner'] are neither plugin kinds nor named",
        ),
    ],
    ids=[
        "keeps",
        "unseeded",
        "stray-mode",
        "lenient",
        "faulty",
        "mislabelled",
        "unnamed-role",
        "unknown-kind",
        "keyless-role",
        "unknown-robot",
        "stray-default",
    ],
)
def test_a_broken_mission_is_caught_by_the_check_naming_what_it_did(mission, data, failing, said):
    results = {r.check: r for r in check_mission(mission, data)}
    assert {name for name, r in results.items() if not r.passed} == failing
    for name in failing:
        assert said in results[name].message
        assert f"mission '{mission.type}' breaks '{name}'" in results[name].message


class TestStillMission(MissionContract):
    """The contract as a plugin package's tests use it."""

    mission = StillMission
    scenario = STILL


def test_the_contract_class_has_one_test_per_check():
    names = {name for name in vars(TestStillMission) if name.startswith("test_")}
    assert names == {f"test_{c.name}" for c in MISSION_CHECKS}


def test_the_mission_written_in_the_docs_keeps_the_contract(tmp_path, monkeypatch):
    """docs/plugins.md's mission, saved as its module, with the scenario beside it."""
    text = (REPO / "docs" / "plugins.md").read_text()
    section = text[text.index("## Writing a mission") : text.index("## Lifecycle hooks")]
    code = next(b for b in re.findall(r"```python\n(.*?)```", section, re.S) if "class Go" in b)
    flight = next(b for b in re.findall(r"```yaml\n(.*?)```", section, re.S))
    (tmp_path / "dcsim_go_to_docs.py").write_text(code)
    monkeypatch.syspath_prepend(str(tmp_path))
    module = importlib.import_module("dcsim_go_to_docs")
    try:
        results = check_mission(module.GoToMission, yaml.safe_load(flight))
        assert [str(r) for r in results if not r.passed] == []
    finally:
        sys.modules.pop("dcsim_go_to_docs", None)
