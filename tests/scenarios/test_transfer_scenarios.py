"""The packaged transfer scenarios: they validate, fly their source's planner to the
goal, end clearly with the straight-line baseline, and hold the geometry they were
designed with."""

from __future__ import annotations

import re
import runpy

import numpy as np
import pytest
import yaml
from click.testing import CliRunner

from dcsim.api import Shape, ShapeKind
from dcsim.cli.main import cli
from dcsim.geometry import quaternion_conjugate, rotate
from dcsim.registry.discovery import PluginRegistry
from dcsim.run.loop import Runner
from dcsim.run.setup import setup_run
from dcsim.scenario import read_scenario
from dcsim.world.objects import build_objects
from tests.conftest import REPO

SCENARIOS = REPO / "scenarios"
STATION = SCENARIOS / "station_inspection.yaml"
ASTEROIDS = SCENARIOS / "asteroid_escape.yaml"
FFSR = SCENARIOS / "ffsr_obstacles.yaml"
FFSR_PLANAR = SCENARIOS / "ffsr_obstacles_planar.yaml"
TRANSFER_FILES = (STATION, ASTEROIDS, FFSR, FFSR_PLANAR)
SOURCE_PLANNERS = {
    STATION: "grid-astar",
    ASTEROIDS: "ompl-control",
    FFSR: "ant-colony",
    FFSR_PLANAR: "ant-colony",
}
"""The planner of each file's source: the Boeing paper's grid A*, the course project's
kinodynamic RRT, the ant colony paper's colony."""
STRAIGHT_LINE = "path_planner.plugin=straight-line"
"""The override each file documents for the straight-line baseline."""

GRID = 6 * 0.3048
"""The Boeing paper's grid spacing, 6 ft in m."""
PAPER_GOALS = {1: (1, 2.167, 0), 2: (1, 4, 1), 3: (8.667, -0.667, 9.833)}
"""The paper's goals in grid units (Tables 3 and 4)."""
GOAL_OVERRIDES = {
    1: "mission.goal.position=[1.8288,3.9624,0.0]",
    2: "mission.goal.position=[1.8288,7.3152,1.8288]",
}
"""The overrides the station file documents for goals 1 and 2."""
NODE_ID = 3
LOGISTICS_ID = 1
BESIDE = 1.5
"""Largest gap from goals 1 and 2 to the node's surface, m."""


@pytest.fixture(scope="module")
def registry():
    return PluginRegistry.discover()


def surface_distance(shape: Shape, centre: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Signed distance (m) of ``points`` (N, 3) to ``shape`` placed at ``centre``
    (negative inside)."""
    body = rotate(quaternion_conjugate(shape.orientation), np.asarray(points) - centre)
    if shape.kind is ShapeKind.SPHERE:
        return np.linalg.norm(body, axis=1) - shape.radius
    if shape.kind is ShapeKind.BOX:
        excess = np.abs(body) - shape.half_extents
    else:
        excess = np.column_stack(
            [np.hypot(body[:, 0], body[:, 1]) - shape.radius, np.abs(body[:, 2]) - shape.height / 2]
        )
    outside = np.linalg.norm(np.maximum(excess, 0.0), axis=1)
    return outside + np.minimum(excess.max(axis=1), 0.0)


def segment(start, end, count: int = 2001) -> np.ndarray:
    return np.linspace(start, end, count)


def static_objects(path, overrides=()):
    """The scenario and its objects with their positions at t = 0."""
    scenario = read_scenario(path, overrides)
    return scenario, [(o, o.motion.state_at(0.0)[0]) for o in build_objects(scenario)]


def test_every_transfer_scenario_validates():
    result = CliRunner().invoke(cli, ["validate", *map(str, TRANSFER_FILES)])
    assert result.exit_code == 0, result.output
    assert result.output.count("ok ") == len(TRANSFER_FILES)


@pytest.mark.parametrize(
    "path", TRANSFER_FILES, ids=["station", "asteroids", "ffsr", "ffsr-planar"]
)
def test_each_file_flies_its_sources_planner_to_the_goal(path, registry):
    setup = setup_run(path, registry=registry)
    assert setup.scenario.path_planner.plugin == SOURCE_PLANNERS[path]
    assert setup.scenario.controller.plugin == "pd"
    runner = Runner(setup, None)
    summary = runner.run()
    assert (summary["status"], summary["reason"]) == ("completed", "goal reached")
    assert summary["goal_met"] is True and summary["collisions"] == 0
    assert [e for e in runner.recorder.events if e["event"] == "no_path"] == []
    assert summary["sim_time_s"] < setup.scenario.world.duration


@pytest.mark.parametrize(
    "path", TRANSFER_FILES, ids=["station", "asteroids", "ffsr", "ffsr-planar"]
)
def test_each_header_names_its_planner_and_the_straight_line_override(path):
    header = "".join(line for line in path.read_text().splitlines(True) if line.startswith("#"))
    flies = rf"The file flies the (paper|source)'s planner, [^.]*\b{SOURCE_PLANNERS[path]}\b"
    assert re.search(flies, header.replace("\n#", ""))
    assert f"dcsim run scenarios/{path.name} --set {STRAIGHT_LINE}" in header


def test_the_asteroid_escape_repeats_exactly(registry):
    """ompl-control is seeded from the scenario and stops at its first solution."""

    def records():
        runner = Runner(setup_run(ASTEROIDS, registry=registry), None)
        runner.run()
        return runner.recorder.events, runner.recorder.rows

    first, second = records(), records()
    assert any(e["event"] == "path" for e in first[0])
    assert first == second


@pytest.mark.parametrize(
    ("path", "overrides", "status", "reason"),
    [
        (STATION, (), "stopped", "no path after 3 attempts: the straight path passes"),
        (STATION, (GOAL_OVERRIDES[1],), "completed", "goal reached"),
        (STATION, (GOAL_OVERRIDES[2],), "completed", "goal reached"),
        (ASTEROIDS, (), "stopped", "no path after 3 attempts: the straight path passes"),
        (FFSR, (), "stopped", "no path after 3 attempts: the straight path passes"),
        (FFSR_PLANAR, (), "stopped", "no path after 3 attempts: the straight path passes"),
    ],
    ids=["station-goal3", "station-goal1", "station-goal2", "asteroids", "ffsr", "ffsr-planar"],
)
def test_straight_line_ends_clearly(path, overrides, status, reason, registry):
    setup = setup_run(path, (STRAIGHT_LINE, *overrides), registry=registry)
    assert setup.scenario.controller.plugin == "pd"
    summary = Runner(setup, None).run()
    assert (summary["status"], summary["reason"][: len(reason)]) == (status, reason)
    assert summary["collisions"] == 0
    assert summary["reached"] is summary["goal_met"] is (status == "completed")
    assert summary["sim_time_s"] < setup.scenario.world.duration


@pytest.mark.parametrize("planner", ["grid-astar", "multi-burn"])
@pytest.mark.parametrize("goal", [1, 2], ids=["goal1", "goal2"])
def test_the_papers_planners_reach_goals_1_and_2_within_the_run(planner, goal, registry):
    overrides = (f"path_planner.plugin={planner}", GOAL_OVERRIDES[goal])
    summary = Runner(setup_run(STATION, overrides, registry=registry), None).run()
    assert (summary["reason"], summary["goal_met"], summary["collisions"]) == (
        "goal reached",
        True,
        0,
    )


def test_station_goals_are_the_papers_in_metres():
    for number, override in GOAL_OVERRIDES.items():
        goal = read_scenario(STATION, [override]).mission.goal.position
        np.testing.assert_allclose(goal, np.array(PAPER_GOALS[number]) * GRID, atol=1e-3)
    third = read_scenario(STATION).mission.goal.position
    np.testing.assert_allclose(third, np.array(PAPER_GOALS[3]) * GRID, atol=1e-3)


def test_station_has_fourteen_fixed_components_and_one_moving_cylinder():
    scenario = read_scenario(STATION)
    fixed = [spec for spec in scenario.obstacles if spec.motion.type == "static"]
    moving = [spec for spec in scenario.obstacles if spec.motion.type != "static"]
    assert len(fixed) == 14
    assert {spec.shape.type for spec in fixed} == {"cylinder", "box"}
    assert [(spec.shape.type, spec.motion.type) for spec in moving] == [("cylinder", "cw")]
    drift = moving[0].motion.build(scenario.mean_motion)
    start, later = drift.position_at(0.0), drift.position_at(600.0)
    assert later[1] < start[1] - 10.0 and abs(later[0] - start[0]) < 1e-3


def test_station_goal_3_is_behind_the_logistics_module_and_goals_1_2_beside_the_node():
    scenario, objects = static_objects(STATION)
    start = np.array(scenario.robot.initial.position)
    robot = scenario.robot.radius

    def gap(obj_id, points):
        obj, centre = next((o, c) for o, c in objects if o.id == obj_id)
        return surface_distance(obj.shape, centre, points)

    third = segment(start, scenario.mission.goal.position)
    assert gap(LOGISTICS_ID, third).min() < 0.0  # the segment runs through the module
    for override in GOAL_OVERRIDES.values():
        goal = np.array(read_scenario(STATION, [override]).mission.goal.position)
        assert 0.0 < gap(NODE_ID, goal[None])[0] < BESIDE
        direct = segment(start, goal)
        clearance = min(surface_distance(o.shape, c, direct).min() for o, c in objects)
        assert clearance > robot


def test_asteroid_field_is_the_scripts_draw_and_keeps_start_and_goal_clear():
    script = runpy.run_path(str(SCENARIOS / "asteroid_field.py"))
    field = yaml.safe_load(ASTEROIDS.read_text())["obstacles"]
    assert field == script["obstacle_entries"](script["draw_field"]())
    scenario, objects = static_objects(ASTEROIDS)
    radii = np.array([o.shape.radius for o, _ in objects])
    centres = np.array([c for _, c in objects])
    assert len(objects) == 40 and {o.shape.kind for o, _ in objects} == {ShapeKind.SPHERE}
    assert radii.min() >= 0.8 and radii.max() <= 2.5
    bounds = scenario.mission.bounds
    assert np.all(centres - radii[:, None] >= [-16, -8, -20])
    assert np.all(centres + radii[:, None] <= [16, 8, 20])
    start = np.array(scenario.robot.initial.position)
    assert np.min(np.linalg.norm(centres - start, axis=1) - radii) > scenario.robot.radius + 1.5
    goal = scenario.mission.goal
    low = np.array(goal.position) - goal.half_extents
    high = np.array(goal.position) + goal.half_extents
    np.testing.assert_allclose([low, high], [[-5, -5, -25], [5, 5, -21]])
    assert np.all(low >= bounds.lower) and np.all(high <= bounds.upper)


@pytest.mark.parametrize("path", [FFSR, FFSR_PLANAR], ids=["3-D", "planar"])
def test_ffsr_obstacles_sit_across_the_segment(path):
    scenario, objects = static_objects(path)
    assert scenario.robot.mass == 5.0
    inertia = 0.4 * scenario.robot.mass * scenario.robot.radius**2
    assert inertia == pytest.approx(0.20833, abs=1e-4)  # Table 1, L_0
    start = np.array(scenario.robot.initial.position)
    direct = segment(start, scenario.mission.goal.position)
    across = [
        surface_distance(o.shape, c, direct).min() < scenario.robot.radius for o, c in objects
    ]
    assert sum(across) == 3
    centres_z = np.array([c[2] for _, c in objects])
    planar = np.allclose(centres_z, 0.0)
    assert planar is (path == FFSR_PLANAR)
