"""``dcsim bench grid-search``: the paper's goals posed on the station, planned, tabled."""

from __future__ import annotations

import math

import numpy as np
import pytest

from dcsim.bench.grid_search import (
    FOOT,
    GOALS,
    PAPER_DELTA_V,
    WEIGHTINGS,
    Cell,
    goal_problem,
    plan_cell,
    tables,
)
from dcsim.bench.path_problems import load_problem
from dcsim.registry.discovery import PluginRegistry
from tests.conftest import REPO

STATION = REPO / "scenarios" / "station_inspection.yaml"


@pytest.fixture(scope="module")
def station():
    return load_problem(str(STATION))


def test_the_paper_goals_are_its_grid_units_in_metres():
    for name, position in GOALS.items():
        units = [float(u) for u in name.strip("<>").split()]
        np.testing.assert_allclose(np.array(position) / (6 * FOOT), units, atol=1e-3)


def test_a_goal_problem_changes_only_the_goal_weights_and_budget(station):
    problem = goal_problem(station, "<1 4 1>", (1.0, 0.5), 7.0)
    np.testing.assert_array_equal(problem.goal.position, GOALS["<1 4 1>"])
    assert (problem.weights.delta_v, problem.weights.length, problem.weights.time) == (1, 0.5, 0)
    assert problem.time_budget == 7.0
    assert problem.obstacles == station.problem.obstacles
    assert problem.start == station.problem.start


@pytest.mark.parametrize("planner", ["grid-astar", "multi-burn"])
def test_both_planners_reach_the_first_goal_clear_of_the_station(station, planner):
    registry = PluginRegistry.discover()
    problem = goal_problem(station, "<1 2.167 0>", (1.0, 0.0), 10.0)
    cell = plan_cell(registry, planner, problem, "<1 2.167 0>", (1.0, 0.0))
    assert cell.status == "solved", cell.reason
    assert not cell.collides and cell.clearance > 0
    assert cell.delta_v == pytest.approx(cell.trajectory.delta_v / FOOT)
    assert problem.goal.contains(cell.trajectory.end_state(problem.goal))
    assert math.isnan(cell.points) == (planner == "multi-burn")


def test_tables_put_the_paper_beside_ours_and_the_ratio_per_goal():
    cells = [
        Cell("grid-astar", goal, weights, "solved", 0.1, points=10.0 * (i + 1), delta_v=0.5)
        for i, goal in enumerate(GOALS)
        for weights in WEIGHTINGS
    ]
    cells += [Cell("multi-burn", goal, (1.0, 0.0), "solved", 0.2, delta_v=0.25) for goal in GOALS]
    text = tables(cells)
    assert f"0.500 ({PAPER_DELTA_V[0][0]:.3f})" in text
    assert "30 (*)" in text  # the paper's unfinished third-goal runs
    assert text.count("| 2.00 |") == len(GOALS)  # 0.5 / 0.25 on every goal
