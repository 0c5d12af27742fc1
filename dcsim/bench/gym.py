"""``dcsim bench gym``: how fast dcsim's Gymnasium environments step.

For each environment id (``dcsim/Transfer-v0``, ``dcsim/Debris-v0``, ``dcsim/Reach-v0``):

- **throughput**: ``n`` copies of the environment in ``gymnasium.vector.AsyncVectorEnv``
  (one worker process per copy, each with its own PyBullet client) and in
  ``SyncVectorEnv`` (all copies in the bench's process), made with the module-prefixed
  id (``dcsim.gym:dcsim/Transfer-v0``). After one seeded reset the vector is stepped a
  fixed number of times with random actions from its seeded action space, copies whose
  episode ended resetting on their next step (Gymnasium's default autoreset). The result
  is the environment steps of all copies per wall second of the stepping (making the
  vector, its reset and closing it not counted).
- **step cost**: one environment step (``gymnasium.make(id)``, the wrappers it adds
  included) against one tick of ``dcsim run`` on the same scenario flown as the
  environment flies it (the environment's scenario, ``path_planner=null``, the
  scenario's controller commanding), opened with :func:`dcsim.api.open_run` without a
  run directory and advanced without a command. Both fly the same number of control
  periods with their own episode seeds, alternately in one process, several times; an
  episode or run that ends is started afresh (starting it not counted). Each side is
  reported as its median wall time per control period, and the ratio against
  :data:`RATIO_TARGET`.
"""

from __future__ import annotations

import functools
import math
import statistics
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np

from dcsim.bench.figures import pyplot, save
from dcsim.gym import ENVIRONMENTS
from dcsim.registry.discovery import PluginRegistry
from dcsim.run.scripting import open_run
from dcsim.scenario.loader import packaged_scenario_path

VECTOR_KINDS = ("async", "sync")
"""The vector environments measured: ``AsyncVectorEnv`` and ``SyncVectorEnv``."""

RATIO_TARGET = 1.2
"""The project's target: an environment step costs at most this many run ticks."""

MODULE_PREFIX = "dcsim.gym:"
"""Prefix of an id that makes Gymnasium import :mod:`dcsim.gym` first (worker processes)."""


@dataclass(frozen=True)
class Throughput:
    """Environment steps per wall second of one vector of copies of one environment.

    Attributes
    ----------
    env_id : str
        The environment's id.
    vector : str
        ``"async"`` or ``"sync"``.
    envs : int
        Copies in the vector.
    steps : int
        Vector steps flown (each steps every copy once).
    seconds : float
        Wall time of those steps, s.
    episodes_ended : int
        Episodes that ended (terminated or truncated) in those steps; each copy's next
        step was its reset, timed with the rest.
    """

    env_id: str
    vector: str
    envs: int
    steps: int
    seconds: float
    episodes_ended: int

    @property
    def env_steps(self) -> int:
        """Environment steps flown by all copies together."""
        return self.steps * self.envs

    @property
    def steps_per_second(self) -> float:
        """Environment steps per wall second, 1/s."""
        return self.env_steps / self.seconds


@dataclass(frozen=True)
class StepCost:
    """Wall time per control period of an environment's step and of a run's tick.

    Attributes
    ----------
    env_id : str
        The environment's id.
    periods : int
        Control periods flown by each side in each repeat.
    env, run : list of float
        Seconds per control period of each repeat: ``env.step(action)`` and the run's
        ``advance()``.
    """

    env_id: str
    periods: int
    env: list[float]
    run: list[float]

    @property
    def env_step(self) -> float:
        """Median wall time of an environment step, s."""
        return statistics.median(self.env)

    @property
    def run_tick(self) -> float:
        """Median wall time of a run tick, s."""
        return statistics.median(self.run)

    @property
    def ratio(self) -> float:
        """The environment step's cost in run ticks (medians)."""
        return self.env_step / self.run_tick

    @property
    def met(self) -> bool:
        """Whether the ratio is within :data:`RATIO_TARGET`."""
        return self.ratio <= RATIO_TARGET


@dataclass(frozen=True)
class GymBenchResult:
    """Everything ``dcsim bench gym`` measured.

    Attributes
    ----------
    throughput : list of Throughput
        One per environment id, vector kind and number of copies, in that order.
    costs : list of StepCost
        One per environment id.
    """

    throughput: list[Throughput]
    costs: list[StepCost]

    def as_json(self) -> dict[str, Any]:
        """The results as JSON-ready values (times in s, rates in 1/s)."""
        return {
            "throughput": [
                {
                    **asdict(row),
                    "env_steps": row.env_steps,
                    "steps_per_second": row.steps_per_second,
                }
                for row in self.throughput
            ],
            "step_cost": [
                {
                    **asdict(cost),
                    "env_step_s": cost.env_step,
                    "run_tick_s": cost.run_tick,
                    "ratio": cost.ratio,
                    "target": RATIO_TARGET,
                    "met": cost.met,
                }
                for cost in self.costs
            ],
        }


def bench_gym(
    env_ids: Sequence[str],
    counts: Sequence[int],
    vectors: Sequence[str],
    steps: int,
    periods: int,
    repeats: int,
    seed: int = 0,
    progress: Callable[[str], None] | None = None,
) -> GymBenchResult:
    """Measure each environment's throughput in vectors and its step cost.

    Parameters
    ----------
    env_ids : sequence of str
        Registered ids (:data:`dcsim.gym.ENVIRONMENTS`).
    counts : sequence of int
        Numbers of copies per vector.
    vectors : sequence of str
        Vector kinds, from :data:`VECTOR_KINDS`.
    steps : int
        Vector steps per throughput measurement.
    periods : int
        Control periods per step-cost measurement, each side.
    repeats : int
        Step-cost measurements per side.
    seed : int
        Seeds the resets and the action spaces.
    progress : callable, optional
        Called with a line of text after each measurement.

    Returns
    -------
    GymBenchResult
        The throughput rows and step costs.
    """
    say = progress or (lambda line: None)
    registry = PluginRegistry.discover()
    rows, costs = [], []
    for env_id in env_ids:
        for vector in vectors:
            for count in counts:
                row = throughput(env_id, vector, count, steps, seed)
                say(f"{env_id} {vector} x{count}: {row.steps_per_second:.0f} steps/s")
                rows.append(row)
        cost = step_cost(env_id, periods, repeats, seed, registry)
        say(f"{env_id}: step {1e3 * cost.env_step:.3f} ms, tick {1e3 * cost.run_tick:.3f} ms")
        costs.append(cost)
    return GymBenchResult(rows, costs)


def throughput(
    env_id: str,
    vector: str,
    count: int,
    steps: int,
    seed: int = 0,
    overrides: Sequence[str] = (),
) -> Throughput:
    """Step ``count`` copies of ``env_id`` in a ``vector`` environment ``steps`` times.

    Parameters
    ----------
    env_id : str
        A registered id.
    vector : {"async", "sync"}
        ``AsyncVectorEnv`` (a worker process per copy) or ``SyncVectorEnv``.
    count : int
        Copies.
    steps : int
        Vector steps timed, after one reset with ``seed``.
    seed : int
        Seeds the reset (copy ``i`` with ``seed + i``) and the action space.
    overrides : sequence of str
        ``key.path=value`` overrides of the environment's scenario.

    Returns
    -------
    Throughput
        The steps, their wall time and the episodes that ended.
    """
    make = functools.partial(gymnasium.make, MODULE_PREFIX + env_id, overrides=list(overrides))
    kind = gymnasium.vector.AsyncVectorEnv if vector == "async" else gymnasium.vector.SyncVectorEnv
    envs = kind([make] * count)
    try:
        envs.action_space.seed(seed)
        envs.reset(seed=seed)
        actions = [envs.action_space.sample() for _ in range(steps)]
        ended = 0
        started = time.perf_counter()
        for action in actions:
            _, _, terminated, truncated, _ = envs.step(action)
            ended += int(np.count_nonzero(terminated | truncated))
        seconds = time.perf_counter() - started
    finally:
        envs.close()
    return Throughput(env_id, vector, count, steps, seconds, ended)


def step_cost(
    env_id: str,
    periods: int,
    repeats: int,
    seed: int = 0,
    registry: PluginRegistry | None = None,
) -> StepCost:
    """Time an environment's step against a run's tick of the same scenario, alternately.

    Parameters
    ----------
    env_id : str
        A registered id.
    periods : int
        Control periods each side flies per repeat.
    repeats : int
        Measurements per side.
    seed : int
        The first episode's and run's seed (each further one takes the next), and the
        action space's.
    registry : PluginRegistry, optional
        The plugins the run chooses from; the installed ones if None.

    Returns
    -------
    StepCost
        Seconds per control period of every repeat, both ways.
    """
    env = gymnasium.make(env_id)
    scenario = packaged_scenario_path(ENVIRONMENTS[env_id].default_scenario)
    try:
        env_times, run_times = [], []
        for _ in range(repeats):
            env_times.append(_env_period(env, periods, seed))
            run_times.append(_run_period(scenario, periods, seed, registry))
    finally:
        env.close()
    return StepCost(env_id, periods, env_times, run_times)


def _env_period(env: gymnasium.Env[Any, Any], periods: int, seed: int) -> float:
    """Wall time per step, s, of ``periods`` steps with random actions (resets not counted)."""
    env.action_space.seed(seed)
    env.reset(seed=seed)
    actions = [env.action_space.sample() for _ in range(periods)]
    elapsed = 0.0
    for action in actions:
        started = time.perf_counter()
        _, _, terminated, truncated, _ = env.step(action)
        elapsed += time.perf_counter() - started
        if terminated or truncated:
            env.reset()
    return elapsed / periods


def _run_period(scenario: Path, periods: int, seed: int, registry: PluginRegistry | None) -> float:
    """Wall time per tick, s, of ``periods`` ticks of runs flown by their controller
    without a path planner (opening and closing runs not counted)."""
    elapsed, flown = 0.0, 0
    while flown < periods:
        runner = open_run(scenario, ["path_planner=null"], seed=seed, registry=registry)
        seed += 1
        started = time.perf_counter()
        while flown < periods and not runner.ended:
            runner.advance()
            flown += 1
        elapsed += time.perf_counter() - started
        runner.close()
    return elapsed / periods


def markdown_tables(result: GymBenchResult) -> str:
    """The throughput and the step costs as two Markdown tables, with the target's verdict."""
    lines = [
        "| environment | vector | envs | env steps | episodes ended | wall [s] | env steps/s |",
        "|---|---|---:|---:|---:|---:|---:|",
    ]
    lines += [
        f"| {row.env_id} | {row.vector} | {row.envs} | {row.env_steps} "
        f"| {row.episodes_ended} | {row.seconds:.3f} "
        f"| {row.steps_per_second:.0f} |"
        for row in result.throughput
    ]
    lines += [
        "",
        f"| environment | env step (median) | run tick (median) | ratio | ≤ {RATIO_TARGET:g} × |",
        "|---|---:|---:|---:|---|",
    ]
    lines += [
        f"| {cost.env_id} | {1e3 * cost.env_step:.3f} ms | {1e3 * cost.run_tick:.3f} ms "
        f"| {cost.ratio:.2f} × | {'met' if cost.met else 'not met'} |"
        for cost in result.costs
    ]
    return "\n".join(lines) + "\n"


def verdict(result: GymBenchResult) -> str:
    """One line per environment: its ratio and whether the target is met."""
    return "\n".join(
        f"{cost.env_id}: an environment step costs {cost.ratio:.2f} run ticks "
        f"(target ≤ {RATIO_TARGET:g}): " + ("met" if cost.met else "NOT MET")
        for cost in result.costs
    )


def plot(result: GymBenchResult, path: Path) -> None:
    """Bar chart of environment steps per second: a panel per environment, a group of
    bars per vector kind, a bar per number of copies."""
    plt = pyplot()
    env_ids = list(dict.fromkeys(row.env_id for row in result.throughput))
    vectors = list(dict.fromkeys(row.vector for row in result.throughput))
    counts = sorted({row.envs for row in result.throughput})
    width = 0.8 / len(counts)
    figure, axes = plt.subplots(1, len(env_ids), figsize=(4.2 * len(env_ids), 3.8), squeeze=False)
    for axis, env_id in zip(axes[0], env_ids, strict=True):
        rate = {
            (r.vector, r.envs): r.steps_per_second for r in result.throughput if r.env_id == env_id
        }
        for k, count in enumerate(counts):
            x = np.arange(len(vectors)) + (k - (len(counts) - 1) / 2) * width
            heights = [rate.get((vector, count), math.nan) for vector in vectors]
            bars = axis.bar(x, heights, width, label=f"{count} env{'s' * (count > 1)}")
            axis.bar_label(bars, fmt="%.0f", fontsize=7)
        axis.set_ylim(0, 1.2 * max(rate.values()))  # room for the legend above the bars
        axis.set_xticks(np.arange(len(vectors)), [f"{v} vector" for v in vectors])
        axis.set_title(env_id, fontsize=10)
        axis.set_ylabel("environment steps per second")
    axes[0][0].legend(fontsize=8, ncol=len(counts), loc="upper center")
    save(figure, path)
