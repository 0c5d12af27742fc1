"""Each mission says whether its goal was met, and a plan that outlasts the run is named.

``summary.json`` carries ``goal_met`` (true, false, or null for a mission without a goal
to meet), and ``dcsim run`` says on its first line when the goal was not met. A path
that ends after ``world.duration`` records a ``plan_outlasts_run`` event and warns.
"""

from __future__ import annotations

import json
import textwrap

import pytest

from dcsim.errors import PlanOutlastsRunWarning
from dcsim.registry.discovery import PluginRegistry
from dcsim.run.loop import Runner
from dcsim.run.setup import setup_run
from tests.conftest import REPO

FFSR = REPO / "scenarios" / "ffsr_obstacles.yaml"
REACH = REPO / "scenarios" / "space_manipulator_reach.yaml"
ANT_COLONY_PATH_END = 71.3
"""End of ant-colony's plan on ffsr_obstacles.yaml, s (``pd`` arrives at 86.4 s)."""


@pytest.fixture(scope="module")
def registry():
    return PluginRegistry.discover()


def fly(registry, path, *overrides: str) -> tuple[dict, list[dict]]:
    """The summary and the events of a run of ``path`` with ``overrides``."""
    runner = Runner(setup_run(path, overrides, registry=registry))
    summary = runner.run()
    return summary, runner.recorder.events


def outlasts(events: list[dict]) -> list[dict]:
    return [e for e in events if e["event"] == "plan_outlasts_run"]


def test_a_transfer_cut_short_says_so_when_the_plan_is_made(registry):
    with pytest.warns(PlanOutlastsRunWarning, match=r"ends at t = 71\.3 s, after .* of 50 s"):
        summary, events = fly(registry, FFSR, "path_planner.plugin=ant-colony", "world.duration=50")
    (notice,) = outlasts(events)
    assert notice["t"] == 0.0 and notice["duration"] == 50.0
    assert notice["plan_end"] == pytest.approx(ANT_COLONY_PATH_END, abs=0.05)
    assert (summary["status"], summary["reason"]) == ("completed", "duration reached")
    assert summary["goal_met"] is False and summary["reached"] is False


def test_a_transfer_that_arrives_meets_its_goal_without_a_notice(registry, recwarn):
    summary, events = fly(registry, FFSR, "path_planner.plugin=ant-colony")
    assert (summary["reason"], summary["goal_met"]) == ("goal reached", True)
    assert not outlasts(events)
    assert not [w for w in recwarn if issubclass(w.category, PlanOutlastsRunWarning)]


def test_a_reach_cut_short_says_so_and_misses_its_goal(registry):
    with pytest.warns(PlanOutlastsRunWarning, match=r"ends at t = 5\.6 s"):
        summary, events = fly(registry, REACH, "world.duration=1")
    (notice,) = outlasts(events)
    assert notice["plan_end"] == pytest.approx(5.63, abs=0.01) and notice["duration"] == 1.0
    assert summary["goal_met"] is False


def test_debris_goal_is_every_target_delivered(registry):
    summary, _ = fly(registry, None, "world.duration=3")
    assert (summary["delivered"], summary["targets"], summary["goal_met"]) == (0, 4, False)


def test_hold_has_no_goal_to_meet(registry, tmp_path):
    path = tmp_path / "hold.yaml"
    path.write_text("world: {frame: geocentric, duration: 2}\nmission: {type: hold}\n")
    summary, _ = fly(registry, path)
    assert summary["status"] == "completed" and summary["goal_met"] is None


def test_run_says_on_its_first_line_that_the_goal_was_not_met(dcsim_cli, tmp_path):
    result = dcsim_cli("run", "--set", "world.duration=3", "--out", str(tmp_path / "run"))
    assert result.returncode == 0, result.stderr
    first = result.stdout.splitlines()[0]
    assert first == (
        "default seed 0: completed (duration reached) — goal not met: delivered 0/4, captured 0"
    )
    assert json.loads((tmp_path / "run" / "summary.json").read_text())["goal_met"] is False


def test_run_warns_on_stderr_when_a_plan_outlasts_the_run(dcsim_cli, tmp_path):
    result = dcsim_cli(
        "run",
        str(FFSR),
        "--set",
        "path_planner.plugin=ant-colony",
        "--set",
        "world.duration=50",
        "--out",
        str(tmp_path / "run"),
    )
    assert result.returncode == 0, result.stderr
    assert result.stderr == textwrap.dedent(
        """\
        warning: the plan made at t = 0.0 s ends at t = 71.3 s, after the run's world.duration \
of 50 s: the run stops before the plan is flown to its end; lengthen world.duration to 72 s \
or more to fly it
        """
    )
    assert "goal not met: 1 plan(s), goal not reached" in result.stdout.splitlines()[0]
