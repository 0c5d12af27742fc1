"""``dcsim bench q-learning``, added by the q-learning plugin through its hook: the
working cells and greedy gaps against value iteration on the planner's own cells, the
size sweep and the two application cases, with their figures."""

from __future__ import annotations

import numpy as np
from click.testing import CliRunner
from dcsim_plugins.path_planners.q_learning import bench
from dcsim_plugins.path_planners.q_learning.planner import QLearningPlanner

from dcsim.api import load_reach_problem, optimal_values, packaged_scenario_path
from dcsim.cli.main import cli

PNG = b"\x89PNG\r\n\x1a\n"
SCENARIO = packaged_scenario_path("space_manipulator_reach.yaml")


def test_the_working_table_scores_each_training_against_the_exact_values():
    problem = load_reach_problem(SCENARIO)
    rows, reachable, cells = bench.working_table(problem, [300], 2, settings=((0.9, 0.9),))
    (row,) = rows
    assert (row.alpha, row.gamma, row.episodes) == (0.9, 0.9, 300)
    assert 0 < reachable <= cells
    assert row.working.shape == (2,) and np.all((0 <= row.working) & (row.working <= 100))
    environment = QLearningPlanner({}, np.random.default_rng(0)).environment(problem)
    optimum = optimal_values(environment.next_cell, environment.reward, environment.ends, 0.9)
    assert optimum[environment.start] > 0  # the target is worth reaching from the start
    finite = row.greedy_gap[np.isfinite(row.greedy_gap)]
    assert np.all(finite >= 0)  # no greedy path beats the optimum


def test_the_command_prints_the_tables_and_writes_the_figures(tmp_path):
    result = CliRunner().invoke(
        cli,
        [
            "bench",
            "q-learning",
            "--scenario",
            str(SCENARIO),
            "--episodes",
            "50",
            "--seeds",
            "1",
            "--margins",
            "0",
            "--size-episodes",
            "50",
            "--figures",
            str(tmp_path),
        ],
    )
    assert result.exit_code == 0, result.output
    assert "| 0.2 | 0.5 | 50 |" in result.stdout
    assert "| 0 | 75 | 0 |" in result.stdout  # margin 0: the 75 cells of the reach's box
    assert "| [1.4, 0.9, -0.8] |" in result.stdout and "| [1.2, 0.9, -1.1] |" in result.stdout
    assert "α = 0.9, γ = 0.9, 50 episodes: " in result.stderr
    names = ("rewards", "sizes", "start_a", "start_b")
    for name in names:
        data = (tmp_path / f"q_learning_{name}.png").read_bytes()
        assert data.startswith(PNG) and len(data) > 10_000, name


def test_bad_numbers_are_errors_without_a_traceback():
    result = CliRunner().invoke(cli, ["bench", "q-learning", "--episodes", "many"])
    assert result.exit_code == 2, result.output
    assert "error: --episodes: expected numbers like 2,6, got 'many'" in result.stderr
    assert "Traceback" not in result.output
