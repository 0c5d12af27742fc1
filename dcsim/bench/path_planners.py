"""``dcsim bench path-planners``: path planners side by side on the same problems.

Every registered path planner (or those named), with its default parameters, plans each
problem of the set (:mod:`dcsim.bench.path_problems`) N times. Run ``i`` gets the
generator the transfer mission would give its planner under world seed ``i``
(``component_rng(i, "path_planner")``), so ``--fly`` flies the same plan. Each plan runs
in a process forked for it: a planner that overruns its budget by more than the
conformance suite allows (20 % and 0.2 s) is a timeout, and is killed a second later; a
crash is an error; and a library with process-wide state (OMPL's random seed) starts
afresh every run. Every planner gets the same contract: the problem's safety margin (the
scenario's ``mission.safety_distance``) and a deadline ``time_budget`` after the instant
the bench starts its clock (``PathProblem.deadline``, ``time.monotonic()`` seconds).

Per run: planning time; the status (``solved`` — a trajectory, ``no path``, ``error``,
``timeout``); whether the trajectory ends inside the goal region within its tolerances
(exact) or not (approximate); its length, duration and delta-v as the planner reports
them; its clearance from the independent swept check
(:func:`dcsim.yardsticks.clearance.path_clearance`, true shapes, a tenth of the robot
radius); the planner's statistics; and the peak of
Python memory allocated during a plan call (tracemalloc: numpy arrays included, a C++
library's own allocations not). The memory is measured on a second call, of a fresh
instance with the same generator, after the timed one: tracemalloc's bookkeeping slows a
call down severalfold. It is the same plan for a planner that depends only on its
generator (OMPL's process-wide generator moves on). With ``--fly``, every run that gave a
trajectory is flown through the transfer mission (world seed ``i``, collisions counted
without stopping): flown delta-v, largest tracking error, collisions, arrival.
"""

from __future__ import annotations

import copy
import json
import math
import multiprocessing
import numbers
import time
import tracemalloc
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from multiprocessing.connection import Connection
from typing import Any

import numpy as np

from dcsim.bench.options import plugin_spec
from dcsim.bench.path_problems import BenchProblem
from dcsim.errors import DcsimError
from dcsim.messages import NoPath, PathProblem, Trajectory
from dcsim.registry.discovery import PluginRegistry, RegisteredPlugin
from dcsim.registry.interfaces import Plugin
from dcsim.run.loop import Runner
from dcsim.run.seeding import component_rng
from dcsim.run.setup import RunSetup
from dcsim.scenario import ScenarioDocument, resolve_plugins, validate
from dcsim.testing.contracts import TIME_SLACK
from dcsim.testing.kind_checks import START_TOLERANCES
from dcsim.yardsticks.clearance import path_clearance

STATUSES = ("solved", "no path", "error", "timeout")
"""A run's status: a trajectory in time, "no path", an exception or a crash, too late."""

KILL_MARGIN = 1.0
"""Seconds past the time allowance after which a planning process is killed."""

Progress = Callable[[str], None]


@dataclass(frozen=True)
class PlannerChoice:
    """A registered path planner with the parameters the bench gives it.

    Attributes
    ----------
    entry : RegisteredPlugin
        The planner.
    params : mapping
        Its parameters (the rest at their defaults); empty for all defaults.
    """

    entry: RegisteredPlugin
    params: Mapping[str, Any] = field(default_factory=dict)

    @property
    def cls(self) -> type[Plugin]:
        """The plugin class."""
        return self.entry.cls

    @property
    def origin(self) -> Any:
        """Where the plugin came from."""
        return self.entry.origin

    @property
    def plugin(self) -> str:
        """The plugin's registered name."""
        return self.entry.name

    @property
    def name(self) -> str:
        """The label of its runs: the plugin's name, then ``:key=value`` per parameter."""
        return self.plugin + "".join(f":{k}={v}" for k, v in self.params.items())

    def settings(self) -> dict[str, Any]:
        """Every parameter's value, defaults included (plain data)."""
        return self.cls.Params.parse(self.plugin, dict(self.params) or None).model_dump(mode="json")


def planner_choice(entry: RegisteredPlugin | PlannerChoice) -> PlannerChoice:
    """``entry`` as a :class:`PlannerChoice` (a registered plugin gets its defaults)."""
    return entry if isinstance(entry, PlannerChoice) else PlannerChoice(entry)


@dataclass(frozen=True)
class Flight:
    """One planned run flown through the transfer mission.

    Attributes
    ----------
    reached : bool
        Whether the robot arrived in the goal region.
    delta_v : float
        Delta-v flown, m/s.
    max_tracking_error : float
        Largest distance from the reference, m.
    collisions : int
        Contacts with obstacles (the flight does not stop at the first).
    """

    reached: bool
    delta_v: float
    max_tracking_error: float
    collisions: int


@dataclass(frozen=True)
class PlanRun:
    """One planner's answer to one problem under one seed.

    Attributes
    ----------
    planner, problem : str
        Names.
    seed : int
        World seed of the run (the planner's generator is that seed's).
    status : str
        One of :data:`STATUSES`.
    reason : str
        The "no path" reason, the error or the overrun; empty when solved.
    time : float
        Wall time of the plan call, s (NaN when the planner never answered).
    peak_memory : float
        Peak Python memory allocated during the call (tracemalloc), bytes.
    exact : bool
        The trajectory starts at the start state (within the conformance suite's
        tolerances of position and time) and ends inside the goal region, within every
        tolerance.
    approximate : bool
        A trajectory that does not.
    length, duration, delta_v : float
        The trajectory's own figures, m, s, m/s (NaN without one).
    clearance : float
        Least surface gap to any obstacle from the swept check, m (NaN without one).
    collides : bool or None
        Whether the swept check finds an overlap (None without a trajectory).
    statistics : mapping of str to float
        The planner's figures (``Trajectory.statistics``).
    flight : Flight or None
        The flown run, with ``--fly`` and a trajectory.
    """

    planner: str
    problem: str
    seed: int
    status: str
    reason: str = ""
    time: float = math.nan
    peak_memory: float = math.nan
    exact: bool = False
    approximate: bool = False
    length: float = math.nan
    duration: float = math.nan
    delta_v: float = math.nan
    clearance: float = math.nan
    collides: bool | None = None
    statistics: Mapping[str, float] = field(default_factory=dict)
    flight: Flight | None = None

    @property
    def success(self) -> bool:
        """An exact trajectory that the swept check finds clear of every obstacle."""
        return self.exact and self.collides is False


@dataclass(frozen=True)
class ProblemResult:
    """Every run on one problem.

    Attributes
    ----------
    problem : BenchProblem
        The problem.
    runs : list of PlanRun
        Planner by planner, seed by seed.
    total_time : float
        Wall time spent on the problem, flights included, s.
    started : str
        Local date and time the problem's runs started.
    """

    problem: BenchProblem
    runs: list[PlanRun]
    total_time: float
    started: str


def _plan_in_child(
    plugin: type,
    seed: int,
    problem: PathProblem,
    connection: Connection,
    params: Mapping[str, Any] | None = None,
    memory: bool = True,
) -> None:
    """Time one plan call and send its answer; then trace a second call's memory and send
    it (NaN without ``memory``).

    The second call (a fresh instance with the same generator) runs under tracemalloc,
    whose bookkeeping would otherwise slow the timed call down severalfold.
    """
    began = time.monotonic()
    try:
        planner = plugin(params, component_rng(seed, "path_planner"))
        began = time.monotonic()
        answer: Any = planner.plan(due_from(problem, began))
    except Exception as error:  # the planner's own failure is a result, not the bench's
        answer = f"{type(error).__name__}: {error}"
    elapsed = time.monotonic() - began
    try:
        connection.send((answer, elapsed))
    except Exception as error:  # an answer that cannot be pickled
        connection.send((f"its answer cannot be sent back: {error}", elapsed))
    connection.send(_traced_peak(plugin, seed, problem, params) if memory else math.nan)


def due_from(problem: PathProblem, began: float) -> PathProblem:
    """``problem`` due ``time_budget`` after ``began`` (``time.monotonic()`` seconds)."""
    return replace(problem, deadline=began + problem.time_budget)


def _traced_peak(
    plugin: type, seed: int, problem: PathProblem, params: Mapping[str, Any] | None
) -> float:
    """Peak Python memory allocated during a plan call of a fresh instance, bytes."""
    planner = plugin(params, component_rng(seed, "path_planner"))
    tracemalloc.start()
    try:
        planner.plan(due_from(problem, time.monotonic()))
        return float(tracemalloc.get_traced_memory()[1])
    except Exception:  # already reported by the timed call
        return math.nan
    finally:
        tracemalloc.stop()


def plan_in_process(
    plugin: type,
    seed: int,
    problem: PathProblem,
    params: Mapping[str, Any] | None = None,
    memory: bool = True,
) -> tuple[Any, float, float]:
    """One plan call (with ``params``, None for the defaults) in a forked process:
    ``(answer, seconds, peak bytes)``; the peak is NaN without ``memory``.

    The answer is a :class:`Trajectory`, a :class:`NoPath`, an error message (str), or
    None when the process had to be killed: then the seconds are the time waited for it
    (a lower bound of the planning time). The peak memory is NaN when the traced call
    did not finish in time.
    """
    context = multiprocessing.get_context("fork")
    receiver, sender = context.Pipe(duplex=False)
    child = context.Process(
        target=_plan_in_child, args=(plugin, seed, problem, sender, params, memory)
    )
    child.daemon = True
    child.start()
    sender.close()
    waited = time_allowance(problem) + KILL_MARGIN
    try:
        if not receiver.poll(waited):
            return None, waited, math.nan
        answer, seconds = receiver.recv()
    except EOFError:
        child.join()
        return f"the planning process died (exit code {child.exitcode})", math.nan, math.nan
    else:
        return answer, seconds, _peak(receiver, waited)
    finally:
        child.kill()
        child.join()
        receiver.close()


def _peak(receiver: Connection, timeout: float) -> float:
    """The traced call's peak memory (bytes), or NaN if it does not come within ``timeout`` s."""
    try:
        return receiver.recv() if receiver.poll(timeout) else math.nan
    except EOFError:
        return math.nan


def time_allowance(problem: PathProblem) -> float:
    """How long a plan may take: the budget plus 20 % and the conformance suite's slack, s."""
    return 1.2 * problem.time_budget + TIME_SLACK


def _statistics(trajectory: Trajectory) -> dict[str, float]:
    return {
        str(name): float(value)
        for name, value in trajectory.statistics.items()
        if isinstance(value, numbers.Real) and not isinstance(value, bool)
    }


def evaluate(
    planner: str, bench: BenchProblem, seed: int, answer: Any, seconds: float, peak: float
) -> PlanRun:
    """What a planner's answer is worth: status, arrival, figures and swept clearance."""
    problem = bench.problem
    head = PlanRun(planner, bench.name, seed, "error", time=seconds, peak_memory=peak)
    if answer is None:
        return replace(head, status="timeout", reason=f"killed after {seconds:.1f} s")
    if seconds > time_allowance(problem):
        reason = f"answered after {seconds:.3f} s with a budget of {problem.time_budget:g} s"
        return replace(head, status="timeout", reason=reason)
    if isinstance(answer, str):
        return replace(head, reason=answer)
    if isinstance(answer, NoPath):
        return replace(head, status="no path", reason=answer.reason)
    if not isinstance(answer, Trajectory):
        return replace(head, reason=f"returned {type(answer).__name__}")
    gap = float(np.linalg.norm(answer.positions[0] - problem.start.position))
    lag = abs(float(answer.times[0] - problem.start.time))
    starts = gap <= START_TOLERANCES[0] and lag <= START_TOLERANCES[1]
    exact = starts and problem.goal.contains(answer.end_state(problem.goal))
    closest = path_clearance(answer, problem)
    return replace(
        head,
        reason="" if starts else f"starts {gap:.3g} m and {lag:.3g} s from the start state",
        status="solved",
        exact=exact,
        approximate=not exact,
        length=answer.length,
        duration=answer.duration,
        delta_v=answer.delta_v,
        clearance=closest.distance,
        collides=closest.collides,
        statistics=_statistics(answer),
    )


def fly(
    document: ScenarioDocument,
    planner: str,
    seed: int,
    registry: PluginRegistry,
    params: Mapping[str, Any] | None = None,
) -> Flight:
    """Fly a problem's transfer scenario with ``planner`` (``params``, None for the
    defaults) under world seed ``seed``.

    Collisions do not stop the flight, so that every one is counted.
    """
    flown = copy.deepcopy(document)
    for assignment in (
        f"path_planner.plugin={planner}",
        f"path_planner.params={json.dumps(dict(params or {}))}",
        f"world.seed={seed}",
        "stop.on_collision=false",
    ):
        flown.apply_override(assignment)
    scenario = resolve_plugins(flown, validate(flown), registry)
    summary = Runner(RunSetup.from_scenario(scenario, registry)).run()
    return Flight(
        bool(summary["reached"]),
        float(summary["delta_v_mps"]),
        float(summary["max_tracking_error_m"]),
        int(summary["collisions"]),
    )


def bench_problem(
    bench: BenchProblem,
    planners: Sequence[RegisteredPlugin | PlannerChoice],
    runs: int,
    flights: bool,
    registry: PluginRegistry,
    progress: Progress = print,
    memory: bool = True,
) -> ProblemResult:
    """Every planner on one problem, ``runs`` seeds each (0 to runs − 1); ``memory``
    traces a second call of each run for its peak memory."""
    started = time.strftime("%Y-%m-%d %H:%M:%S")
    began = time.perf_counter()
    results = []
    for entry in map(planner_choice, planners):
        params = dict(entry.params) or None
        for seed in range(runs):
            answer, seconds, peak = plan_in_process(entry.cls, seed, bench.problem, params, memory)
            run = evaluate(entry.name, bench, seed, answer, seconds, peak)
            if flights and run.status == "solved":
                flight = fly(bench.document, entry.plugin, seed, registry, params)
                run = replace(run, flight=flight)
            results.append(run)
            progress(
                f"{bench.name} {entry.name} seed {seed}: {run.status} "
                f"in {1e3 * run.time:.1f} ms {run.reason}".rstrip()
            )
    return ProblemResult(bench, results, time.perf_counter() - began, started)


def select_planners(registry: PluginRegistry, names: Sequence[str] | None) -> list[PlannerChoice]:
    """The named path planners, or every registered one (in name order) when None.

    A name may carry parameters, each as ``:key=value`` (the value read as YAML):
    ``ompl-control:controls=discrete:planner=est``.

    Raises
    ------
    DcsimError
        If a name is unknown or ambiguous, a parameter is malformed or invalid, or no
        path planner is registered.
    """
    if names is None:
        chosen = [
            PlannerChoice(entry)
            for entry in sorted(registry.plugins("path_planner"), key=lambda entry: entry.name)
        ]
    else:
        chosen = [planner_spec(registry, name) for name in names]
    if not chosen:
        raise DcsimError("no path planner is installed")
    return chosen


def planner_spec(registry: PluginRegistry, spec: str) -> PlannerChoice:
    """The planner and parameters of ``NAME[:key=value...]``."""
    name, params = plugin_spec(spec)
    choice = PlannerChoice(registry.get("path_planner", name), params)
    choice.settings()  # an invalid parameter is an error now, not in every run
    return choice


def bench_path_planners(
    problems: Sequence[BenchProblem],
    planners: Sequence[RegisteredPlugin | PlannerChoice],
    runs: int,
    flights: bool,
    registry: PluginRegistry,
    progress: Progress = print,
    memory: bool = True,
) -> list[ProblemResult]:
    """Every planner on every problem, ``runs`` seeds each, problem by problem."""
    return [bench_problem(p, planners, runs, flights, registry, progress, memory) for p in problems]
