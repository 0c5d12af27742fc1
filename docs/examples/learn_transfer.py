"""A learning baseline on ``dcsim/Transfer-v0``: a policy trained by Stable-Baselines3,
against a random policy and the scenario's pd controller, over the same seeded episodes.

The environment flies the packaged ``ffsr_obstacles.yaml``: a 5 kg free flyer crosses
6 m to its goal past four spheres, three of them across the straight line, so the pd
controller flying straight at the goal strikes the first sphere. The agent gives the
body force (``attitude="controller"``: the scenario's controller holds the attitude)
once every 0.5 s, 300 steps an episode; each episode starts within 0.5 m of the
scenario's start, drawn by its seed. :data:`ENV_OPTIONS` lists every option.

The script trains PPO (or SAC) with PyTorch on the CPU for ``--timesteps`` steps, then
flies ``--episodes`` episodes of seeds 0, 1, ... with each of three pilots:

- the trained policy, deterministic;
- a random policy (``action_space.sample()``, the action space seeded by the episode's
  seed);
- ``pd``: the scenario's controller flying at the goal (no action is taken: the
  episode's run is advanced with the controller's own command).

It writes ``learning_curve.png`` (the training episodes' return and success rate
against timesteps), ``results.json`` (success and collision rates, mean returns, times
to goal, peak speeds and delta-v, each episode's outcome and distance left to the goal,
timesteps, wall time, the environment's options) and the trained policy
(``policy.zip``, with its observation normaliser ``normaliser.pkl``) into ``--out`` and
prints a table.

Needs the ``rl`` extra (Gymnasium, Stable-Baselines3, PyTorch): a CPU PyTorch is
``pip install torch --index-url https://download.pytorch.org/whl/cpu`` before
``pip install dcsim[rl]``. Run it as::

    python docs/examples/learn_transfer.py --timesteps 600000 --out learn-out
"""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np

from dcsim.gym import TransferEnv
from dcsim.run.loop import Runner

ENV_ID = "dcsim.gym:dcsim/Transfer-v0"
"""The environment trained and evaluated (the packaged ffsr_obstacles.yaml)."""

ENV_OPTIONS: dict[str, Any] = {
    "overrides": [
        "world.control_period=0.5",  # s: 300 steps in the 150 s episode
        "world.physics_step=0.01",  # s
        "mission.goal.radius=0.3",  # m (the scenario's is 0.1)
        "mission.goal.velocity_tolerance=0.05",  # m/s (the scenario's is 0.02)
    ],
    "attitude": "controller",  # the action is the force; the controller holds attitude
    "start_spread": 0.5,  # m: each episode starts in a 1 m box about the scenario's start
    "progress_weight": 2.0,  # the shaping outweighs the path-length cost (w_L = 1/m)
    "speed_weight": 10.0,  # 1/m: flying above robot.max_speed (0.2 m/s) costs (the default)
}
"""The options every pilot flies with (``gymnasium.make(ENV_ID, **ENV_OPTIONS)``)."""

Pilot = Callable[[gymnasium.Env, np.ndarray, int], np.ndarray]
"""A policy: (environment, observation, episode seed) to an action."""


def make_env() -> gymnasium.Env:
    """A fresh transfer environment with :data:`ENV_OPTIONS`."""
    return gymnasium.make(ENV_ID, **ENV_OPTIONS)


def fly(env: gymnasium.Env, pilot: Pilot, seed: int) -> dict[str, Any]:
    """Fly one episode of seed ``seed`` with ``pilot`` (the action space seeded by it).

    Returns
    -------
    dict
        ``return`` (sum of rewards), ``goal_met``, ``collided``, ``time_s`` (the
        simulated time at the episode's end, s) and what :func:`flight` gives.
    """
    observation, info = env.reset(seed=seed)
    env.action_space.seed(seed)
    total, peak, over = 0.0, 0.0, False
    while not over:
        observation, reward, terminated, truncated, info = env.step(pilot(env, observation, seed))
        total += float(reward)
        peak = max(peak, speed(env))
        over = terminated or truncated
    return {
        "return": total,
        "goal_met": bool(info["goal_met"]),
        "collided": info["collisions"] > 0,
        "time_s": float(info["time_s"]),
        **flight(env, peak),
    }


def episode_run(env: gymnasium.Env) -> Runner:
    """The run of the environment's current episode."""
    assert isinstance(env.unwrapped, TransferEnv) and env.unwrapped.runner is not None
    return env.unwrapped.runner


def speed(env: gymnasium.Env) -> float:
    """The robot's true speed (m/s) in the episode's run now."""
    return float(np.linalg.norm(episode_run(env).outputs["velocity"]))


def flight(env: gymnasium.Env, peak_speed: float) -> dict[str, float]:
    """How the episode's run has flown: ``peak_speed_mps`` (as given: the fastest true
    speed at the end of a control period, m/s), ``delta_v_mps`` (spent, m/s) and
    ``goal_distance_m`` (true distance from the goal's centre now, m)."""
    runner = episode_run(env)
    assert runner.reference is not None  # the transfer's reference is the goal
    position = np.asarray(runner.outputs["position"])
    return {
        "peak_speed_mps": peak_speed,
        "delta_v_mps": float(runner.outputs["delta_v"]),
        "goal_distance_m": float(np.linalg.norm(position - runner.reference.position)),
    }


def random_pilot(env: gymnasium.Env, observation: np.ndarray, seed: int) -> np.ndarray:
    """A uniformly random action (:func:`fly` seeds the action space with the episode's
    seed)."""
    return env.action_space.sample()


def evaluate(pilot: Pilot, seeds: Sequence[int]) -> list[dict[str, Any]]:
    """Fly one episode per seed with ``pilot`` in a fresh environment (see :func:`fly`)."""
    env = make_env()
    try:
        return [fly(env, pilot, seed) for seed in seeds]
    finally:
        env.close()


def evaluate_pd(seeds: Sequence[int]) -> list[dict[str, Any]]:
    """Fly each seed's episode with the scenario's controller instead of an agent.

    The episode is reset as for an agent (same start), then its run is advanced with
    the controller's command until it ends. There is no return: the environment's
    reward is not computed outside ``step``.
    """
    env = make_env()
    episodes = []
    for seed in seeds:
        env.reset(seed=seed)
        runner = episode_run(env)
        peak = 0.0
        while not runner.ended:
            runner.advance()
            peak = max(peak, speed(env))
        summary = runner.close()
        episodes.append(
            {
                "return": None,
                "goal_met": bool(summary["goal_met"]),
                "collided": summary["collisions"] > 0,
                "time_s": float(summary["sim_time_s"]),
                **flight(env, peak),
            }
        )
    env.close()
    return episodes


def summarise(episodes: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """Success and collision rates, mean return, mean time to goal, mean peak speed and
    median delta-v of some episodes."""
    returns = [e["return"] for e in episodes if e["return"] is not None]
    arrivals = [e["time_s"] for e in episodes if e["goal_met"]]
    return {
        "mean_peak_speed_mps": float(np.mean([e["peak_speed_mps"] for e in episodes])),
        "median_delta_v_mps": float(np.median([e["delta_v_mps"] for e in episodes])),
        "episodes": len(episodes),
        "success_rate": float(np.mean([e["goal_met"] for e in episodes])),
        "collision_rate": float(np.mean([e["collided"] for e in episodes])),
        "mean_return": float(np.mean(returns)) if returns else None,
        "mean_time_to_goal_s": float(np.mean(arrivals)) if arrivals else None,
    }


def table(results: dict[str, dict[str, Any]]) -> str:
    """The summaries as a Markdown table, one row per pilot."""
    lines = [
        "| pilot | success | collision | mean return | mean time to goal (s) "
        "| mean peak speed (m/s) | median delta-v (m/s) |",
        "|---|---|---|---|---|---|---|",
    ]
    for name, row in results.items():
        mean_return = "—" if row["mean_return"] is None else f"{row['mean_return']:.2f}"
        arrival = row["mean_time_to_goal_s"]
        lines.append(
            f"| {name} | {row['success_rate']:.0%} | {row['collision_rate']:.0%} "
            f"| {mean_return} | {'—' if arrival is None else f'{arrival:.1f}'} "
            f"| {row['mean_peak_speed_mps']:.2f} | {row['median_delta_v_mps']:.2f} |"
        )
    return "\n".join(lines)


def plot_curve(curve: Sequence[tuple[int, float, bool]], path: Path, window: int = 100) -> None:
    """Save the training episodes' return and success rate (running means over ``window``
    episodes) against timesteps."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib import pyplot

    steps = np.array([c[0] for c in curve])
    returns = np.array([c[1] for c in curve])
    successes = np.array([c[2] for c in curve], dtype=float)
    width = min(window, max(len(curve), 1))
    kernel = np.ones(width) / width
    figure, (top, bottom) = pyplot.subplots(2, 1, sharex=True, figsize=(7, 5))
    top.plot(steps, returns, ".", markersize=2, alpha=0.3, color="grey")
    if len(curve) >= width:
        valid = slice(width - 1, None)
        top.plot(steps[valid], np.convolve(returns, kernel, "valid"), color="C0")
        bottom.plot(steps[valid], np.convolve(successes, kernel, "valid"), color="C2")
    top.set_yscale("symlog", linthresh=10.0)
    top.set_ylabel("episode return")
    bottom.set_ylabel(f"success rate\n(last {width} episodes)")
    bottom.set_xlabel("timesteps")
    bottom.set_ylim(-0.02, 1.02)
    figure.suptitle("dcsim/Transfer-v0: training episodes")
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    pyplot.close(figure)


def version(distribution: str) -> str:
    """The installed version of ``distribution``."""
    from importlib.metadata import version as installed

    return installed(distribution)


def parse(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """The command line (see the module)."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--timesteps", type=int, default=600_000, help="training steps")
    parser.add_argument("--episodes", type=int, default=100, help="evaluation episodes (seeds)")
    parser.add_argument("--seed", type=int, default=0, help="training seed")
    parser.add_argument("--out", type=Path, default=Path("learn-out"), help="output folder")
    parser.add_argument("--algorithm", choices=("ppo", "sac"), default="ppo")
    parser.add_argument("--envs", type=int, default=4, help="environments stepped together")
    return parser.parse_args(argv)


def train(arguments: argparse.Namespace) -> tuple[Any, Any, list[tuple[int, float, bool]]]:
    """Train the policy; return it, its observation normaliser and the training curve."""
    import torch
    from stable_baselines3 import PPO, SAC
    from stable_baselines3.common.callbacks import BaseCallback
    from stable_baselines3.common.monitor import Monitor
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

    torch.set_num_threads(1)
    curve: list[tuple[int, float, bool]] = []

    class Curve(BaseCallback):
        """Collects each finished training episode's (timestep, return, goal met)."""

        def _on_step(self) -> bool:
            for info in self.locals["infos"]:
                if "episode" in info:
                    curve.append((self.num_timesteps, info["episode"]["r"], info["goal_met"]))
            return True

    def monitored() -> gymnasium.Env:
        return Monitor(make_env())

    episodes = DummyVecEnv([monitored] * arguments.envs)
    episodes.seed(arguments.seed)
    normalised = VecNormalize(episodes, gamma=0.99)
    if arguments.algorithm == "ppo":
        model: Any = PPO(
            "MlpPolicy", normalised, n_steps=512, batch_size=256, seed=arguments.seed, device="cpu"
        )
    else:
        model = SAC("MlpPolicy", normalised, seed=arguments.seed, device="cpu")
    model.learn(total_timesteps=arguments.timesteps, callback=Curve())
    normalised.training = False
    return model, normalised, curve


def main(argv: Sequence[str] | None = None) -> dict[str, Any]:
    """Train, save the policy, evaluate, write ``learning_curve.png`` and ``results.json``,
    print the table (see the module)."""
    arguments = parse(argv)
    arguments.out.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    model, normaliser, curve = train(arguments)
    trained_s = time.perf_counter() - started
    model.save(arguments.out / "policy.zip")
    normaliser.save(str(arguments.out / "normaliser.pkl"))

    def trained(env: gymnasium.Env, observation: np.ndarray, seed: int) -> np.ndarray:
        action, _ = model.predict(normaliser.normalize_obs(observation), deterministic=True)
        return action

    seeds = range(arguments.episodes)
    episodes = {
        arguments.algorithm: evaluate(trained, seeds),
        "random": evaluate(random_pilot, seeds),
        "pd": evaluate_pd(seeds),
    }
    results = {name: summarise(flown) for name, flown in episodes.items()}
    plot_curve(curve, arguments.out / "learning_curve.png")
    report = {
        "algorithm": arguments.algorithm,
        "timesteps": arguments.timesteps,
        "training_seed": arguments.seed,
        "environments": arguments.envs,
        "evaluation_seeds": [0, arguments.episodes - 1],
        "training_wall_time_s": trained_s,
        "wall_time_s": time.perf_counter() - started,
        "training_episodes": len(curve),
        "env_id": ENV_ID,
        "env_options": ENV_OPTIONS,
        "versions": {name: version(name) for name in ("stable-baselines3", "torch", "gymnasium")},
        "results": results,
        "episodes": episodes,
    }
    (arguments.out / "results.json").write_text(json.dumps(report, indent=2), "utf-8")
    print(table(results))
    whole = report["wall_time_s"]
    print(f"trained {arguments.timesteps} steps in {trained_s:.0f} s; all: {whole:.0f} s")
    return report


if __name__ == "__main__":
    try:
        main()
    except ModuleNotFoundError as missing:  # the rl extra is not installed
        raise SystemExit(
            f"{missing.name} is missing: training needs the rl extra (see the module's "
            "docstring: a CPU PyTorch first, then pip install 'dcsim[rl]')"
        ) from None
