"""``dcsim bench dynamics``: the world's orbit models against an inertial reference.

**Free drift.** The robot of a bare :class:`~dcsim.world.World` starts at a separation
along one LVLH axis with a drift-free velocity (``ẏ = −2 n x`` under ``cw``, the chief's
specific energy under ``two-body`` and ``j2``: :mod:`dcsim.world.orbit.bounded`) and
drifts free; its position is compared every :data:`SAMPLE_INTERVAL` seconds with
:func:`~dcsim.bench.orbit_reference.propagate_relative`, which integrates chief and robot
in the Earth-centred inertial frame with its own code. The reference has the exact
physics: a ``cw`` or ``two-body`` world is held to the two-body reference (for ``cw``
the difference is the linearisation's error), a ``j2`` world to the J2 reference (the
world's integration error).

**Thrust.** The integration cost of thrust: one case flies a constant thrust for its
first :data:`THRUST_DURATION` seconds, once at the physics step and once at half of it;
the worst distance between the two flights (and between the same pair without thrust).

**CW planners in a j2 world.** Missions whose planners model Clohessy–Wiltshire are
flown by the full runner under ``cw`` and under ``j2``: delta-v flown and planned, the
transfer's final distance to its goal, whether the goal was met, collisions.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from dcsim.bench import orbit_reference as reference
from dcsim.bench.figures import pyplot, save
from dcsim.errors import CwValidityWarning, PlannerModelWarning, ScenarioError
from dcsim.registry.discovery import PluginRegistry
from dcsim.run.loop import Runner
from dcsim.run.seeding import component_rng
from dcsim.run.setup import setup_run
from dcsim.scenario import read_scenario
from dcsim.scenario.model import OrbitSpec, Scenario
from dcsim.world import World, WorldInputs
from dcsim.world.orbit.bounded import energy_matched_velocity
from dcsim.world.orbit.chief import orbit_period, orbit_potential, relative_dynamics
from dcsim.world.orbit.validity import cw_error_estimate

MODELS = ("cw", "two-body", "j2")
"""The world's orbit models, in the tables' order."""
AXES = ("x", "y", "z")
"""LVLH axes: radial, along track, orbit normal."""
ORBIT_RADIUS = 6_778_137.0
"""Semi-major axis of every chief, m (400 km up for the circular one)."""
SAMPLE_INTERVAL = 10.0
"""Time between two comparisons with the reference, s (rounded to control periods)."""
TARGETS = {1000.0: 0.01, 10_000.0: 0.1}
"""Worst drift error allowed an exact (``two-body``, ``j2``) world, m, by separation (m)."""
THRUST = 0.1
"""Thrust of the thrusting case, N, along the radial axis."""
THRUST_DURATION = 100.0
"""How long the thrusting case thrusts from t = 0, s."""
ROBOT_MASS = 100.0
"""The drifting robot's mass, kg (10 kg of it propellant)."""

Progress = Callable[[str], None]


@dataclass(frozen=True)
class DriftCase:
    """One free-drift case.

    Attributes
    ----------
    model : str
        The world's orbit model: ``cw``, ``two-body`` or ``j2``.
    eccentricity : float
        The chief's eccentricity (semi-major axis :data:`ORBIT_RADIUS`).
    separation : float
        The robot's distance from the chief at t = 0, m.
    axis : str
        The LVLH axis it starts on: ``x``, ``y`` or ``z``.
    """

    model: str
    eccentricity: float
    separation: float
    axis: str

    @property
    def start(self) -> np.ndarray:
        """The robot's position at t = 0, LVLH, m."""
        position = np.zeros(3)
        position[AXES.index(self.axis)] = self.separation
        return position

    @property
    def reference_model(self) -> reference.OrbitModel:
        """The exact physics the case is held to: J2 for a ``j2`` world, else two-body."""
        return "j2" if self.model == "j2" else "two-body"


@dataclass(frozen=True)
class DriftResult:
    """A free-drift case's outcome.

    Attributes
    ----------
    case : DriftCase
    simulated : float
        Time flown, s.
    worst_error : float or None
        Largest distance from the reference over the samples, m; None if skipped.
    wall_per_second : float or None
        Wall time of the world's stepping per simulated second, s.
    cw_estimate : float or None
        Under ``cw``: the linearisation's error bound ``3 ρ² n t / a`` for the flight, m.
    skipped : str
        Why the case was not flown (the scenario rules' message), or empty.
    """

    case: DriftCase
    simulated: float
    worst_error: float | None
    wall_per_second: float | None
    cw_estimate: float | None = None
    skipped: str = ""

    @property
    def target(self) -> float | None:
        """The worst error allowed (m) an exact world at this separation, if any."""
        if self.case.model == "cw":
            return None
        return TARGETS.get(self.case.separation)

    @property
    def met(self) -> bool | None:
        """Whether the worst error is within :attr:`target` (None without one)."""
        if self.target is None or self.worst_error is None:
            return None
        return self.worst_error <= self.target


def drift_scenario(
    case: DriftCase,
    duration: float,
    physics_step: float = 0.01,
    control_period: float = 0.1,
    velocity: Sequence[float] = (0.0, 0.0, 0.0),
) -> Scenario:
    """The scenario of a drift case: a 100 kg sphere at :attr:`DriftCase.start` and no
    objects; its mission (``hold``) is not flown, the world is stepped bare.

    Parameters
    ----------
    case : DriftCase
    duration : float
        ``world.duration``, s.
    physics_step, control_period : float
        s.
    velocity : sequence of float
        The robot's velocity at t = 0, LVLH (seen in the rotating frame), m/s.

    Raises
    ------
    ScenarioError
        When the scenario rules refuse the case (``cw`` on an eccentric orbit).
    """
    orbit = {"model": case.model, "radius": ORBIT_RADIUS, "eccentricity": case.eccentricity}
    return read_scenario(
        {
            "name": f"drift-{case.model}",
            "world": {
                "frame": "lvlh",
                "orbit": orbit,
                "physics_step": physics_step,
                "control_period": control_period,
                "duration": duration,
            },
            "robot": {
                "mass": ROBOT_MASS,
                "propellant_mass": 10.0,
                "radius": 0.5,
                "initial": {"position": case.start.tolist(), "velocity": list(velocity)},
            },
            "mission": {"type": "hold"},
        }
    )


def drift_free_velocity(orbit: OrbitSpec, position: np.ndarray) -> np.ndarray:
    """The velocity (LVLH, m/s) that keeps a body at ``position`` (m) near the chief:
    ``(0, −2 n x, 0)`` under ``cw``, the chief's specific energy otherwise."""
    if orbit.model == "cw":
        return np.array([0.0, -2.0 * orbit.mean_motion * position[0], 0.0])
    dynamics, potential = relative_dynamics(orbit), orbit_potential(orbit)
    return np.asarray(energy_matched_velocity(dynamics, potential, position, np.zeros(3)))


def fly(
    scenario: Scenario, sample_every: int, thrust_periods: int = 0
) -> tuple[np.ndarray, np.ndarray, float]:
    """Step a bare world to its duration, thrusting :data:`THRUST` N radially over its
    first ``thrust_periods`` control periods.

    Returns
    -------
    times : ndarray (m,)
        Every ``sample_every``-th control period's end, and the last, s.
    positions : ndarray (m, 3)
        The robot's positions then, LVLH, m.
    wall : float
        Wall time of the stepping, s.
    """
    coast, thrust = WorldInputs(), WorldInputs(force=np.array([THRUST, 0.0, 0.0]))
    times, positions = [], []
    with World(scenario, component_rng(scenario.world.seed, "world")) as world:
        periods = round(scenario.world.duration / world.control_period)
        start = time.perf_counter()
        for k in range(1, periods + 1):
            world.step(thrust if k <= thrust_periods else coast)
            if k % sample_every == 0 or k == periods:
                times.append(world.time)
                positions.append(world.base_state()[0].copy())
        wall = time.perf_counter() - start
    return np.array(times), np.array(positions), wall


def drift_duration(orbit: OrbitSpec, orbits: float, control_period: float) -> float:
    """The flight time (s) of ``orbits`` chief periods rounded to whole control periods
    of ``control_period`` s, at least one."""
    return max(round(orbits * orbit_period(orbit) / control_period), 1) * control_period


def chief_elements(orbit: OrbitSpec) -> reference.OrbitElements:
    """The chief's elements at t = 0 in the reference's terms (SI units, rad)."""
    chief = orbit.chief_orbit()
    return reference.OrbitElements(
        chief.semi_major_axis,
        chief.eccentricity,
        chief.inclination,
        chief.raan,
        chief.argument_of_perigee,
        chief.true_anomaly,
    )


def reference_positions(
    case: DriftCase, orbit: OrbitSpec, velocity: np.ndarray, times: np.ndarray
) -> np.ndarray:
    """The robot's positions (m, LVLH) at ``times`` (s) by the inertial reference under
    the case's exact physics, from its start and ``velocity`` (m/s)."""
    trajectory = reference.propagate_relative(
        chief_elements(orbit),
        case.start[None],
        velocity[None],
        times,
        case.reference_model,
        mu=orbit.mu,
        radius=orbit.earth_radius,
        j2=orbit.j2,
    )
    return trajectory.rho[:, 0]


def drift_error(
    case: DriftCase, orbits: float, physics_step: float = 0.01, control_period: float = 0.1
) -> DriftResult:
    """Fly one drift case for ``orbits`` chief orbits and hold it to the reference.

    A case the scenario rules refuse is returned skipped, with their message.
    """
    try:
        scenario = drift_scenario(case, 1.0, physics_step, control_period)
    except ScenarioError as refused:
        reason = "; ".join(p.message for p in refused.problems)
        return DriftResult(case, 0.0, None, None, skipped=reason)
    orbit = scenario.world.orbit
    period = scenario.world.control_period
    duration = drift_duration(orbit, orbits, period)
    velocity = drift_free_velocity(orbit, case.start)
    scenario = drift_scenario(case, duration, physics_step, control_period, velocity.tolist())
    times, positions, wall = fly(scenario, max(round(SAMPLE_INTERVAL / period), 1))
    expected = reference_positions(case, orbit, velocity, times)
    worst = float(np.linalg.norm(positions - expected, axis=1).max())
    estimate = None
    if case.model == "cw":
        estimate = cw_error_estimate(
            case.separation, duration, orbit.semi_major_axis, orbit.mean_motion
        )
    return DriftResult(case, duration, worst, wall / duration, estimate)


def drift_cases(
    models: Sequence[str],
    eccentricities: Sequence[float],
    separations: Sequence[float],
    axes: Sequence[str],
) -> list[DriftCase]:
    """Every combination, model by model, orbit by orbit, separation by separation."""
    return [
        DriftCase(model, e, separation, axis)
        for model in models
        for e in eccentricities
        for separation in separations
        for axis in axes
    ]


def bench_drift(
    cases: Sequence[DriftCase],
    orbits: float,
    physics_step: float = 0.01,
    control_period: float = 0.1,
    progress: Progress = print,
) -> list[DriftResult]:
    """Fly every case; ``progress`` receives a line per case."""
    results = []
    for number, case in enumerate(cases, 1):
        result = drift_error(case, orbits, physics_step, control_period)
        results.append(result)
        label = f"{case.model}, e = {case.eccentricity:g}, {case.separation:g} m on {case.axis}"
        if result.skipped:
            progress(f"[{number}/{len(cases)}] {label}: skipped ({result.skipped})")
        else:
            progress(
                f"[{number}/{len(cases)}] {label}: worst error {result.worst_error:.3g} m, "
                f"{1e3 * (result.wall_per_second or 0.0):.2f} ms per simulated second"
            )
    return results


def _number(value: float | None, digits: int = 3) -> str:
    return "–" if value is None else f"{value:.{digits}g}"


def drift_table(results: Sequence[DriftResult]) -> str:
    """The drift cases as a Markdown table, a row per model, orbit and separation with the
    worst error of each axis flown (skipped cases say so)."""
    lines = [
        "| model | reference | e | separation (m) | worst error x (m) | y (m) | z (m) | "
        "CW bound 3ρ²nt/a (m) | target (m) | met | wall ms / sim s |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---|---:|",
    ]
    groups: dict[tuple[str, float, float], list[DriftResult]] = {}
    for r in results:
        groups.setdefault((r.case.model, r.case.eccentricity, r.case.separation), []).append(r)
    for (model, e, separation), group in groups.items():
        head = f"| {model} | {group[0].case.reference_model} | {e:g} | {separation:g}"
        if all(r.skipped for r in group):
            lines.append(
                f"{head} | skipped: the scenario rules refuse it | – | – | – | – | – | – |"
            )
            continue
        flown = {r.case.axis: r for r in group if not r.skipped}
        errors = " | ".join(
            _number(flown[axis].worst_error) if axis in flown else "–" for axis in AXES
        )
        first = next(iter(flown.values()))
        met = [r.met for r in flown.values()]
        verdict = "–" if met[0] is None else ("yes" if all(met) else "**no**")
        wall = 1e3 * float(np.mean([r.wall_per_second or 0.0 for r in flown.values()]))
        lines.append(
            f"{head} | {errors} | {_number(first.cw_estimate)} | {_number(first.target)} | "
            f"{verdict} | {wall:.2f} |"
        )
    return "\n".join(lines)


def verdict(results: Sequence[DriftResult]) -> str:
    """One line per target: whether every exact case at that separation met it."""
    lines = []
    for separation, target in TARGETS.items():
        held = [r for r in results if r.target == target and r.case.separation == separation]
        if not held:
            continue
        worst = max(r.worst_error or 0.0 for r in held)
        met = all(r.met for r in held)
        lines.append(
            f"target ≤ {target * 100:g} cm at {separation:g} m (two-body, j2): "
            f"{'met' if met else 'NOT met'}, worst {worst:.3g} m over {len(held)} cases"
        )
    refused: dict[tuple[str, float, str], int] = {}
    for r in results:
        if r.skipped:
            key = (r.case.model, r.case.eccentricity, r.skipped)
            refused[key] = refused.get(key, 0) + 1
    for (model, e, reason), count in refused.items():
        lines.append(
            f"skipped {model} on the orbit of e = {e:g} ({count} case{'s' * (count > 1)}): "
            f"the scenario rules refuse it: {reason}"
        )
    return "\n".join(lines)


@dataclass(frozen=True)
class ThrustCost:
    """The integration cost of thrust on one case.

    Attributes
    ----------
    case : DriftCase
    simulated : float
        Time flown, s.
    physics_step : float
        The coarser step, s (the other is half of it).
    with_thrust : float
        Worst distance between the two steps' flights with :data:`THRUST` N radially over
        the first :data:`THRUST_DURATION` s, m.
    without_thrust : float
        The same for the free drift, m.
    """

    case: DriftCase
    simulated: float
    physics_step: float
    with_thrust: float
    without_thrust: float


def thrust_cost(
    orbits: float, physics_step: float = 0.01, control_period: float = 0.1
) -> ThrustCost:
    """Fly the 1 km radial ``j2`` case with and without thrust at ``physics_step`` and at
    half of it, for ``orbits`` orbits; the worst distances between the step sizes."""
    case = DriftCase("j2", 0.0, 1000.0, "x")
    orbit = drift_scenario(case, 1.0).world.orbit
    velocity = drift_free_velocity(orbit, case.start).tolist()
    duration = drift_duration(orbit, orbits, control_period)
    periods = round(duration / control_period)
    sample_every = max(round(SAMPLE_INTERVAL / control_period), 1)
    thrusting = min(round(THRUST_DURATION / control_period), periods)
    gaps = []
    for thrust_periods in (thrusting, 0):
        flown = [
            fly(
                drift_scenario(case, duration, step, control_period, velocity),
                sample_every,
                thrust_periods,
            )[1]
            for step in (physics_step, physics_step / 2)
        ]
        gaps.append(float(np.linalg.norm(flown[0] - flown[1], axis=1).max()))
    return ThrustCost(case, duration, physics_step, gaps[0], gaps[1])


def thrust_line(cost: ThrustCost) -> str:
    """The thrust cost as one paragraph of the bench's output."""
    return (
        f"thrust: {cost.case.model}, {cost.case.separation:g} m on {cost.case.axis}, "
        f"{THRUST:g} N radial for the first {THRUST_DURATION:g} s on {ROBOT_MASS:g} kg, "
        f"{cost.simulated:.0f} s flown: physics step {cost.physics_step:g} s against "
        f"{cost.physics_step / 2:g} s differ by {cost.with_thrust:.3g} m at worst "
        f"({cost.without_thrust:.3g} m without thrust)"
    )


@dataclass(frozen=True)
class Flight:
    """A mission flown by the full runner under one orbit model.

    Attributes
    ----------
    scenario : str
        The scenario file's name.
    planner : str
        The planner under test (the path planner of a transfer, the task planner of a
        debris mission).
    model : str
        The world's orbit model.
    status : str
        How the run ended, with its reason.
    delta_v : float
        Delta-v flown, m/s.
    planned_delta_v : float or None
        Sum of the delta-v of every path the path planner gave, m/s (None if none).
    plans : int
        Paths planned.
    miss : float or None
        Distance from the transfer's goal centre at the end, m (None for other missions).
    goal_met : bool
    collisions : int
    sim_time, wall_time : float
        s.
    """

    scenario: str
    planner: str
    model: str
    status: str
    delta_v: float
    planned_delta_v: float | None
    plans: int
    miss: float | None
    goal_met: bool
    collisions: int
    sim_time: float
    wall_time: float


FLIGHTS = (
    ("station_inspection.yaml", "grid-astar", ("path_planner.plugin=grid-astar",)),
    ("station_inspection.yaml", "multi-burn", ("path_planner.plugin=multi-burn",)),
    ("default.yaml", "ga", ()),
)
"""The missions flown: scenario file, planner under test, the overrides that select it."""


def fly_mission(
    path: Path, planner: str, overrides: Sequence[str], model: str, registry: PluginRegistry
) -> Flight:
    """Fly a scenario file with ``overrides`` in a world of orbit ``model``, recording in
    memory; the warnings that its planners model another orbit are expected and silenced."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlannerModelWarning)
        warnings.simplefilter("ignore", CwValidityWarning)
        setup = setup_run(path, [*overrides, f"world.orbit.model={model}"], registry=registry)
        runner = Runner(setup, plots=False)
        summary: dict[str, Any] = runner.run()
    paths = [e for e in runner.recorder.events if e["event"] == "path"]
    last = runner.recorder.rows[-1] if runner.recorder.rows else {}
    return Flight(
        scenario=path.name,
        planner=planner,
        model=model,
        status=f"{summary['status']} ({summary['reason']})",
        delta_v=float(summary["delta_v_mps"]),
        planned_delta_v=sum(float(e["delta_v"]) for e in paths) if paths else None,
        plans=len(paths),
        miss=float(last["goal_distance"]) if "goal_distance" in last else None,
        goal_met=bool(summary["goal_met"]),
        collisions=int(summary["collisions"]),
        sim_time=float(summary["sim_time_s"]),
        wall_time=float(summary["wall_time_s"]),
    )


def bench_flights(
    scenarios: Path,
    models: Sequence[str] = ("cw", "j2"),
    registry: PluginRegistry | None = None,
    progress: Progress = print,
) -> list[Flight]:
    """Fly every mission of :data:`FLIGHTS` (files in ``scenarios``) under each model."""
    registry = registry if registry is not None else PluginRegistry.discover()
    flights = []
    for name, planner, overrides in FLIGHTS:
        for model in models:
            flight = fly_mission(scenarios / name, planner, overrides, model, registry)
            flights.append(flight)
            progress(
                f"{name}, {planner}, {model}: {flight.status}, delta-v {flight.delta_v:.5f} m/s, "
                f"{flight.sim_time:.0f} s in {flight.wall_time:.1f} s"
            )
    return flights


def flights_table(flights: Sequence[Flight]) -> str:
    """The missions flown as a Markdown table."""
    lines = [
        "| scenario | planner | world | outcome | delta-v flown (m/s) | planned (m/s) | plans "
        "| final miss (m) | goal met | collisions | simulated (s) | wall (s) |",
        "|---|---|---|---|---:|---:|---:|---:|---|---:|---:|---:|",
    ]
    for f in flights:
        planned = "–" if f.planned_delta_v is None else f"{f.planned_delta_v:.5f}"
        miss = "–" if f.miss is None else f"{f.miss:.4f}"
        lines.append(
            f"| {f.scenario} | {f.planner} | {f.model} | {f.status} | {f.delta_v:.5f} | "
            f"{planned} | {f.plans} | {miss} | {'yes' if f.goal_met else 'no'} | "
            f"{f.collisions} | {f.sim_time:.1f} | {f.wall_time:.1f} |"
        )
    return "\n".join(lines)


def plot(results: Sequence[DriftResult], path: Path) -> None:
    """Worst drift error against separation (log-log), one line per model and orbit and
    axis-worst, with the 1 cm and 10 cm targets; written to ``path`` (PNG)."""
    plt = pyplot()
    figure, axes = plt.subplots(figsize=(7.0, 4.8))
    flown = [r for r in results if not r.skipped and r.worst_error]
    lines = sorted(
        {(r.case.model, r.case.eccentricity) for r in flown},
        key=lambda m: (MODELS.index(m[0]), m[1]),
    )
    for model, e in lines:
        points: dict[float, float] = {}
        for r in flown:
            if (r.case.model, r.case.eccentricity) == (model, e):
                s = r.case.separation
                points[s] = max(points.get(s, 0.0), float(r.worst_error or 0.0))
        separations = sorted(points)
        style = "-" if e == 0 else "--"
        axes.plot(
            separations,
            [points[s] for s in separations],
            style,
            marker={"cw": "o", "two-body": "s", "j2": "^"}[model],
            markerfacecolor="none" if e else None,
            color={"cw": "tab:red", "two-body": "tab:blue", "j2": "tab:green"}[model],
            label=f"{model}, e = {e:g}",
        )
    for separation, target in TARGETS.items():
        axes.plot([separation], [target], "kv", markersize=9)
        axes.annotate(
            f"target {target * 100:g} cm",
            (separation, target),
            textcoords="offset points",
            xytext=(6, 4),
            fontsize=8,
        )
    axes.set_xscale("log")
    axes.set_yscale("log")
    axes.set_xlabel("separation from the chief (m)")
    axes.set_ylabel("worst position error over the flight (m)")
    axes.set_title("Free drift against the inertial reference (worst over the axes)")
    axes.grid(True, which="both", alpha=0.3)
    axes.legend(fontsize=8)
    save(figure, path)
