"""dcsim's Gymnasium environments: Gymnasium's checkers, seeding, vector environments,
termination and the errors a user can make (docs/gym.md)."""

from __future__ import annotations

import subprocess
import sys
import warnings

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import dcsim.gym
from dcsim.api import ScenarioError
from dcsim.gym import ENVIRONMENTS, EpisodeOver
from tests.conftest import REPO

SHORT = {
    "dcsim/Transfer-v0": ["world.duration=3"],
    "dcsim/Debris-v0": ["world.duration=3"],
    "dcsim/Reach-v0": ["world.duration=0.2"],
}
"""Overrides that keep each environment's episodes a few dozen steps long."""

UNBOUNDED = "observation space m(in|ax)imum value is -?infinity"
"""The checkers' only remark on these environments: positions and velocities have no
bound, so the observation space says so."""


def episode(env: gymnasium.Env, seed: int, steps: int) -> tuple[list, list]:
    """Observations and rewards of ``steps`` seeded random steps from ``reset(seed)``."""
    observation, _ = env.reset(seed=seed)
    env.action_space.seed(seed)
    observations, rewards = [observation], []
    for _ in range(steps):
        observation, reward, terminated, truncated, _ = env.step(env.action_space.sample())
        observations.append(observation)
        rewards.append(reward)
        if terminated or truncated:
            break
    return observations, rewards


@pytest.mark.parametrize("env_id", sorted(ENVIRONMENTS))
def test_every_environment_passes_gymnasiums_checkers(env_id):
    env = gymnasium.make(env_id, overrides=SHORT[env_id])  # with the passive checker
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env.unwrapped, skip_render_check=True)
        episode(env, seed=1, steps=40)
    remarks = {str(w.message) for w in caught}
    assert all(_unbounded(remark) for remark in remarks), remarks
    assert env.observation_space.shape == (len(env.unwrapped.observation_names),)
    assert env.action_space.shape == (len(env.unwrapped.action_names),)
    env.close()


def _unbounded(remark: str) -> bool:
    import re

    return re.search(UNBOUNDED, remark) is not None


@pytest.mark.parametrize("env_id", ["dcsim/Transfer-v0", "dcsim/Debris-v0"])
def test_a_seed_reproduces_an_episode_bit_for_bit_and_another_seed_does_not(env_id):
    options = {"start_spread": 0.5} if env_id == "dcsim/Transfer-v0" else {}
    env = gymnasium.make(env_id, overrides=SHORT[env_id], **options)
    first, first_rewards = episode(env, seed=7, steps=30)
    episode(env, seed=8, steps=5)  # something else in between
    again, again_rewards = episode(env, seed=7, steps=30)
    other, _ = episode(env, seed=9, steps=30)
    assert len(first) == len(again) == 31
    assert all(np.array_equal(a, b) for a, b in zip(first, again, strict=True))
    assert first_rewards == again_rewards
    assert not np.array_equal(first[0], other[0])
    env.close()


def test_episodes_after_the_first_seed_are_drawn_from_it_reproducibly():
    env = gymnasium.make(
        "dcsim/Transfer-v0", overrides=SHORT["dcsim/Transfer-v0"], start_spread=1.0
    )
    starts = [env.reset(seed=3)[0]] + [env.reset()[0] for _ in range(2)]
    again = [env.reset(seed=3)[0]] + [env.reset()[0] for _ in range(2)]
    assert all(np.array_equal(a, b) for a, b in zip(starts, again, strict=True))
    assert not np.array_equal(starts[1], starts[2])
    env.close()


def test_two_asynchronous_environments_step_and_reset_on_their_own():
    make = [
        lambda: gymnasium.make("dcsim.gym:dcsim/Transfer-v0", overrides=["world.duration=1"])
    ] * 2
    vector = gymnasium.vector.AsyncVectorEnv(make)
    try:
        observations, _ = vector.reset(seed=[1, 2])
        assert observations.shape == (2, 52)
        ended = np.zeros(2, dtype=bool)
        for _ in range(12):  # 10 control periods of 0.1 s end an episode; then a reset
            observations, rewards, terminated, truncated, _ = vector.step(
                vector.action_space.sample()
            )
            ended |= truncated
        assert ended.all() and np.isfinite(observations).all() and rewards.shape == (2,)
    finally:
        vector.close()


def test_the_module_prefixed_id_works_in_a_fresh_process():
    code = (
        "import gymnasium\n"
        "env = gymnasium.make('dcsim.gym:dcsim/Reach-v0', overrides=['world.duration=0.05'])\n"
        "observation, info = env.reset(seed=0)\n"
        "print(observation.shape, info['mode'])\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=REPO, timeout=120
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "(29,) REACH"


def test_arriving_in_the_goal_region_terminates_with_the_goal_reward():
    env = gymnasium.make(
        "dcsim/Transfer-v0",
        overrides=[
            "obstacles=[]",
            "mission.goal.position=[0.5, 0, 0]",
            "mission.goal.velocity_tolerance=1",
        ],
        attitude="controller",
    )
    env.reset(seed=0)
    total, terminated, truncated, steps = 0.0, False, False, 0
    while not (terminated or truncated):
        _, reward, terminated, truncated, info = env.step(np.array([0.2, 0.0, 0.0]))
        total += reward
        steps += 1
    assert terminated and not truncated and info["goal_met"]
    assert reward == pytest.approx(10.0)  # flying straight at it: progress pays the length
    # progress 0.4 m less the length flown (w_L = 1), then the goal's 10
    assert total == pytest.approx(10.0, abs=0.01)
    with pytest.raises(EpisodeOver, match="reset"):
        env.step(np.zeros(3))
    env.close()


def test_flying_above_the_speed_limit_costs_what_the_speed_term_says():
    options = {"overrides": ["obstacles=[]"], "attitude": "controller"}
    limited = gymnasium.make("dcsim/Transfer-v0", speed_weight=10.0, **options)
    free = gymnasium.make("dcsim/Transfer-v0", speed_weight=0.0, **options)
    limited.reset(seed=0)
    free.reset(seed=0)
    full = np.array([1.0, 0.0, 0.0])  # 0.2 m/s² on 5 kg: past 0.2 m/s after about 1 s
    for _ in range(20):
        _, with_term, *_ = limited.step(full)
        _, without, *_ = free.step(full)
        speed = float(np.linalg.norm(limited.unwrapped.runner.outputs["velocity"]))
        over = max(0.0, speed - 0.2)
        assert without - with_term == pytest.approx(10.0 * over * 0.1, abs=1e-12)
    assert over > 0.15
    limited.close()
    free.close()


@pytest.mark.parametrize("stops", ["true", "false"])
def test_a_collision_terminates_with_the_penalty_whether_or_not_the_run_stops_on_it(stops):
    env = gymnasium.make(
        "dcsim/Transfer-v0", overrides=[f"stop.on_collision={stops}"], attitude="controller"
    )
    env.reset(seed=0)
    terminated = truncated = False
    while not (terminated or truncated):
        observation, reward, terminated, truncated, info = env.step(np.array([1.0, 0.0, 0.0]))
    assert terminated and info["collisions"] >= 1 and not info["goal_met"]
    assert reward < -9.0 and np.isfinite(observation).all()
    assert env.unwrapped.runner.ended == (stops == "true")
    with pytest.raises(EpisodeOver):
        env.step(np.zeros(3))
    env.close()


def test_the_nearest_obstacle_is_observed_relative_to_the_estimate():
    env = gymnasium.make("dcsim/Transfer-v0", obstacles=2)
    observation, _ = env.reset(seed=0)
    names = env.unwrapped.observation_names
    row = {name: observation[i] for i, name in enumerate(names)}
    tracks = env.unwrapped.runner.surroundings.obstacles
    gaps = [np.linalg.norm(t.position) - t.radius for t in tracks]  # the robot starts at 0
    nearest = tracks[int(np.argmin(gaps))]
    assert len(names) == 13 + 6 + 1 + 2 * 8
    assert [row["obstacle1_dx_m"], row["obstacle1_dy_m"], row["obstacle1_dz_m"]] == pytest.approx(
        nearest.position
    )
    assert row["obstacle1_radius_m"] == pytest.approx(nearest.radius)
    assert row["obstacle1_seen"] == row["obstacle2_seen"] == 1.0
    assert [row["goal_dx_m"], row["goal_dy_m"], row["goal_dz_m"]] == pytest.approx([6, 0, 0])
    env.close()


def test_reach_actions_are_joint_torques_scaled_to_the_links_limits_and_recorded():
    env = gymnasium.make("dcsim/Reach-v0", overrides=SHORT["dcsim/Reach-v0"])
    env.reset(seed=0)
    runner = env.unwrapped.runner
    runner.recorder.keep_rows = True
    env.step(np.array([1.0, -0.5, 0.0, 0.25, 0.0, 2.0]))  # the last is clipped to 1
    row = runner.recorder.rows[0]  # the first period's, recorded with the command flown
    torques = [row[f"joint_torque_{j}"] for j in range(1, 7)]
    assert torques == pytest.approx([100.0, -50.0, 0.0, 25.0, 0.0, 100.0])
    assert [row["tx"], row["ty"], row["tz"], row["fx"]] == [0.0] * 4  # the base floats free
    env.close()


def test_a_scenario_of_another_mission_or_a_bad_option_is_refused():
    with pytest.raises(ScenarioError, match="mission.type: is debris, but TransferEnv flies"):
        gymnasium.make("dcsim/Transfer-v0", scenario=REPO / "scenarios" / "default.yaml")
    with pytest.raises(ValueError, match="attitude must be one of agent, controller"):
        gymnasium.make("dcsim/Transfer-v0", attitude="wheels")
    with pytest.raises(ScenarioError, match="world.duration"):
        gymnasium.make("dcsim/Debris-v0", overrides=["world.duration=-1"])
    assert dcsim.gym.TransferEnv.default_scenario == "ffsr_obstacles.yaml"
