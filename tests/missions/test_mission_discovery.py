"""Missions are found as plugins are: through the ``dcsim.missions`` entry point group,
so a mission in a third party's distribution is a scenario's ``mission.type`` once the
distribution is installed."""

from __future__ import annotations

import textwrap

import pytest

from dcsim.errors import PluginLoadWarning
from dcsim.missions import MISSION_GROUP, mission_class, mission_types
from dcsim.missions import _installed as installed_missions
from dcsim.registry.discovery import PluginRegistry
from dcsim.run.loop import Runner
from dcsim.run.setup import setup_run

MODULE = '''
from typing import Literal

from pydantic import Field

from dcsim.api import Reference
from dcsim.missions.base import Mission
from dcsim.scenario.model import MissionSettings


class PatrolSettings(MissionSettings):
    """Hold the start for a while (test)."""

    type: Literal["patrol"] = "patrol"
    rounds: int = Field(2, ge=1, description="Rounds to fly.")


class PatrolMission(Mission):
    type = "patrol"
    summary = "patrol (test)"
    Settings = PatrolSettings
    roles = ("controller",)
    modes = ("PATROL",)

    @property
    def mode(self):
        return "PATROL"

    def tick(self, time, estimate, observations):
        self.time = time
        return Reference(time=time, position=estimate.position)

    def finished(self):
        if self.time >= self.settings.rounds:
            return "completed", f"{self.settings.rounds} rounds"
        return None


class Misnamed(PatrolMission):
    type = "not-what-the-entry-point-says"
'''


def install(site, name: str, entry_points: str) -> None:
    """A distribution on ``site`` as pip leaves one: its module and its metadata."""
    (site / f"{name}.py").write_text(MODULE)
    info = site / f"{name}-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(f"[{MISSION_GROUP}]\n{entry_points}\n")


@pytest.fixture
def site(tmp_path, monkeypatch):
    site = tmp_path / "site"
    site.mkdir()
    monkeypatch.syspath_prepend(str(site))
    installed_missions.cache_clear()
    yield site
    installed_missions.cache_clear()


def test_an_installed_distribution_s_mission_is_a_mission_type(site, tmp_path):
    install(site, "patrol_missions", "patrol = patrol_missions:PatrolMission")
    assert mission_class("patrol").__module__ == "patrol_missions"
    assert {"debris", "transfer", "reach", "hold"} <= set(mission_types())
    scenario = tmp_path / "patrol.yaml"
    scenario.write_text(
        textwrap.dedent(
            """\
            world: {frame: geocentric, duration: 10}
            mission: {type: patrol, rounds: 1}
            """
        )
    )
    summary = Runner(setup_run(scenario, registry=PluginRegistry.discover())).run()
    assert (summary["mission"], summary["status"], summary["reason"]) == (
        "patrol",
        "completed",
        "1 rounds",
    )


def test_a_broken_mission_entry_point_is_skipped_with_a_warning(site):
    install(
        site,
        "odd_missions",
        "misnamed = odd_missions:Misnamed\nmissing = odd_missions:NoSuchClass",
    )
    with pytest.warns(PluginLoadWarning) as caught:
        found = mission_types()
    messages = " ".join(str(w.message) for w in caught)
    assert "Misnamed.type is 'not-what-the-entry-point-says', not 'misnamed'" in messages
    assert "entry point 'missing' = odd_missions:NoSuchClass of odd_missions failed" in messages
    assert "misnamed" not in found and "missing" not in found
    assert "debris" in found
