"""The debris mission gives up after ``max_plan_attempts`` "no path" answers in a row."""

from __future__ import annotations

import pytest

from dcsim.registry.discovery import PluginRegistry
from dcsim.run.loop import Runner
from dcsim.run.setup import setup_run

REFUSAL = "no path: moving obstacles need ompl-control or a time-aware planner"
"""ompl-geometric's answer among the default scenario's drifting obstacles."""


@pytest.fixture(scope="module")
def registry():
    return PluginRegistry.discover()


@pytest.mark.parametrize("attempts", [1, 3])
def test_the_run_stops_with_the_planners_reason(registry, attempts):
    overrides = ["path_planner={plugin: ompl-geometric}", f"mission.max_plan_attempts={attempts}"]
    runner = Runner(setup_run(None, overrides, registry=registry))
    summary = runner.run()
    refusals = [e for e in runner.recorder.events if e["event"] == "no_path"]
    assert [e["reason"] for e in refusals] == [REFUSAL] * attempts
    assert (summary["status"], summary["reason"]) == (
        "stopped",
        f"no path after {attempts} attempts: {REFUSAL}",
    )
    assert summary["goal_met"] is False
    retry = runner.scenario.mission.path_retry
    assert summary["sim_time_s"] < attempts * retry + 1.0


def test_a_pickup_without_a_path_is_planned_anew_from_the_tracks_then(registry):
    overrides = ["path_planner={plugin: ompl-geometric}", "mission.max_plan_attempts=2"]
    runner = Runner(setup_run(None, overrides, registry=registry))
    runner.run()
    events = runner.recorder.events
    refused = next(i for i, e in enumerate(events) if e["event"] == "no_path")
    after = events[refused + 1 :]
    replanned = next(
        i for i, e in enumerate(after) if e["event"] == "mode" and e["mode"] == "DEVISE_PLAN"
    )
    assert after[replanned]["reason"] == "no path to the pickup"
    assert after[replanned]["t"] >= events[refused]["t"] + runner.scenario.mission.path_retry
    assert [e["event"] for e in after[replanned + 1 :] if e["event"] in ("plan", "no_path")][
        :2
    ] == ["plan", "no_path"], "the tasks are planned afresh before the path is asked again"
