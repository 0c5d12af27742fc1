"""``dcsim bench task-planners``: the thesis's time-strategy comparison and gaps to the optimum.

Two studies on random instances (a collector at rest at the origin, targets in a cube of
half-width 50 m, a drop point within 20 m, capacity 3, speed limit 0.5 m/s,
acceleration 0.02 m/s²):

1. **Time strategies** (the thesis's figures 3.1–3.10): the ``ga`` planner with each
   time strategy on moving targets (random velocities, σ = 0.02 m/s per axis), n = 5, 10
   and 15: mean plan cost, generations, planning time, plan duration, and dispersion —
   the number of distinct plans (order and drop visits) over repeated runs with
   different seeds on one instance. The thesis's algorithm alone (no local search) is
   compared, with the planner's default configuration beside it.
2. **Gap to the optimum**: the plan cost of ``ga`` (defaults) and of the ``nearest``
   baseline against the exact optimum — Held–Karp over subsets for stationary targets,
   the same dynamic programming on a time grid for moving ones
   (:mod:`dcsim.bench.optimal_plans`). The plan model of the optimum is the bench's
   own (:data:`PLAN_MODEL`: the thesis's time weight, least leg time, speed fraction and
   longest leg); both planners are given it as their parameters, as a scenario file
   would, and every plan is costed by :func:`dcsim.api.plan_cost` with its time weight.
3. **Tracked targets**: the same two planners, configured the same way, plan one moving
   instance twice at the end of an observation (:data:`OBSERVATION`, 10 s): from the
   targets' true motions (the oracle) and from the tracks the ``kalman`` tracker makes
   of the ``object-sensor``'s detections at the realistic profile's numbers, the robot
   at rest at the origin and known exactly. Every plan is then flown against the truth:
   its order, pickup times and drop visits kept, each pickup where its target truly is
   then (:func:`flown_against_truth`), costed by :func:`dcsim.api.plan_cost`.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol, runtime_checkable

import numpy as np

from dcsim.api import (
    DropPoint,
    FrameDynamics,
    KnownObject,
    LinearMotion,
    ObjectKind,
    ObjectTrack,
    Plan,
    SensedTruth,
    SensorSetup,
    StateEstimate,
    StaticMotion,
    TaskRequest,
    plan_cost,
    plan_duration,
)
from dcsim.bench.figures import pyplot, save
from dcsim.bench.optimal_plans import LegRules, optimal_grid_plan, optimal_static_plan
from dcsim.registry.discovery import PluginRegistry
from dcsim.registry.interfaces import TaskPlanner, Tracker
from dcsim.scenario.sensors import REALISTIC
from dcsim.world.sensors.object_sensor import ObjectSensor

AREA = 50.0
"""Half-width of the cube the targets start in, m."""
DROP_AREA = 20.0
"""Half-width of the cube the drop point lies in, m."""
TARGET_SPEED_SIGMA = 0.02
"""Standard deviation of a moving target's velocity per axis, m/s."""
CAPACITY = 3
MAX_SPEED = 0.5
MAX_ACCELERATION = 0.02


class _SearchCount(Protocol):
    """The part of the ga planner's ``statistics`` the strategy bench reads."""

    @property
    def iterations(self) -> int:
        """Generations run by the last plan."""
        ...


@runtime_checkable
class _SearchingPlanner(Protocol):
    """A task planner that reports its last search in ``statistics`` (the ga planner)."""

    @property
    def statistics(self) -> _SearchCount:
        """How the last plan's search went."""
        ...


PLAN_MODEL = LegRules(time_weight=0.005, min_time_step=1.0, speed_fraction=0.8, max_leg_time=600.0)
"""The plan model the optimum is exact for, and the planners are configured with."""

OBSERVATION = 10.0
"""How long the object sensor watches the targets before the tracked plan, s."""
OBSERVATION_PERIOD = 0.1
"""Time between two of the tracker's updates while it watches, s (a control period)."""

STRATEGY_VARIANTS: tuple[tuple[str, dict], ...] = (
    ("brute-force", {"time_strategy": "brute-force", "local_search": False}),
    ("minimum-distance", {"time_strategy": "minimum-distance", "local_search": False}),
    ("mixed", {"time_strategy": "mixed", "local_search": False}),
    ("mixed + local search (default)", {}),
)
"""(label, ``ga`` parameters) of the time-strategy comparison."""

Progress = Callable[[str], None]


def random_request(
    rng: np.random.Generator, n: int, moving: bool, time_budget: float = 10.0
) -> TaskRequest:
    """A random benchmark instance (see the module documentation)."""
    tracks = []
    for i in range(n):
        position = rng.uniform(-AREA, AREA, 3)
        velocity = rng.normal(0.0, TARGET_SPEED_SIGMA, 3) if moving else np.zeros(3)
        tracks.append(
            ObjectTrack(
                i + 1,
                ObjectKind.TARGET,
                0.0,
                position,
                velocity,
                mass=5.0,
                radius=0.3,
                motion=LinearMotion(position, velocity),
            )
        )
    return TaskRequest(
        time=0.0,
        robot=StateEstimate(time=0.0, position=np.zeros(3), converged=True),
        targets=tuple(tracks),
        drop_point=DropPoint(StaticMotion(rng.uniform(-DROP_AREA, DROP_AREA, 3)), tolerance=1.0),
        capacity=CAPACITY,
        max_speed=MAX_SPEED,
        max_acceleration=MAX_ACCELERATION,
        time_budget=time_budget,
    )


def _plan(
    registry: PluginRegistry, name: str, params: dict, seed: int, request: TaskRequest
) -> tuple[Plan, float, TaskPlanner]:
    """Plan with a fresh planner; return the plan, the wall time and the planner."""
    planner = registry.create("task_planner", name, params, np.random.default_rng(seed))
    assert isinstance(planner, TaskPlanner)  # the registry files plugins by their class's kind
    start = time.perf_counter()
    plan = planner.plan(request)
    return plan, time.perf_counter() - start, planner


def _signature(plan: Plan) -> tuple:
    return tuple(t.target_id for t in plan.tasks), tuple(v.after_task for v in plan.drop_visits)


# --------------------------------------------------------------------- time strategies


@dataclass
class StrategyResult:
    """One time strategy on one problem size."""

    label: str
    n: int
    costs: list[float] = field(default_factory=list)
    iterations: list[int] = field(default_factory=list)
    seconds: list[float] = field(default_factory=list)
    durations: list[float] = field(default_factory=list)
    distinct: list[int] = field(default_factory=list)


def compare_strategies(
    sizes: Sequence[int],
    instances: int,
    repeats: int,
    dispersion_instances: int,
    progress: Progress = print,
) -> list[StrategyResult]:
    """Run every variant of :data:`STRATEGY_VARIANTS` on the same moving instances."""
    registry = PluginRegistry.discover()
    results = []
    for n in sizes:
        requests = [
            random_request(np.random.default_rng(seed), n, True) for seed in range(instances)
        ]
        for label, params in STRATEGY_VARIANTS:
            result = StrategyResult(label, n)
            for seed, request in enumerate(requests):
                plan, seconds, planner = _plan(registry, "ga", params, seed, request)
                assert isinstance(planner, _SearchingPlanner)  # ga reports its search
                result.costs.append(plan.cost)  # ga's cost is plan_cost with its time weight
                result.iterations.append(planner.statistics.iterations)
                result.seconds.append(seconds)
                result.durations.append(plan_duration(request, plan))
            for request in requests[:dispersion_instances]:
                plans = {
                    _signature(_plan(registry, "ga", params, 1000 + r, request)[0])
                    for r in range(repeats)
                }
                result.distinct.append(len(plans))
            results.append(result)
            progress(
                f"n={n} {label}: mean cost {np.mean(result.costs):.3f} m/s, "
                f"mean time {np.mean(result.seconds):.3f} s"
            )
    return results


def strategy_table(results: list[StrategyResult], repeats: int) -> str:
    """Markdown table of the time-strategy comparison."""
    lines = [
        "| n | strategy | mean cost [m/s] | mean generations | mean planning time [s] "
        f"| mean plan duration [s] | distinct plans in {repeats} runs (mean) |",
        "|---:|---|---:|---:|---:|---:|---:|",
    ]
    for r in results:
        lines.append(
            f"| {r.n} | {r.label} | {np.mean(r.costs):.3f} | {np.mean(r.iterations):.0f} | "
            f"{np.mean(r.seconds):.3f} | {np.mean(r.durations):.0f} | {np.mean(r.distinct):.1f} |"
        )
    return "\n".join(lines)


def plot_strategies(results: list[StrategyResult], path: Path) -> None:
    """Bar charts of the five compared quantities against n, one bar per strategy."""
    plt = pyplot()

    labels = list(dict.fromkeys(r.label for r in results))
    sizes = sorted({r.n for r in results})
    panels = [
        ("mean cost [m/s]", lambda r: np.mean(r.costs)),
        ("mean generations", lambda r: np.mean(r.iterations)),
        ("mean planning time [s]", lambda r: np.mean(r.seconds)),
        ("mean plan duration [s]", lambda r: np.mean(r.durations)),
        ("distinct plans (dispersion)", lambda r: np.mean(r.distinct)),
    ]
    figure, axes = plt.subplots(1, len(panels), figsize=(20, 4.2))
    width = 0.8 / len(labels)
    for axis, (title, value) in zip(axes, panels, strict=True):
        for i, label in enumerate(labels):
            heights = [
                value(next(r for r in results if r.label == label and r.n == n)) for n in sizes
            ]
            axis.bar(np.arange(len(sizes)) + i * width, heights, width, label=label)
        axis.set_xticks(np.arange(len(sizes)) + 0.4 - width / 2, [f"n = {n}" for n in sizes])
        axis.set_title(title)
        axis.grid(alpha=0.3, axis="y")
    axes[0].legend(fontsize=8)
    figure.suptitle("ga time strategies on moving targets (thesis figures 3.1–3.10)")
    save(figure, path)


# --------------------------------------------------------------------- gaps


@dataclass
class GapResult:
    """One planner's relative gaps to the optimum on one problem size.

    ``incomplete`` counts plans that left targets out (no gap recorded); ``unsolved``
    counts instances the grid optimum could not plan within its horizon (skipped).
    """

    label: str
    moving: bool
    n: int
    gaps: list[float] = field(default_factory=list)
    seconds: list[float] = field(default_factory=list)
    incomplete: int = 0
    unsolved: int = 0


def optimality_gaps(
    static_sizes: Sequence[int],
    moving_sizes: Sequence[int],
    instances: int,
    moving_instances: int,
    grid_step: float,
    grid_horizon: float,
    progress: Progress = print,
) -> list[GapResult]:
    """Gaps of ``ga`` and ``nearest`` to the exact (or grid-exact) optimum."""
    registry = PluginRegistry.discover()
    rules = PLAN_MODEL
    planners = _model_planners(rules)
    cases = [(False, n, instances) for n in static_sizes] + [
        (True, n, moving_instances) for n in moving_sizes
    ]
    results: list[GapResult] = []
    for moving, n, count in cases:
        rows = {label: GapResult(label, moving, n) for label, _, _ in planners}
        for seed in range(count):
            request = random_request(np.random.default_rng(10_000 + seed), n, moving, 1.0)
            try:
                if moving:
                    best = optimal_grid_plan(request, rules, grid_step, grid_horizon)
                else:
                    best = optimal_static_plan(request, rules)
            except ValueError:  # no plan visits every target within the grid's horizon
                for row in rows.values():
                    row.unsolved += 1
                continue
            for label, name, params in planners:
                plan, seconds, _ = _plan(registry, name, params, seed, request)
                row = rows[label]
                row.seconds.append(seconds)
                if len(plan.tasks) < n:
                    row.incomplete += 1
                    continue
                row.gaps.append(plan_cost(request, plan, rules.time_weight) / best.cost - 1.0)
        results.extend(rows.values())
        ga_row = rows["ga"]
        progress(
            f"{'moving' if moving else 'stationary'} n={n}: ga median gap "
            f"{_percent(ga_row.gaps, np.median)} %, max time {max(ga_row.seconds, default=0):.2f} s"
        )
    return results


def _model_planners(rules: LegRules) -> list[tuple[str, str, dict]]:
    """(label, plugin, parameters) of ``ga`` and ``nearest`` given the plan model ``rules``."""
    return [
        (
            "ga",
            "ga",
            {
                "time_weight": rules.time_weight,
                "MIN_TIME_STEP": rules.min_time_step,
                "speed_fraction": rules.speed_fraction,
                "max_leg_time": rules.max_leg_time,
            },
        ),
        (
            "nearest",
            "nearest",
            {"min_time_step": rules.min_time_step, "speed_fraction": rules.speed_fraction},
        ),
    ]


def _percent(gaps: list[float], statistic: Callable[[np.ndarray], float]) -> str:
    """``statistic`` of relative gaps as a percentage, or "–" if there is none."""
    return f"{100 * statistic(np.array(gaps)):.2f}" if gaps else "–"


def gap_table(results: list[GapResult]) -> str:
    """Markdown table of the gaps to the optimum."""
    lines = [
        "| targets | n | planner | instances | gap median [%] | gap p95 [%] | gap max [%] "
        "| time median [s] | time max [s] |",
        "|---|---:|---|---:|---:|---:|---:|---:|---:|",
    ]
    for r in results:
        kind = "moving (grid optimum)" if r.moving else "stationary"
        done = f"{len(r.gaps)}"
        if r.incomplete:
            done += f" (+{r.incomplete} plans leaving targets out)"
        if r.unsolved:
            done += f" (+{r.unsolved} without an optimum in the horizon)"
        lines.append(
            f"| {kind} | {r.n} | {r.label} | {done} | {_percent(r.gaps, np.median)} | "
            f"{_percent(r.gaps, lambda g: np.percentile(g, 95))} | {_percent(r.gaps, np.max)} | "
            f"{_seconds(r.seconds, np.median)} | {_seconds(r.seconds, np.max)} |"
        )
    return "\n".join(lines)


def _seconds(seconds: list[float], statistic: Callable[[np.ndarray], float]) -> str:
    """``statistic`` of planning times, s, or "–" if no plan was made (no instance, or
    none the optimum could plan)."""
    return f"{statistic(np.array(seconds)):.3f}" if seconds else "–"


def plot_gaps(results: list[GapResult], path: Path) -> None:
    """Box plots of the gap distributions, per problem and planner."""
    plt = pyplot()

    figure, axis = plt.subplots(figsize=(11, 4.5))
    data = [100 * np.array(r.gaps) for r in results]
    names = [f"{'mov' if r.moving else 'stat'} {r.n}\n{r.label}" for r in results]
    axis.boxplot(data, whis=(5, 95), showfliers=True)
    axis.set_xticks(np.arange(1, len(names) + 1), names, fontsize=8)
    axis.set_yscale("symlog", linthresh=0.1)
    axis.set_ylabel("plan cost above the optimum [%]")
    axis.set_title("Task planners against the exact optimum (whiskers: 5th–95th percentile)")
    axis.grid(alpha=0.3, axis="y")
    save(figure, path)


# --------------------------------------------------------------------- tracked targets


def request_at(request: TaskRequest, time: float) -> TaskRequest:
    """``request`` asked at ``time`` (s) instead: each target's track moved there along its
    motion, the robot in the same state."""
    targets = []
    for track in request.targets:
        position, velocity = track.predict(time)
        targets.append(dataclasses.replace(track, time=time, position=position, velocity=velocity))
    robot = dataclasses.replace(request.robot, time=time)
    return dataclasses.replace(request, time=time, robot=robot, targets=tuple(targets))


def tracked_request(
    truth: TaskRequest, registry: PluginRegistry, seed: int, observation: float = OBSERVATION
) -> TaskRequest:
    """``truth`` with its targets as the ``kalman`` tracker knows them after watching.

    From time 0 to ``truth.time`` the ``object-sensor`` (the realistic profile's model
    and numbers, all round, unlimited reach) reads the targets on their true motions
    from the robot, which stays at rest where ``truth.robot`` is and is known exactly,
    and the tracker folds in its detections every :data:`OBSERVATION_PERIOD`.

    Parameters
    ----------
    truth : TaskRequest
        The oracle request, asked at ``observation`` s (:func:`request_at`).
    registry : PluginRegistry
        Where the tracker comes from (dcsim does not import plugins).
    seed : int
        Seeds the sensor's and the tracker's generators.
    observation : float
        Length of the watch, s; ``truth.time`` must equal it.

    Returns
    -------
    TaskRequest
        ``truth`` whose targets are the tracker's tracks at ``truth.time`` (a target
        never detected is missing).
    """
    assert np.isclose(truth.time, observation), "the oracle request is asked at the watch's end"
    choice = REALISTIC["objects"]
    assert choice is not None  # the realistic profile gives the object sensor its model
    sensor = ObjectSensor(choice.params, np.random.default_rng([seed, 1]))
    catalogue = tuple(KnownObject(t.id, t.kind, t.mass, t.shape) for t in truth.targets)
    sensor.reset(SensorSetup(control_period=OBSERVATION_PERIOD, objects=catalogue))
    tracker = registry.create("tracker", "kalman", {}, np.random.default_rng([seed, 2]))
    assert isinstance(tracker, Tracker)  # the registry files plugins by their class's kind
    tracker.reset(FrameDynamics(), 0.0)
    robot = truth.robot
    ticks = round(observation / OBSERVATION_PERIOD)
    tracks: tuple[ObjectTrack, ...] = ()
    for tick in range(ticks + 1):
        now = tick * OBSERVATION_PERIOD
        states = [t.predict(now) for t in truth.targets]
        reading = SensedTruth(
            now,
            robot.position,
            robot.velocity,
            np.array([0.0, 0.0, 0.0, 1.0]),
            np.zeros(3),
            np.array([p for p, _ in states]),
            np.array([v for _, v in states]),
            np.ones(len(states), dtype=bool),
        )
        known = StateEstimate(
            now, robot.position, velocity=robot.velocity, covariance=np.zeros((6, 6))
        )
        tracks = tracker.update(now, sensor.measure(reading), known)
    return dataclasses.replace(truth, targets=tracks)


def flown_against_truth(truth: TaskRequest, plan: Plan) -> Plan:
    """``plan`` flown in the true world: its order, pickup times and drop visits kept,
    each pickup at its target's true position and velocity at the pickup time."""
    targets = {t.id: t for t in truth.targets}
    tasks = []
    for task in plan.tasks:
        position, velocity = targets[task.target_id].predict(task.pickup_time)
        tasks.append(dataclasses.replace(task, pickup_point=position, pickup_velocity=velocity))
    return dataclasses.replace(plan, tasks=tuple(tasks))


@dataclass
class TrackedResult:
    """One planner on one problem size, planning from the truth and from tracks.

    Attributes
    ----------
    label : str
        The planner.
    n : int
        Targets per instance.
    oracle : list of float
        Cost of the plan made from the true motions (as planned and as flown), m/s, on
        the instances whose tracked plan is costed.
    planned, flown : list of float
        Cost of the plan made from the tracks, as planned and flown against the truth,
        m/s.
    misses : list of float
        Distance from each tracked plan's pickup point to where its target truly is at
        the pickup time, m.
    incomplete : int
        Tracked plans that left a target out (the instance is not costed).
    """

    label: str
    n: int
    oracle: list[float] = field(default_factory=list)
    planned: list[float] = field(default_factory=list)
    flown: list[float] = field(default_factory=list)
    misses: list[float] = field(default_factory=list)
    incomplete: int = 0


def tracked_targets(
    sizes: Sequence[int],
    instances: int,
    observation: float = OBSERVATION,
    progress: Progress = print,
) -> list[TrackedResult]:
    """``ga`` and ``nearest`` planning moving instances from the truth and from tracks."""
    registry = PluginRegistry.discover()
    rules = PLAN_MODEL
    results: list[TrackedResult] = []
    for n in sizes:
        rows = {label: TrackedResult(label, n) for label, _, _ in _model_planners(rules)}
        for seed in range(instances):
            start = random_request(np.random.default_rng(20_000 + seed), n, True, 1.0)
            truth = request_at(start, observation)
            tracked = tracked_request(truth, registry, seed, observation)
            for label, name, params in _model_planners(rules):
                row = rows[label]
                oracle = _plan(registry, name, params, seed, truth)[0]
                plan = _plan(registry, name, params, seed, tracked)[0]
                if len(plan.tasks) < n:
                    row.incomplete += 1
                    continue
                flown = flown_against_truth(truth, plan)
                row.oracle.append(plan_cost(truth, oracle, rules.time_weight))
                row.planned.append(plan_cost(tracked, plan, rules.time_weight))
                row.flown.append(plan_cost(truth, flown, rules.time_weight))
                row.misses.extend(
                    float(np.linalg.norm(a.pickup_point - b.pickup_point))
                    for a, b in zip(plan.tasks, flown.tasks, strict=True)
                )
        results.extend(rows.values())
        ga_row = rows["ga"]
        progress(
            f"tracked n={n}: ga median cost flown {np.median(ga_row.flown):.3f} m/s "
            f"(oracle {np.median(ga_row.oracle):.3f})"
        )
    return results


def tracked_table(results: list[TrackedResult]) -> str:
    """Markdown table of the plans from the truth against those from tracks."""
    lines = [
        "| n | planner | instances | oracle cost median [m/s] | tracked: as planned median "
        "[m/s] | tracked: flown median [m/s] | flown / oracle median (p95) "
        "| flown / as planned median (max) | pickup miss median / max [m] |",
        "|---:|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in results:
        done = f"{len(r.flown)}"
        if r.incomplete:
            done += f" (+{r.incomplete} tracked plans leaving targets out)"
        ratio = np.array(r.flown) / np.array(r.oracle)
        drift = np.array(r.flown) / np.array(r.planned)
        lines.append(
            f"| {r.n} | {r.label} | {done} | {np.median(r.oracle):.3f} | "
            f"{np.median(r.planned):.3f} | {np.median(r.flown):.3f} | "
            f"{np.median(ratio):.3f} ({np.percentile(ratio, 95):.3f}) | "
            f"{np.median(drift):.3f} ({np.max(drift):.3f}) | "
            f"{np.median(r.misses):.2f} / {np.max(r.misses):.2f} |"
        )
    return "\n".join(lines)
