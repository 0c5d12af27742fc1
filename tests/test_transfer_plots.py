"""The transfer mission's pictures: a run writes path.png and timeline.png."""

from __future__ import annotations

import json

import matplotlib.pyplot as plt
import numpy as np
import pytest

from dcsim.missions.transfer import TransferMission
from dcsim.missions.transfer.plots import build_scene, path_figure, read_planned, timeline_figure
from dcsim.registry.discovery import PluginRegistry
from dcsim.run.loop import Runner
from dcsim.run.recording import read_telemetry
from dcsim.run.setup import setup_run
from tests.conftest import REPO

STATION = REPO / "scenarios" / "station_inspection.yaml"
GOAL_1 = "mission.goal.position=[1.8288,3.9624,0.0]"
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def registry():
    return PluginRegistry.discover()


@pytest.fixture(scope="module")
def station_run(tmp_path_factory, registry):
    """A station flight to goal 1, written to a run directory."""
    out = tmp_path_factory.mktemp("station") / "run"
    setup = setup_run(STATION, [GOAL_1], registry=registry)
    summary = Runner(setup, out).run()
    return setup.scenario, out, summary


def assert_pictures(out):
    plots = out / "plots"
    assert sorted(p.name for p in plots.iterdir()) == ["path.png", "timeline.png"]
    for picture in plots.iterdir():
        data = picture.read_bytes()
        assert data.startswith(PNG_SIGNATURE) and len(data) > 20_000


def test_a_transfer_run_writes_its_path_and_timeline(station_run):
    _, out, summary = station_run
    assert summary["status"] == "completed"
    assert_pictures(out)


def test_a_run_that_never_gets_a_plan_still_writes_both(tmp_path, registry):
    setup = setup_run(
        REPO / "scenarios" / "ffsr_obstacles_planar.yaml",
        ["path_planner.plugin=straight-line"],  # it refuses: the spheres are in the way
        registry=registry,
    )
    summary = Runner(setup, tmp_path / "run").run()
    assert summary["status"] == "stopped"
    assert not (tmp_path / "run" / "trajectory.csv").exists()
    assert_pictures(tmp_path / "run")


def test_the_scene_holds_the_plan_the_station_and_the_moving_cylinder_at_three_instants(
    station_run,
):
    scenario, out, _ = station_run
    planned = read_planned(out / "trajectory.csv")
    np.testing.assert_allclose(planned[0], [0.0, 0.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(planned[-1], scenario.mission.goal.position, atol=1e-6)
    telemetry = read_telemetry(out / "telemetry.csv", max_points=500)
    scene = build_scene(scenario, telemetry, planned)
    assert len(scene.obstacles) == len(scenario.obstacles)
    moving = [p for p in scene.obstacles if len(p.path)]
    assert len(moving) == 1 and moving[0].centres.shape == (3, 3)
    assert moving[0].centres[0, 1] > moving[0].centres[-1, 1]  # it drifts towards -y
    everything = np.vstack([scene.flown, *(p.centres for p in scene.obstacles)])
    assert np.all(everything >= scene.lower) and np.all(everything <= scene.upper)


def test_the_station_views_name_the_lvlh_axes_and_the_timeline_shows_attitude_and_rate(
    station_run,
):
    scenario, out, _ = station_run
    telemetry = read_telemetry(out / "telemetry.csv", max_points=500)
    events = [json.loads(line) for line in (out / "events.jsonl").read_text().splitlines()]
    scene = build_scene(scenario, telemetry, read_planned(out / "trajectory.csv"))
    try:
        views = path_figure(scenario, scene).axes
        assert [views[0].get_xlabel(), views[0].get_ylabel(), views[0].get_zlabel()] == [
            "radial [m]",
            "along-track [m]",
            "orbit-normal [m]",
        ]
        assert [views[1].get_xlabel(), views[1].get_ylabel()] == ["radial [m]", "along-track [m]"]
        timeline = timeline_figure(scenario, telemetry, events, TransferMission.modes, 0.5)
        titles = [axis.get_title() for axis in timeline.axes]
        assert "Attitude: angle turned from the initial attitude" in titles
        assert "Angular rate (world frame)" in titles and "Commanded thrust" in titles
    finally:
        plt.close("all")
