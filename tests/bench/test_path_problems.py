"""The problem set of ``dcsim bench path-planners``: seeded families and transfer scenarios."""

from __future__ import annotations

import numpy as np
import pytest
from dcsim_plugins.path_planners.straight_line import StraightLinePlanner

from dcsim.bench.path_problems import FAMILIES, KEEP_OUT, load_problem
from dcsim.errors import DcsimError
from dcsim.messages import ShapeKind
from dcsim.registry.discovery import PluginOrigin, PluginRegistry
from dcsim.run.loop import Runner
from dcsim.run.setup import RunSetup
from dcsim.scenario import read_scenario


@pytest.mark.parametrize("family", list(FAMILIES))
def test_families_are_seeded_and_keep_start_and_goal_clear(family):
    first, again, other = (load_problem(s) for s in (f"{family}:3", f"{family}:3", family))
    assert first.name == f"{family}-3" and other.name == f"{family}-0"
    assert first.problem == again.problem and first.problem != other.problem
    problem = first.problem
    assert len(problem.obstacles) >= 16
    for obstacle in problem.obstacles:
        start_gap = np.linalg.norm(obstacle.position - problem.start.position)
        goal_gap = np.linalg.norm(obstacle.position - problem.goal.position)
        assert start_gap > obstacle.radius + problem.robot_radius + KEEP_OUT - 1e-9
        assert goal_gap > obstacle.radius + problem.goal.tolerance + KEEP_OUT - 1e-9


def test_families_differ_in_frame_motion_and_shape():
    cw = load_problem("cw-spheres").problem
    assert cw.frame.kind == "clohessy-wiltshire" and cw.frame.mean_motion > 0
    assert all(np.linalg.norm(o.velocity) > 0 for o in cw.obstacles)
    assert cw.goal.position[1] == 60.0  # along-track, an equilibrium of the frame
    shapes = {o.shape.kind for o in load_problem("shapes").problem.obstacles}
    assert shapes == {ShapeKind.BOX, ShapeKind.CYLINDER}
    assert load_problem("static-spheres").problem.frame.kind == "inertial"


class SpyPlanner(StraightLinePlanner):
    name = "spy"
    summary = "Remembers the problems it was given (test)"
    seen: list = []

    def plan(self, problem):
        SpyPlanner.seen.append(problem)
        return super().plan(problem)


def test_a_transfer_scenario_gives_the_problem_the_mission_poses(transfer_file):
    bench = load_problem(str(transfer_file))
    registry = PluginRegistry.discover()
    registry.register_class(SpyPlanner, PluginOrigin("tests", "0", "spy"))
    scenario = read_scenario(
        transfer_file, ["path_planner.plugin=spy", "world.duration=0.2"], registry
    )
    SpyPlanner.seen.clear()
    Runner(RunSetup.from_scenario(scenario, registry)).run()
    assert bench.name == "two_obstacles"
    assert SpyPlanner.seen[0] == bench.problem
    assert [o.id for o in bench.problem.obstacles] == [1, 2]  # 3 is beyond sensor range
    assert bench.problem.time_budget == 0.5 and bench.problem.max_delta_v == 3.0


def test_what_is_no_transfer_problem_is_refused(tmp_path):
    with pytest.raises(DcsimError, match="neither a problem family .* nor a scenario file"):
        load_problem("asteroids:2")
    debris = tmp_path / "debris.yaml"
    debris.write_text("name: debris here\n")
    with pytest.raises(DcsimError, match="is a debris mission; the path-planner bench takes"):
        load_problem(str(debris))
