"""``dcsim bench world``: the closed loop's cost against PyBullet stepping alone.

For each field size the benchmark builds one synthetic LVLH scenario (four targets near
the collector, the rest obstacles on bounded Clohessy–Wiltshire orbits 60–500 m away)
and measures, on that same world:

- **bare stepping**: ``stepSimulation`` alone for the simulated time;
- **closed loop**: the full runner (sensors, localiser, mission, planners, controller,
  forces, collision checks, telemetry), recording in memory.

Both are reported as wall time per simulated second, and the closed loop is split by
phase of the run loop (the runner's lap timer): the world's control-period step
(physics included), sensors, localiser, tracker (under an object sensor model), mission
(planners included), controller and recording. ``--sensors realistic`` flies every world
with the realistic sensing profile (sensor errors, detections tracked by the tracker).

Then the default scenario is flown, and the floor under its real-time factor measured:
what any run of it pays whatever the framework does around it, for the span it flew
(:func:`loop_floor`): PyBullet's stepping, the state reads and force applications
each physics step needs, and the localiser plugin's own predict, update and estimate
once a tick.
"""

from __future__ import annotations

import time
import timeit
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from dcsim.messages import BeaconRange, MotionInput, Prior
from dcsim.motion import mean_motion
from dcsim.registry.discovery import PluginRegistry
from dcsim.registry.interfaces import Localiser
from dcsim.run.loop import Runner
from dcsim.run.seeding import component_rng
from dcsim.run.setup import RunSetup, setup_run
from dcsim.scenario import read_scenario
from dcsim.scenario.model import Scenario
from dcsim.world import World
from dcsim.world.pybullet_client import pb

ORBIT_RADIUS = 6_778_137.0
_TARGETS = ([15.0, 30.0, 5.0], [-10.0, 45.0, -5.0], [20.0, -35.0, 0.0], [-15.0, -25.0, 8.0])
_BEACONS = [[100, 100, 100], [100, -100, -100], [-100, 100, -100], [-100, -100, 100]]


PHASES = ("world", "sensors", "localiser", "tracker", "mission", "controller", "recording")
"""Phases of the run loop the closed-loop time is split into (see ``LapTimer``)."""


@dataclass(frozen=True)
class WorldBenchRow:
    """One field size's measurements, in seconds of wall time per simulated second.

    Attributes
    ----------
    objects : int
        Targets and obstacles in the field.
    bare : float
        ``stepSimulation`` alone.
    closed_loop : float
        The full runner.
    phases : dict of str to float
        The closed loop split by phase of the run loop.
    localiser : float
        The scenario's localiser plugin alone (predict, update, estimate once per
        control period, standing still with the ranges read at the start).
    """

    objects: int
    bare: float
    closed_loop: float
    phases: dict[str, float]
    localiser: float

    @property
    def overhead(self) -> float:
        """Closed-loop time over bare stepping, minus one (0.5 is 50 % more)."""
        return self.closed_loop / self.bare - 1.0

    @property
    def floor_ratio(self) -> float:
        """Closed-loop time over bare stepping and the localiser alone (the project's
        target at 100 and 1,000 objects: at most 3)."""
        return self.closed_loop / (self.bare + self.localiser)


def field_scenario(
    objects: int,
    duration: float,
    seed: int = 0,
    orbit_model: str = "cw",
    sensing: str = "ideal",
) -> Scenario:
    """The synthetic benchmark scenario with ``objects`` targets and obstacles in all,
    in a world of orbit model ``orbit_model`` (``cw``, ``two-body`` or ``j2``), sensed
    with the profile ``sensing`` (``ideal`` or ``realistic``)."""
    rng = np.random.default_rng(seed)
    n = mean_motion(ORBIT_RADIUS)

    def cw(position: list[float], vz: float = 0.0) -> dict:
        return {"type": "cw", "position": position, "velocity": [0.0, -2 * n * position[0], vz]}

    targets = [
        {"id": i, "radius": 0.3, "mass": 5.0, "motion": cw(p)}
        for i, p in enumerate(_TARGETS[: min(4, objects)])
    ]
    obstacles = []
    for i in range(len(targets), objects):
        direction = rng.normal(size=3)
        position = direction / np.linalg.norm(direction) * rng.uniform(60.0, 500.0)
        obstacles.append(
            {"id": i, "radius": 1.0, "motion": cw(position.tolist(), rng.normal(0, 0.01))}
        )
    return read_scenario(
        {
            "name": f"bench-{objects}",
            "world": {
                "frame": "lvlh",
                "orbit": {"radius": ORBIT_RADIUS, "model": orbit_model},
                "duration": duration,
            },
            "robot": {"radius": 0.5, "max_force": 5.0, "max_speed": 0.5, "sensor_range": 120.0},
            "obstacles": obstacles,
            "beacons": {"positions": _BEACONS, "noise_sigma": 0.05, "report_nearest": 4},
            "mission": {
                "targets": targets,
                "drop_point": {"position": [-5.0, 0.0, 0.0], "tolerance": 1.5},
                "stop_on_all_delivered": False,
            },
            "stop": {"on_collision": False},
            "sensors": {"profile": sensing},
        }
    )


def bare_stepping(scenario: Scenario) -> float:
    """Wall seconds per simulated second of ``stepSimulation`` alone on the scenario's world."""
    with World(scenario, component_rng(0, "world")) as world:
        steps = round(scenario.world.duration / world.physics_step)
        start = time.perf_counter()
        _step_bare(world, steps)
        return (time.perf_counter() - start) / scenario.world.duration


def closed_loop(scenario: Scenario, registry: PluginRegistry) -> tuple[float, dict[str, float]]:
    """Wall seconds per simulated second of the full runner, in all and by phase."""
    runner = Runner(RunSetup.from_scenario(scenario, registry))
    start = time.perf_counter()
    runner.run()
    elapsed = time.perf_counter() - start
    duration = scenario.world.duration
    return elapsed / duration, {p: runner.laps.totals.get(p, 0.0) / duration for p in PHASES}


def localiser_alone(scenario: Scenario, registry: PluginRegistry) -> float:
    """Wall seconds per simulated second of the scenario's localiser plugin alone."""
    setup = RunSetup.from_scenario(scenario, registry)
    localiser = setup.plugins["localiser"]
    assert isinstance(localiser, Localiser)  # the field scenarios fly one
    with World(scenario, component_rng(0, "world")) as world:
        ticks = round(scenario.world.duration / world.control_period)
        timed = _time_localiser(localiser, world, ticks, repeats=1)
    return timed / scenario.world.duration


def bench_world(
    sizes: list[int],
    duration: float,
    progress: Callable[[str], None] = print,
    orbit_model: str = "cw",
    sensing: str = "ideal",
) -> list[WorldBenchRow]:
    """Measure every field size in worlds of ``orbit_model`` sensed with the profile
    ``sensing``; ``progress`` receives a line per finished size."""
    registry = PluginRegistry.discover()
    warm_up = field_scenario(4, 5.0, orbit_model=orbit_model, sensing=sensing)
    closed_loop(warm_up, registry)
    rows = []
    for objects in sizes:
        scenario = field_scenario(objects, duration, orbit_model=orbit_model, sensing=sensing)
        bare = bare_stepping(scenario)
        loop, phases = closed_loop(scenario, registry)
        alone = localiser_alone(scenario, registry)
        rows.append(WorldBenchRow(objects, bare, loop, phases, alone))
        progress(
            f"{objects} objects: bare stepping {1e3 * bare:.1f} ms, "
            f"closed loop {1e3 * loop:.1f} ms per simulated second"
        )
    return rows


def markdown_table(rows: list[WorldBenchRow]) -> str:
    """The measurements as a Markdown table (milliseconds of wall time per simulated second)."""
    head = (
        "| objects | bare stepping | closed loop | overhead | real-time factor | "
        + " | ".join(PHASES)
        + " | localiser alone | loop / (bare + localiser alone) |"
    )
    lines = [head, "|" + "---:|" * (7 + len(PHASES))]
    for r in rows:
        phases = " | ".join(f"{1e3 * r.phases[p]:.2f}" for p in PHASES)
        lines.append(
            f"| {r.objects} | {1e3 * r.bare:.2f} | {1e3 * r.closed_loop:.2f} | "
            f"{100 * r.overhead:.0f} % | {1 / r.closed_loop:.0f} | {phases} | "
            f"{1e3 * r.localiser:.2f} | {r.floor_ratio:.1f}× |"
        )
    return "\n".join(lines)


@dataclass(frozen=True)
class LoopFloor:
    """Wall time (s) a run of a scenario cannot avoid, for the span it flew.

    Attributes
    ----------
    sim_time : float
        Simulated span, s.
    stepping : float
        ``stepSimulation`` once per physics step.
    forces : float
        Beyond ``stepping``: reading the collector's pose and velocity and applying a
        force each physics step, as the world does for thrust and orbital forces.
    localiser : float
        The localiser plugin alone: predict, update (with the beacon ranges the
        collector reads at its start) and estimate once per control period.
    closed_loop : float
        The run's own wall time.
    """

    sim_time: float
    stepping: float
    forces: float
    localiser: float
    closed_loop: float

    @property
    def total(self) -> float:
        """The floor: stepping, forces and the localiser together, s."""
        return self.stepping + self.forces + self.localiser

    @property
    def ceiling(self) -> float:
        """The real-time factor if everything else in the loop cost nothing."""
        return self.sim_time / self.total

    @property
    def ratio(self) -> float:
        """The whole loop's wall time over the floor (1.0 would be a free framework)."""
        return self.closed_loop / self.total


def loop_floor(
    sim_time: float,
    closed_loop: float,
    registry: PluginRegistry,
    repeats: int = 3,
    overrides: Sequence[str] = (),
) -> LoopFloor:
    """Measure the floor of the default scenario over the span a run of it flew.

    Parameters
    ----------
    sim_time : float
        Simulated span the run flew, s.
    closed_loop : float
        The run's wall time, s (reported beside the floor).
    registry : PluginRegistry
        Where the scenario's localiser plugin comes from.
    repeats : int
        Each part is timed this many times; the shortest counts.
    overrides : sequence of str
        Overrides of the default scenario the run flew (``world.orbit.model=j2``).

    Returns
    -------
    LoopFloor
    """
    setup = setup_run(overrides=overrides, registry=registry)
    with World(setup.scenario, component_rng(0, "world")) as world:
        ticks = round(sim_time / world.control_period)
        steps = ticks * world.steps_per_control
        stepping = _best(lambda: _step_bare(world, steps), repeats)
        forced = _best(lambda: _step_with_forces(world, steps), repeats)
        localiser = setup.plugins["localiser"]
        assert isinstance(localiser, Localiser)  # the run set it up for the localiser role
        timed = _time_localiser(localiser, world, ticks, repeats)
    return LoopFloor(sim_time, stepping, max(forced - stepping, 0.0), timed, closed_loop)


def _best(measure: Callable[[], None], repeats: int) -> float:
    """Shortest wall time of ``repeats`` calls of ``measure``, s."""
    return min(timeit.repeat(measure, number=1, repeat=repeats))


def _step_bare(world: World, steps: int) -> None:
    """``stepSimulation`` alone, ``steps`` times."""
    for _ in range(steps):
        pb.stepSimulation(physicsClientId=world.client)


def _step_with_forces(world: World, steps: int) -> None:
    """``steps`` physics steps with the collector's state read and a force applied before
    each, as the world steps a control period."""
    client, body = world.client, world.robot_id
    for _ in range(steps):
        position = pb.getBasePositionAndOrientation(body, physicsClientId=client)[0]
        pb.getBaseVelocity(body, physicsClientId=client)
        pb.applyExternalForce(
            body, -1, (0.0, 0.0, 0.0), position, pb.WORLD_FRAME, physicsClientId=client
        )
        pb.stepSimulation(physicsClientId=client)


def _time_localiser(localiser: Localiser, world: World, ticks: int, repeats: int) -> float:
    """Shortest wall time (s) of ``ticks`` control periods of ``localiser`` alone, standing
    still where the world's robot starts with the beacon ranges it reads there."""
    ranges = list(world.beacon_ranges())
    position = world.base_state()[0]
    _localise(localiser, ranges, position, 1, world.control_period)  # imports on first use
    return _best(
        lambda: _localise(localiser, ranges, position, ticks, world.control_period), repeats
    )


def _localise(
    localiser: Localiser,
    ranges: list[BeaconRange],
    position: np.ndarray,
    ticks: int,
    period: float,
) -> None:
    """Reset ``localiser`` at ``position`` (m) and run ``ticks`` periods of ``period`` s
    with the same ``ranges``, standing still."""
    localiser.reset(Prior(position, 0.5, np.zeros(3), 0.01), 0.0)
    still = MotionInput(acceleration=np.zeros(3))
    for _ in range(ticks):
        localiser.predict(still, period)
        localiser.update(ranges)
        localiser.estimate()


def floor_line(floor: LoopFloor) -> str:
    """The floor as one line of the bench's output: its parts, their sum, the ceiling on
    the real-time factor, and the whole loop's wall time (s)."""
    return (
        f"floor of the default scenario over its {floor.sim_time:.1f} s: stepping "
        f"{floor.stepping:.2f} s + per-step state reads and forces {floor.forces:.2f} s + "
        f"localiser plugin alone {floor.localiser:.2f} s = {floor.total:.2f} s, so a real-time "
        f"factor of at most {floor.ceiling:.0f} if the rest of the loop were free "
        f"(the whole loop: {floor.closed_loop:.2f} s)"
    )


def ratio_line(floor: LoopFloor) -> str:
    """How far the default scenario's whole loop is above its floor, as the bench's last
    line: their ratio of wall times (``2.0×`` is twice the floor)."""
    return f"default scenario: the whole loop is {floor.ratio:.1f}× its floor"
