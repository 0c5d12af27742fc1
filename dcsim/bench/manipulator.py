"""``dcsim bench manipulator``: the manipulator model's time per call against PyBullet's
and Pinocchio's.

On the source thesis's robot (:func:`dcsim.robots.dh.thesis_manipulator`, six joints),
at ``states`` random states from a fixed seed
(:func:`dcsim.bench.reference_models.random_state`), each implementation computes the
forward kinematics, the end effector's Jacobian, the mass matrix ``M``, the Coriolis
matrix ``C`` and the velocity-dependent force ``C q̇`` (PyBullet has no ``C``; dcsim
also gives ``M`` and ``C`` from one call, ``ManipulatorModel.dynamics``). A pass calls
one quantity once at every state; :mod:`timeit` times ``number`` passes of every
implementation and quantity in turn, ``repeats`` rounds over them all (so that a burst
of load on the machine hits them alike), and each one's best round gives its wall time
per call. PyBullet's and Pinocchio's
arguments are prepared in their own forms beforehand (lists, their velocity orders), so
theirs is the library call alone; dcsim's calls take the state as numpy arrays.

Before timing, PyBullet's and Pinocchio's ``M``, ``C q̇`` and Jacobian are mapped to
dcsim's order and compared with dcsim's at every state. Pinocchio (``pin``) is a test
extra: without it, its column is empty and the 10× target is not judged.

Optionally a scenario is run once with the runner (as ``dcsim run`` does, recording in
memory) for its real-time factor and its wall time per simulated second by phase of the
run loop.
"""

from __future__ import annotations

import timeit
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from dcsim.bench.reference_models import BulletModel, PinocchioModel, pin, random_state
from dcsim.bench.world import PHASES
from dcsim.registry.discovery import PluginRegistry
from dcsim.robots.dh import thesis_manipulator
from dcsim.robots.manipulator import ManipulatorModel
from dcsim.run.loop import Runner
from dcsim.run.setup import setup_run

OURS, BULLET, PINOCCHIO = "dcsim", "PyBullet", "Pinocchio"
IMPLEMENTATIONS = (OURS, BULLET, PINOCCHIO)

QUANTITIES = {
    "forward kinematics": "forward kinematics",
    "jacobian": "end-effector Jacobian",
    "mass matrix": "M",
    "coriolis matrix": "C",
    "bias": "C q̇",
    "mass and coriolis": "M and C from one call",
}
"""The timed quantities (the keys of each implementation's calls) and their table names."""

TARGET = 10.0
"""The target: dcsim's M + C within this factor of Pinocchio's (time per call)."""

Calls = dict[str, Callable[[], object]]


@dataclass(frozen=True)
class ManipulatorBenchResult:
    """Wall time per call of every implementation and quantity, and their agreement.

    Attributes
    ----------
    seconds : dict of str to dict of str to float
        Per implementation (``"dcsim"``, ``"PyBullet"``, ``"Pinocchio"``), the best wall
        time per call of each quantity it has (the keys of :data:`QUANTITIES`), s.
    agreement : dict of str to float
        Per ``"<implementation> <quantity>"``, the largest difference from dcsim's over
        the states, relative to dcsim's largest entry.
    states, repeats, number : int
        States, rounds and passes per round of the timing.
    """

    seconds: dict[str, dict[str, float]]
    agreement: dict[str, float]
    states: int
    repeats: int
    number: int

    def mass_and_coriolis(self, implementation: str) -> float | None:
        """``M`` and ``C`` by two calls, s (None when the implementation lacks one)."""
        times = self.seconds.get(implementation, {})
        if "mass matrix" not in times or "coriolis matrix" not in times:
            return None
        return times["mass matrix"] + times["coriolis matrix"]

    @property
    def target_ratio(self) -> float | None:
        """dcsim's ``M + C`` (two calls) over Pinocchio's; None without Pinocchio."""
        ours, theirs = self.mass_and_coriolis(OURS), self.mass_and_coriolis(PINOCCHIO)
        return None if ours is None or theirs is None else ours / theirs


@dataclass(frozen=True)
class ScenarioSpeed:
    """One run of a scenario.

    Attributes
    ----------
    name : str
        The scenario's name.
    sim_time, wall_time : float
        Simulated and wall time of the run, s.
    phases : dict of str to float
        Wall seconds per simulated second by phase of the run loop (``dcsim.bench.world``'s
        ``PHASES``).
    """

    name: str
    sim_time: float
    wall_time: float
    phases: dict[str, float]

    @property
    def real_time_factor(self) -> float:
        """Simulated seconds per wall second."""
        return self.sim_time / self.wall_time


def bench_manipulator(
    states: int = 64,
    repeats: int = 30,
    number: int = 10,
    seed: int = 0,
    progress: Callable[[str], None] | None = None,
) -> ManipulatorBenchResult:
    """Time dcsim's, PyBullet's and Pinocchio's (if installed) model of the thesis robot.

    Parameters
    ----------
    states : int
        Random states, drawn from ``seed``.
    repeats, number : int
        Timing rounds (the best counts) and passes over the states per round.
    seed : int
        Seed of the states.
    progress : callable, optional
        Called with a line of text per implementation timed.

    Returns
    -------
    ManipulatorBenchResult
    """
    say = progress or (lambda line: None)
    model = ManipulatorModel(thesis_manipulator())
    rng = np.random.default_rng(seed)
    sampled = [random_state(rng, model.n_joints) for _ in range(states)]
    references: dict[str, BulletModel | PinocchioModel] = {}
    seconds: dict[str, dict[str, float]] = {}
    agreement: dict[str, float] = {}
    with BulletModel(model) as bullet:
        references[BULLET] = bullet
        if pin is not None:
            references[PINOCCHIO] = PinocchioModel(model)
        implementations = {OURS: _own_calls(model), **{k: v.calls for k, v in references.items()}}
        for name, reference in references.items():
            agreement.update(_agreement(name, model, reference, sampled))
        passes = {}
        for name, calls_at in implementations.items():
            calls = [calls_at(q, qd) for q, qd in sampled]
            for quantity in QUANTITIES:
                if quantity in calls[0]:
                    passes[name, quantity] = _pass([at[quantity] for at in calls])
        best = _best_times(passes, repeats, number)
    for (name, quantity), seconds_per_pass in best.items():
        seconds.setdefault(name, {})[quantity] = seconds_per_pass / states
    for name, times in seconds.items():
        say(f"{name}: timed {len(times)} quantities at {states} states")
    if pin is None:
        say("Pinocchio is not installed (pip install 'dcsim[test]'): its column stays empty")
    return ManipulatorBenchResult(seconds, agreement, states, repeats, number)


def _own_calls(model: ManipulatorModel) -> Callable[[np.ndarray, np.ndarray], Calls]:
    """dcsim's calls at a state, keyed like the references' (:data:`QUANTITIES`)."""

    def calls(q: np.ndarray, qd: np.ndarray) -> Calls:
        return {
            "forward kinematics": lambda: model.forward_kinematics(q),
            "jacobian": lambda: model.jacobian(q),
            "mass matrix": lambda: model.mass_matrix(q),
            "coriolis matrix": lambda: model.coriolis_matrix(q, qd),
            "bias": lambda: model.bias(q, qd),
            "mass and coriolis": lambda: model.dynamics(q, qd),
        }

    return calls


def _agreement(
    name: str,
    model: ManipulatorModel,
    reference: BulletModel | PinocchioModel,
    sampled: Sequence[tuple[np.ndarray, np.ndarray]],
) -> dict[str, float]:
    """The largest relative differences of ``reference``'s M, C q̇ and Jacobian from
    dcsim's over the states."""
    worst = {f"{name} M": 0.0, f"{name} C q̇": 0.0, f"{name} Jacobian": 0.0}
    for q, qd in sampled:
        pairs = {
            f"{name} M": (model.mass_matrix(q), reference.mass_matrix(q)),
            f"{name} C q̇": (model.bias(q, qd), reference.bias(q, qd)),
            f"{name} Jacobian": (model.jacobian(q), reference.jacobian(q)),
        }
        for key, (ours, theirs) in pairs.items():
            difference = float(np.abs(theirs - ours).max() / np.abs(ours).max())
            worst[key] = max(worst[key], difference)
    return worst


def _pass(calls: list[Callable[[], object]]) -> Callable[[], None]:
    """One pass: every call once."""

    def one_pass() -> None:
        for call in calls:
            call()

    return one_pass


def _best_times(
    passes: dict[tuple[str, str], Callable[[], None]], repeats: int, number: int
) -> dict[tuple[str, str], float]:
    """Best wall time of one pass, s, of each of ``passes``: ``repeats`` rounds, each
    timing ``number`` passes of every one in turn."""
    timers = {key: timeit.Timer(one_pass) for key, one_pass in passes.items()}
    best = dict.fromkeys(passes, np.inf)
    for _ in range(repeats):
        for key, timer in timers.items():
            best[key] = min(best[key], timer.timeit(number) / number)
    return best


def scenario_speed(
    path: str | Path, overrides: Sequence[str] = (), registry: PluginRegistry | None = None
) -> ScenarioSpeed:
    """Run the scenario at ``path`` once (recording in memory) and time it."""
    runner = Runner(setup_run(path, overrides, registry=registry))
    summary = runner.run()
    sim_time = summary["sim_time_s"]
    phases = {phase: runner.laps.totals.get(phase, 0.0) / sim_time for phase in PHASES}
    return ScenarioSpeed(summary["scenario"], sim_time, summary["wall_time_s"], phases)


def markdown_table(result: ManipulatorBenchResult) -> str:
    """The times per call (µs) as a Markdown table, then the 10× target's verdict."""
    columns = " | ".join(f"{name} (µs)" for name in IMPLEMENTATIONS)
    head = f"| call | {columns} | dcsim / Pinocchio |"
    lines = [head, "|---|" + "---:|" * (len(IMPLEMENTATIONS) + 1)]
    pinocchio_pair = result.mass_and_coriolis(PINOCCHIO)
    for quantity, label in QUANTITIES.items():
        times = [result.seconds.get(name, {}).get(quantity) for name in IMPLEMENTATIONS]
        reference = pinocchio_pair if quantity == "mass and coriolis" else times[2]
        lines.append(_row(label, times, reference))
    pair = [result.mass_and_coriolis(name) for name in IMPLEMENTATIONS]
    lines.append(_row("M + C, two calls", pair, pinocchio_pair))
    return "\n".join([*lines, "", verdict(result)])


def _row(label: str, times: list[float | None], reference: float | None) -> str:
    cells = ["—" if t is None else f"{1e6 * t:.2f}" for t in times]
    ratio = "—" if reference is None or times[0] is None else f"{times[0] / reference:.1f}"
    return f"| {label} | {' | '.join(cells)} | {ratio} |"


def verdict(result: ManipulatorBenchResult) -> str:
    """Whether dcsim's ``M + C`` is within :data:`TARGET` times Pinocchio's, in words."""
    ratio = result.target_ratio
    ours, theirs = result.mass_and_coriolis(OURS), result.mass_and_coriolis(PINOCCHIO)
    if ratio is None or ours is None or theirs is None:
        return f"M + C within {TARGET:g}× of Pinocchio: not judged (Pinocchio is not installed)"
    one_call = 1e6 * result.seconds[OURS]["mass and coriolis"]
    holds = "yes" if ratio <= TARGET else "no"
    return (
        f"M + C within {TARGET:g}× of Pinocchio: {holds} (dcsim {1e6 * ours:.2f} µs in two "
        f"calls, {one_call:.2f} µs in one; Pinocchio {1e6 * theirs:.2f} µs; {ratio:.1f}×)"
    )


def agreement_line(result: ManipulatorBenchResult) -> str:
    """The references' largest relative differences from dcsim, in one line."""
    parts = ", ".join(f"{key} {value:.1e}" for key, value in result.agreement.items())
    return f"agreement with dcsim over the {result.states} states (relative): {parts}"


def scenario_line(speed: ScenarioSpeed) -> str:
    """A scenario run's real-time factor and its phases, in one line."""
    phases = ", ".join(f"{p} {1e3 * s:.1f}" for p, s in speed.phases.items())
    return (
        f"scenario {speed.name}: {speed.sim_time:.2f} s simulated in {speed.wall_time:.2f} s, "
        f"real-time factor {speed.real_time_factor:.2f}; ms of wall time per simulated "
        f"second by phase: {phases}"
    )
