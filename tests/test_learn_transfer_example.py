"""docs/examples/learn_transfer.py without Stable-Baselines3 or PyTorch: its help, and its
random and pd pilots flown through its own evaluation.

The training itself needs the ``rl`` extra's SB3 and PyTorch, which the test extra
leaves out; the script imports them inside its training function only.
"""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from types import ModuleType

import pytest

from tests.conftest import REPO

SCRIPT = REPO / "docs" / "examples" / "learn_transfer.py"

BLOCKED = "import sys; sys.modules.update(torch=None, stable_baselines3=None)"
"""Makes importing torch or SB3 fail in a subprocess, whether they are installed or not."""


@pytest.fixture(scope="module")
def script() -> ModuleType:
    """The example, imported as a module of its own."""
    spec = importlib.util.spec_from_file_location("learn_transfer", SCRIPT)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_its_help_needs_neither_torch_nor_stable_baselines3():
    code = f"{BLOCKED}; import runpy; runpy.run_path({str(SCRIPT)!r}, run_name='__main__')"
    done = subprocess.run(
        [sys.executable, "-c", code, "--help"], capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    for option in ("--timesteps", "--episodes", "--seed", "--out", "--algorithm"):
        assert option in done.stdout
    assert "{ppo,sac}" in done.stdout


def test_the_random_pilot_flies_two_seeded_episodes_the_same_twice(script):
    first = script.evaluate(script.random_pilot, [0, 1])
    assert first == script.evaluate(script.random_pilot, [0, 1])
    assert len(first) == 2 and first[0] != first[1]
    for episode in first:
        assert set(episode) == {
            "return",
            "goal_met",
            "collided",
            "time_s",
            "peak_speed_mps",
            "delta_v_mps",
            "goal_distance_m",
        }
        assert episode["return"] < 0  # a random walk pays for its path length
    summary = script.summarise(first)
    assert summary["episodes"] == 2 and summary["success_rate"] == 0.0
    assert "| random | 0% |" in script.table({"random": summary})


def test_the_pd_pilot_strikes_the_first_sphere_flying_straight_at_the_goal(script):
    episodes = script.evaluate_pd([0, 1])
    assert [e["collided"] for e in episodes] == [True, True]
    assert [e["goal_met"] for e in episodes] == [False, False]
    assert all(e["return"] is None for e in episodes)
    # the controller keeps to the robot's max_speed (0.2 m/s) until it strikes
    assert all(0.0 < e["peak_speed_mps"] <= 0.2 for e in episodes)
    # the first sphere sits 1.6 m along the 6 m transfer
    assert all(4.0 < e["goal_distance_m"] < 6.0 for e in episodes)
