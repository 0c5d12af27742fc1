"""The q-learning planner: the thesis's actions, ε rule, update and rewards, the exact
solver it is scored against, its saved tables and its answers."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from dcsim_plugins.path_planners.q_learning.cells import ACTIONS, CellRules, build_environment
from dcsim_plugins.path_planners.q_learning.planner import QLearningPlanner, simplified
from dcsim_plugins.path_planners.q_learning.tabular_q import (
    Schedule,
    choose_action,
    greedy_rollout,
    td_update,
    train,
)

from dcsim.api import NoPath, PluginError, Trajectory
from dcsim.bench.cell_optimum import optimal_values, reachable_cells, working_cells
from dcsim.testing.problems import reach_problem


def planner(seed: int = 0, **params) -> QLearningPlanner:
    return QLearningPlanner(QLearningPlanner.Params(**params), np.random.default_rng(seed))


@pytest.fixture(scope="module")
def small():
    """The thesis's reach on the grid of start and target cells only (no margin)."""
    return build_environment(reach_problem(), CellRules(margin=0))


@pytest.fixture(scope="module")
def application():
    """The reach with the planner's default grid, and a table trained on it."""
    environment = planner().environment(reach_problem())
    return environment, planner().train(environment)


# ----------------------------------------------------------------- environment


def test_actions_move_one_cell_and_stop_at_the_grid_edges(small):
    shape = small.shape
    assert shape == (3, 5, 5)  # the target is (+2, −4, −4) cells from the start
    indices = np.column_stack(np.unravel_index(np.arange(small.cells), shape))
    for cell, index in enumerate(indices):
        for action, step in enumerate(ACTIONS):
            moved = index + step
            inside = np.all((moved >= 0) & (moved < shape))
            expected = np.ravel_multi_index(tuple(moved if inside else index), shape)
            assert small.next_cell[cell, action] == expected


def test_the_lattice_is_anchored_at_the_end_effector_and_holds_the_target(small):
    problem = reach_problem()
    np.testing.assert_allclose(small.centres(np.array([small.start]))[0], [1.4, 0.9, -0.8])
    np.testing.assert_allclose(
        small.centres(np.array([small.target]))[0], problem.goal.position, atol=1e-12
    )


def test_cell_states_keep_the_centre_of_mass_and_the_attitude(small):
    model = reach_problem().model
    problem = reach_problem()
    q0 = problem.start.configuration
    centre = model.centre_of_mass(q0)
    for cell in (small.start, small.target, 7):
        q = np.concatenate([small.base_positions[cell], q0[3:7], small.joints[cell]])
        np.testing.assert_allclose(model.centre_of_mass(q), centre, atol=1e-9)
        np.testing.assert_allclose(
            model.forward_kinematics(q).end_effector, small.centres(np.array([cell]))[0], atol=1e-8
        )


@pytest.mark.parametrize(
    "rules, reason",
    [
        (CellRules(margin=0, joint_limit=np.radians(60.0)), "joint limit"),
        (CellRules(margin=0, singular_det=4.3), "singularity"),
        (CellRules(margin=0, sight_limit=np.radians(39.15)), "target out of sight"),
    ],
)
def test_each_constraint_makes_terminal_cells(rules, reason):
    environment = build_environment(reach_problem(), rules)
    broken = [c for c in range(environment.cells) if environment.reasons[c] == reason]
    assert broken, f"no cell breaks {reason}"
    assert all(environment.terminal[c] and environment.ends[c] for c in broken)
    assert not environment.terminal[environment.start]  # where the arm already is
    entering = environment.reward[environment.next_cell == broken[0]]
    assert np.all(entering == rules.terminal_reward)


def test_the_base_criterion_costs_a_penalty_and_is_not_terminal():
    rules = CellRules(margin=0, base_ratio=0.05, base_penalty=-3.0)
    environment = build_environment(reach_problem(), rules)
    missed = np.flatnonzero(~environment.base_ok & ~environment.ends)
    assert missed.size and not environment.terminal[missed].any()
    into = environment.reward[environment.next_cell == missed[0]]
    assert np.all(into == rules.step_reward + rules.base_penalty)


# ----------------------------------------------------------------- learning rules


def test_epsilon_rises_linearly_and_is_the_probability_of_the_greedy_action():
    schedule = Schedule(episodes=5, epsilon_start=0.1, epsilon_end=0.9)
    np.testing.assert_allclose([schedule.epsilon(k) for k in range(5)], [0.1, 0.3, 0.5, 0.7, 0.9])
    row = np.array([0.0, 2.0, 5.0, 5.0, 1.0, 0.0])
    assert choose_action(row, epsilon=0.9, draw=0.5, random_action=4) == 2  # greedy, first max
    assert choose_action(row, epsilon=0.1, draw=0.5, random_action=4) == 4  # explores


def test_one_temporal_difference_update_by_hand():
    q = np.array([[1.0, 2.0], [3.0, 5.0]])
    td_update(q, cell=0, action=1, reward=-1.0, after=1, ends=False, alpha=0.9, gamma=0.9)
    assert q[0, 1] == pytest.approx(2.0 + 0.9 * (-1.0 + 0.9 * 5.0 - 2.0))
    td_update(q, cell=1, action=0, reward=100.0, after=0, ends=True, alpha=0.5, gamma=0.9)
    assert q[1, 0] == pytest.approx(3.0 + 0.5 * (100.0 - 3.0))


def test_training_is_reproducible_from_the_seed(small):
    args = (small.next_cell, small.reward, small.ends, np.flatnonzero(~small.ends))
    first = train(*args, Schedule(episodes=200), np.random.default_rng(4))
    again = train(*args, Schedule(episodes=200), np.random.default_rng(4))
    other = train(*args, Schedule(episodes=200), np.random.default_rng(5))
    np.testing.assert_array_equal(first.q, again.q)
    assert not np.array_equal(first.q, other.q)


# ----------------------------------------------------------------- exact solver


def tiny_environment():
    """A 3 × 2 × 1 grid, target at one corner, one terminal cell, rewards as the planner's."""
    shape = (3, 2, 1)
    indices = np.column_stack(np.unravel_index(np.arange(6), shape))
    moved = indices[:, None, :] + ACTIONS[None]
    inside = np.all((moved >= 0) & (moved < shape), axis=2)
    moved = np.where(inside[:, :, None], moved, indices[:, None, :])
    next_cell = np.ravel_multi_index(tuple(moved.transpose(2, 0, 1)), shape)
    target, terminal = 5, 2
    entering = np.full(6, -1.0)
    entering[3] = -2.0  # the base criterion missed there
    entering[terminal], entering[target] = -100.0, 100.0
    ends = np.zeros(6, dtype=bool)
    ends[[terminal, target]] = True
    return next_cell, entering[next_cell], ends, target


def brute_force_return(next_cell, reward, ends, start, gamma, depth=7) -> float:
    """The best discounted return over every action sequence that ends within ``depth``."""
    best = -np.inf
    for actions in itertools.product(range(6), repeat=depth):
        cell, total = start, 0.0
        for k, action in enumerate(actions):
            total += gamma**k * reward[cell, action]
            cell = next_cell[cell, action]
            if ends[cell]:
                best = max(best, total)
                break
    return best


def test_value_iteration_matches_brute_force_on_a_tiny_grid():
    next_cell, reward, ends, target = tiny_environment()
    values = optimal_values(next_cell, reward, ends, gamma=0.9)
    for start in (0, 1, 3, 4):
        assert values[start] == pytest.approx(
            brute_force_return(next_cell, reward, ends, start, 0.9, depth=5)
        )


def test_reachable_and_working_cells_on_a_tiny_grid():
    next_cell, reward, ends, target = tiny_environment()
    reach = reachable_cells(next_cell, ends, target)
    assert reach.tolist() == [True, True, False, True, True, False]
    # a table whose greedy action is always "+z" (blocked: it stays) works nowhere
    stuck = np.zeros((6, 6))
    stuck[:, 0] = 1.0
    assert not working_cells(stuck, next_cell, ends, target).any()
    optimal = np.zeros((6, 6))
    values = optimal_values(next_cell, reward, ends, 0.9)
    optimal += reward + 0.9 * np.where(ends[next_cell], 0.0, values[next_cell])
    assert (working_cells(optimal, next_cell, ends, target) == reach).all()


# ----------------------------------------------------------------- the planner


def test_the_thesis_settings_make_every_reachable_cell_work(application):
    environment, training = application
    reach = reachable_cells(environment.next_cell, environment.ends, environment.target)
    works = working_cells(training.q, environment.next_cell, environment.ends, environment.target)
    assert reach.sum() == environment.cells - 1
    assert (works == reach).all()  # 100 % at α = γ = 0.9 (Table 7.3)
    optimum = optimal_values(environment.next_cell, environment.reward, environment.ends, 0.9)
    rollout = planner().greedy_path(environment, training.q)
    assert rollout.outcome == "target"
    assert rollout.discounted_return >= optimum[environment.start] - 0.01 * abs(
        optimum[environment.start]
    )
    assert training.returns[-100:].mean() > training.returns[:100].mean()  # Fig. 7.2


def test_plan_flies_the_cells_to_the_target_within_the_limits():
    problem = reach_problem()
    answer = planner().plan(problem)
    assert isinstance(answer, Trajectory), answer
    np.testing.assert_allclose(answer.positions[0], [1.4, 0.9, -0.8], atol=1e-12)
    np.testing.assert_allclose(answer.positions[-1], problem.goal.position, atol=1e-12)
    assert not answer.velocities[0].any() and not answer.velocities[-1].any()
    assert np.linalg.norm(answer.velocities, axis=1).max() <= problem.max_speed * (1 + 1e-6)
    assert answer.statistics["moves"] == 10  # the fewest: (+2, −4, −4) cells


def test_a_table_is_saved_and_loaded(tmp_path):
    path = tmp_path / "agent" / "q.npz"
    problem = reach_problem()
    first = planner(seed=1, q_table_file=str(path), margin=0).plan(problem)
    assert path.exists() and first.statistics["loaded_q_table"] == 0.0
    again = planner(seed=2, q_table_file=str(path), margin=0).plan(problem)
    assert again.statistics["loaded_q_table"] == 1.0
    np.testing.assert_array_equal(first.positions, again.positions)
    retrained = planner(seed=2, q_table_file=str(path), margin=0, episodes=300).plan(problem)
    assert retrained.statistics["loaded_q_table"] == 0.0  # another schedule: trained again


def test_a_greedy_path_into_a_terminal_cell_is_no_path():
    environment = build_environment(reach_problem(), CellRules(margin=0))
    q = np.zeros((environment.cells, 6))
    q[:, 0] = 1.0  # always "+z": from the start it stays at the grid's edge
    rollout = greedy_rollout(
        q, environment.next_cell, environment.reward, environment.ends, environment.target,
        environment.start, 0.9,
    )  # fmt: skip
    assert rollout.outcome == "loop"


def test_a_constraint_at_the_target_and_a_short_budget_are_no_path():
    problem = reach_problem()
    refused = planner(singular_det=1e6, margin=0).plan(problem)
    assert isinstance(refused, NoPath) and "singularity" in refused.reason
    hurried = planner().plan(reach_problem(time_budget=0.05))
    assert isinstance(hurried, NoPath) and "budget" in hurried.reason


def test_simplified_keeps_every_point_within_the_tolerance():
    steps = np.array([[0, 0, 0], [0, 1, 0], [0, 1, 1], [0, 2, 1], [0, 2, 2], [1, 2, 2]], float)
    kept = simplified(steps, 1.0)
    assert len(kept) < len(steps)
    np.testing.assert_array_equal(kept[[0, -1]], steps[[0, -1]])
    assert len(simplified(steps, 0.0)) == len(steps)


def test_a_target_in_the_start_cell_is_one_short_move():
    problem = reach_problem(target=(1.41, 0.9, -0.8))  # within the start's 5 cm cell
    answer = planner().plan(problem)
    assert isinstance(answer, Trajectory)
    assert answer.length == pytest.approx(0.01)  # straight there, no detour
    assert np.isfinite(answer.velocities).all()


def test_a_grid_larger_than_max_cells_and_a_foreign_table_are_refused(tmp_path):
    assert "max_cells" in planner(cell_size=0.001).plan(reach_problem()).reason
    foreign = tmp_path / "q.npy"
    np.save(foreign, np.zeros(3))
    with pytest.raises(PluginError, match="cannot read the Q-table"):
        planner(q_table_file=str(foreign), margin=0).plan(reach_problem())


def test_the_facing_axis_sets_the_sight_constraint():
    default = planner(margin=0).environment(reach_problem())
    turned = planner(margin=0, facing_axis=(0.0, 1.0, 0.0)).environment(reach_problem())
    assert default.sight.max() < np.radians(60.0) < turned.sight.min()
