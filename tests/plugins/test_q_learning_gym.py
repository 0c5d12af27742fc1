"""The reach task as a Gymnasium environment: Gymnasium's own checker, and the planner's
rewards and ends step by step."""

from __future__ import annotations

import subprocess
import sys

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

MODULE = "dcsim_plugins.path_planners.q_learning.gym"
"""The module that registers the environment when imported."""
ENVIRONMENT_ID = "dcsim/ManipulatorReachCells-v0"


@pytest.fixture(scope="module")
def env():
    # the module:id form imports the module, as a fresh process or a vector env's worker would
    environment = gymnasium.make(f"{MODULE}:{ENVIRONMENT_ID}", planner_params={"margin": 0})
    yield environment
    environment.close()


def test_gymnasiums_checker_passes(env):
    check_env(env.unwrapped, skip_render_check=True)


def test_the_shortest_path_reaches_the_target_with_the_planners_rewards(env):
    cells = env.unwrapped.cells
    observation, info = env.reset(seed=3)
    assert observation == cells.start
    np.testing.assert_allclose(info["centre"], [1.4, 0.9, -0.8])
    moves = [4, 4] + [2] * 4 + [1] * 4  # (+2, −4, −4) cells: +x, −y, −z
    total = 0.0
    for k, action in enumerate(moves):
        before = observation
        observation, reward, terminated, truncated, info = env.step(action)
        assert reward == cells.reward[before, action]
        assert terminated == (k == len(moves) - 1) and not truncated
        total += reward
    assert info["target"] and total == pytest.approx(9 * -1.0 + 100.0)


def test_random_starts_are_seeded_and_bad_actions_refused(env):
    first = [env.reset(seed=7, options={"random_start": True})[0] for _ in range(2)]
    assert first[0] == first[1]
    with pytest.raises(ValueError, match="action"):
        env.step(6)


def test_a_fresh_process_makes_the_environment_by_its_module_and_id():
    made = subprocess.run(
        [
            sys.executable,
            "-c",
            "import gymnasium\n"
            f"env = gymnasium.make('{MODULE}:{ENVIRONMENT_ID}', planner_params={{'margin': 0}})\n"
            "print(env.reset(seed=1)[0])",
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert made.returncode == 0, made.stderr
    start = gymnasium.make(f"{MODULE}:{ENVIRONMENT_ID}", planner_params={"margin": 0})
    assert made.stdout.split() == [str(start.unwrapped.cells.start)]
