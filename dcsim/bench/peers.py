"""``dcsim bench peers``: dcsim's attitude loop beside Basilisk's, in one run.

The same rigid free flyer (mass, inertia, initial attitude, angular rate and velocity)
slews to a fixed inertial attitude under a PD law, controlled at 10 Hz for the whole
span, navigation fed the true state:

- **dcsim**: the ``hold`` mission (the attitude held is the goal; ``hold_position``
  false for the attitude-only row) with the ``pd`` controller, no localiser, through
  the normal runner (:class:`~dcsim.run.loop.Runner`, recording in memory), PyBullet
  stepping at the scenario's physics step;
- **Basilisk**: the modules of :mod:`dcsim.bench.basilisk_loop`, the dynamics task at
  the same step unless told otherwise.

Four rows: the attitude slew alone (no translation command), the same slew while
the position is held (dcsim's ``pd`` translation loop; Basilisk's
``hillFrameRelativeControl`` about a constant chief at the hold point), the attitude
slew on four reaction wheels in a pyramid instead of an ideal torque (dcsim's
``robot.actuators.reaction_wheels``; Basilisk's ``rwMotorTorque`` and
``reactionWheelStateEffector``, see :mod:`dcsim.bench.basilisk_loop` for how the two
wheel models are made the same spacecraft), and the attitude slew on twelve thrusters
in six opposed couples (dcsim's ``robot.actuators.thrusters``: allocation and
pulse-width modulation; Basilisk's ``thrForceMapping``, ``thrFiringRemainder`` and
``thrusterDynamicEffector``). Both sides share the commanded torque among the wheels by
the minimum-norm inverse and hold each wheel's torque over the control period; the
wheels' and thrusters' limits are above what the slew needs, so none saturates. The
thruster row flies the same slew only roughly: Basilisk's thruster modules fire from the
third period on and round on-times to the integrator's stages
(:mod:`dcsim.bench.basilisk_loop`), which leaves its pointing in a limit cycle where
dcsim's converges.

Gains: ``pd`` closes each loop on a double integrator with poles of
``s² + 2ζω s + ω²`` (``kp = ω²``, ``kd = 2ζω`` per unit inertia or mass, unsaturated
torque ``τ = I (kp θ ê − kd ω) + ω × Iω``). ``mrpFeedback`` gives
``τ = −K σ − P ω + ω × Iω`` with the MRP error ``σ = tan(θ/4) ê``, so
``K = 4 I kp`` and ``P = I kd`` give the same stiffness and damping to first order in
θ (for large errors the MRP law is stiffer: by 5.5 % at 90°). K and P are scalars in
``mrpFeedback``; the free flyer is a sphere, so its inertia is ``I`` times the identity
and the match holds on every axis. The robot's torque limit is set far above the
largest torque the slew needs, so neither law saturates.

Wall time, both sides, from the case's numbers to the end of the run, imports not
included (a short warm-up run of each side comes first): for dcsim, scenario
validation, plugin construction and gain design, world construction (PyBullet) and
the run; for Basilisk, module construction and wiring, recorders, initialisation and
the run. Reading the records afterwards is not timed. Each side's best run counts; the
process's CPU time over the same spans is reported beside, as a check on a busy
machine.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Literal

import numpy as np

from dcsim.bench.basilisk_loop import (
    BasiliskSetup,
    ThrusterSetup,
    WheelSetup,
    basilisk_missing,
    fly_basilisk,
)
from dcsim.geometry import (
    quaternion_conjugate,
    quaternion_from_rotation_vector,
    quaternion_multiply,
    rotation_vector,
)
from dcsim.missions.hold.settings import HoldMissionSection
from dcsim.registry.discovery import PluginRegistry
from dcsim.run.loop import Runner
from dcsim.run.seeding import component_rng
from dcsim.run.setup import RunSetup
from dcsim.scenario.model import Scenario, scenario_model
from dcsim.world import World

GOAL_ATTITUDE = (0.0, 0.0, 0.3826834323650898, 0.9238795325112867)
"""The inertial attitude held: 45° about +z, ``[x, y, z, w]``."""

SLEW = tuple(float(v) for v in np.radians(90.0) * np.array([1.0, -2.0, 2.0]) / 3.0)
"""Rotation vector from the initial attitude to the goal's (body axes): 90° about
(1, −2, 2)/3, rad."""

INITIAL_ATTITUDE = tuple(
    float(v)
    for v in quaternion_multiply(
        GOAL_ATTITUDE, quaternion_conjugate(quaternion_from_rotation_vector(SLEW))
    )
)
"""The initial attitude ``[x, y, z, w]``: 90° away from the goal."""

PYRAMID = tuple(
    tuple(float(v) for v in np.array(axis) / np.sqrt(3.0))
    for axis in ((1, 1, 1), (-1, 1, 1), (-1, -1, 1), (1, -1, 1))
)
"""The four wheels' spin axes, body frame: a pyramid about +z, each axis 54.7° from it,
so that ``Σ ĝ ĝᵀ = 4/3 I`` (the wheels give the same torque about every axis)."""

COUPLES = (
    ((0, 1, 0), (1, 0, 0)),
    ((0, -1, 0), (1, 0, 0)),
    ((0, 1, 0), (-1, 0, 0)),
    ((0, -1, 0), (-1, 0, 0)),
    ((0, 0, 1), (0, 1, 0)),
    ((0, 0, -1), (0, 1, 0)),
    ((0, 0, 1), (0, -1, 0)),
    ((0, 0, -1), (0, -1, 0)),
    ((1, 0, 0), (0, 0, 1)),
    ((-1, 0, 0), (0, 0, 1)),
    ((1, 0, 0), (0, 0, -1)),
    ((-1, 0, 0), (0, 0, -1)),
)
"""Twelve thrusters in six opposed couples, ``(position / arm, direction)``, body frame:
the x thrusters sit on ±y (torque about z), the y ones on ±z, the z ones on ±x; each
couple gives a torque about one axis and no force."""

TorqueBy = Literal["ideal", "wheels", "thrusters"]
"""What gives a row's torque: the ideal torque, the reaction wheels or the thrusters."""

TORQUES: tuple[TorqueBy, ...] = ("ideal", "wheels", "thrusters")
"""Every :data:`TorqueBy`, in the rows' order."""

RPM = 60.0 / (2.0 * np.pi)
"""Revolutions per minute in one rad/s."""

WHEEL_ROW = "slew on 4 wheels"
"""The name of the reaction-wheel row."""

THRUSTER_ROW = "slew on 12 thrusters"
"""The name of the thruster row."""

TARGET_RATIO = 3.0
"""The target: dcsim's loop within this factor of Basilisk's wall time."""


@dataclass(frozen=True)
class SlewCase:
    """The closed loop both simulators fly, SI units, world (inertial) frame.

    Attributes
    ----------
    mass : float
        kg.
    radius : float
        Radius of the spherical free flyer, m (its inertia is 0.4 m r² about each axis).
    initial_attitude, goal_attitude : tuple of float
        ``[x, y, z, w]``, body to world.
    initial_angular_velocity : tuple of float
        rad/s, world frame.
    initial_velocity : tuple of float
        m/s, world frame (the free flyer drifts unless its position is held).
    physics_step, control_period, duration : float
        s; the duration is a whole number of control periods.
    max_torque : float
        dcsim's torque limit, N·m (above what the slew needs: neither law saturates).
    bandwidth, damping : float
        ``pd``'s position loop: natural frequency (rad/s) and damping ratio.
    attitude_bandwidth, attitude_damping : float
        ``pd``'s attitude loop: natural frequency (rad/s) and damping ratio.
    wheel_axes : tuple of tuple of float
        The reaction wheels' unit spin axes, body frame (the wheel row).
    wheel_inertia : float
        Each wheel's moment of inertia about its spin axis, kg·m².
    wheel_max_torque : float
        Each wheel's torque limit, N·m (the wheels' limit on the base's torque in its
        weakest direction is 4/3 of it for the pyramid; above what the slew needs).
    wheel_max_momentum : float
        Each wheel's momentum limit, N·m·s (above what the slew stores).
    thruster_arm : float
        Distance of the thrusters from the centre of mass, m (:data:`COUPLES`).
    thruster_max_thrust : float
        Each thruster's thrust, N (a couple gives ``2 arm F`` about its axis).
    """

    mass: float = 100.0
    radius: float = 1.0
    initial_attitude: tuple[float, ...] = INITIAL_ATTITUDE
    goal_attitude: tuple[float, ...] = GOAL_ATTITUDE
    initial_angular_velocity: tuple[float, ...] = (0.02, -0.01, 0.03)
    initial_velocity: tuple[float, ...] = (0.05, -0.03, 0.02)
    physics_step: float = 0.01
    control_period: float = 0.1
    duration: float = 600.0
    max_torque: float = 100.0
    bandwidth: float = 0.2
    damping: float = 0.9
    attitude_bandwidth: float = 0.5
    attitude_damping: float = 0.9
    wheel_axes: tuple[tuple[float, ...], ...] = PYRAMID
    wheel_inertia: float = 0.1
    wheel_max_torque: float = 20.0
    wheel_max_momentum: float = 50.0
    thruster_arm: float = 1.0
    thruster_max_thrust: float = 10.0

    @property
    def attitude_gains(self) -> tuple[float, float]:
        """``pd``'s attitude gains ``kp = ω²`` (1/s²) and ``kd = 2ζω`` (1/s)."""
        return _pd_gains(self.attitude_bandwidth, self.attitude_damping)

    @property
    def position_gains(self) -> tuple[float, float]:
        """``pd``'s position gains ``kp = ω²`` (1/s²) and ``kd = 2ζω`` (1/s)."""
        return _pd_gains(self.bandwidth, self.damping)

    def mrp_gains(self, inertia: float) -> tuple[float, float]:
        """``mrpFeedback``'s K = 4 I kp (N·m) and P = I kd (N·m·s) for the principal
        moment ``inertia`` (kg·m²)."""
        kp, kd = self.attitude_gains
        return 4.0 * inertia * kp, inertia * kd


def _pd_gains(bandwidth: float, damping: float) -> tuple[float, float]:
    return bandwidth**2, 2.0 * damping * bandwidth


@dataclass(frozen=True)
class Flight:
    """One side's record of one run, at the control period.

    Attributes
    ----------
    wall : float
        Wall time of the run, s (see the module's notes for what is included).
    cpu : float
        The process's CPU time over the same span, s.
    times : ndarray (N,)
        s.
    pointing_error : ndarray (N,)
        Angle between the attitude and the goal's, rad.
    position_error : ndarray (N,)
        Distance from the start (hold) position, m.
    peak_torque : float
        Largest commanded torque magnitude, N·m.
    wheel_speed : ndarray (N, wheels)
        Each reaction wheel's momentum about its axis over its inertia, rad/s (dcsim's
        ``wheel_speed``; the spin rate relative to the base plus the base's rate about
        the wheel's axis); no columns with ideal torque.
    phases : dict of str to float
        dcsim's wall time by phase of the run loop (the runner's lap timer), s; empty
        for Basilisk.
    """

    wall: float
    cpu: float
    times: np.ndarray
    pointing_error: np.ndarray
    position_error: np.ndarray
    peak_torque: float
    wheel_speed: np.ndarray
    phases: dict[str, float] = field(default_factory=dict)

    @property
    def peak_wheel_speed(self) -> float:
        """The largest wheel speed magnitude of the run, rad/s (nan without wheels)."""
        return float(np.max(np.abs(self.wheel_speed))) if self.wheel_speed.size else np.nan


@dataclass
class PeerRow:
    """One closed loop flown by both sides, ``repeats`` times each.

    Attributes
    ----------
    name : str
        What the row flies.
    hold_position : bool
        Whether the position is held too.
    torque_by : str
        What gives the torque (:data:`TorqueBy`).
    dcsim : list of Flight
        dcsim's runs.
    basilisk : list of Flight
        Basilisk's runs (empty when it was not flown).
    """

    name: str
    hold_position: bool
    torque_by: TorqueBy = "ideal"
    dcsim: list[Flight] = field(default_factory=list)
    basilisk: list[Flight] = field(default_factory=list)


@dataclass(frozen=True)
class PeersResult:
    """The benchmark's rows and how it was run.

    Attributes
    ----------
    case : SlewCase
        What was flown.
    rows : list of PeerRow
        Attitude only, with the position held, on reaction wheels, on thrusters.
    inertia : float
        The free flyer's principal moment of inertia, kg·m² (as PyBullet holds it).
    basilisk_step : float
        Basilisk's dynamics step, s.
    basilisk_note : str or None
        Why Basilisk was not flown, or None.
    """

    case: SlewCase
    rows: list[PeerRow]
    inertia: float
    basilisk_step: float
    basilisk_note: str | None


# ---------------------------------------------------------------------- dcsim's side
def slew_scenario(case: SlewCase, hold_position: bool, torque_by: TorqueBy = "ideal") -> Scenario:
    """dcsim's scenario of ``case``: a ``hold`` mission of the goal attitude, ``pd``,
    no localiser, a force-free (geocentric) world with nothing else in it; the case's
    reaction wheels or thrusters give the torque as ``torque_by`` says (its limit then
    theirs)."""
    robot: dict[str, Any] = {
        "mass": case.mass,
        "radius": case.radius,
        "initial": {
            "attitude": list(case.initial_attitude),
            "angular_velocity": list(case.initial_angular_velocity),
            "velocity": list(case.initial_velocity),
        },
    }
    if torque_by == "ideal":
        robot["max_torque"] = case.max_torque
    else:
        robot["actuators"] = {_section(torque_by): _actuators(case, torque_by)}
    name = "peers-slew" + ("-hold" if hold_position else "")
    name += "" if torque_by == "ideal" else f"-{torque_by}"
    return scenario_model(HoldMissionSection).model_validate(
        {
            "name": name,
            "world": {
                "frame": "geocentric",
                "physics_step": case.physics_step,
                "control_period": case.control_period,
                "duration": case.duration,
            },
            "robot": robot,
            "localiser": None,
            "controller": {
                "plugin": "pd",
                "params": {
                    "bandwidth": case.bandwidth,
                    "damping": case.damping,
                    "attitude_bandwidth": case.attitude_bandwidth,
                    "attitude_damping": case.attitude_damping,
                },
            },
            "mission": {
                "type": "hold",
                "attitude": list(case.goal_attitude),
                "hold_position": hold_position,
            },
            "stop": {"on_collision": False},
        }
    )


def flyer_inertia(case: SlewCase) -> np.ndarray:
    """The free flyer's inertia tensor as dcsim's world holds it, body frame, kg·m²."""
    scenario = slew_scenario(case, hold_position=False)
    with World(scenario, component_rng(0, "world")) as world:
        return np.array(world.robot_spec().inertia)


def _section(torque_by: TorqueBy) -> str:
    """The ``robot.actuators`` key of the wheels or the thrusters."""
    return {"wheels": "reaction_wheels", "thrusters": "thrusters"}[torque_by]


def _actuators(case: SlewCase, torque_by: TorqueBy) -> list[dict[str, Any]]:
    """The case's reaction wheels or thrusters as ``robot.actuators`` lists them."""
    if torque_by == "wheels":
        wheel = {
            "inertia": case.wheel_inertia,
            "max_torque": case.wheel_max_torque,
            "max_momentum": case.wheel_max_momentum,
        }
        return [{"axis": list(axis), **wheel} for axis in case.wheel_axes]
    return [
        {
            "position": [case.thruster_arm * v for v in position],
            "direction": list(direction),
            "max_thrust": case.thruster_max_thrust,
        }
        for position, direction in COUPLES
    ]


def torque_limit(case: SlewCase, torque_by: TorqueBy) -> float:
    """The torque dcsim's robot is limited to, N·m: the case's, or what its wheels or
    thrusters give the base in its weakest direction."""
    return float(slew_scenario(case, False, torque_by).robot.max_torque)


def fly_dcsim(
    case: SlewCase, hold_position: bool, registry: PluginRegistry, torque_by: TorqueBy = "ideal"
) -> Flight:
    """Fly ``case`` through dcsim's runner and return its record (the torque given as
    ``torque_by`` says)."""
    began, cpu_began = time.perf_counter(), time.process_time()
    scenario = slew_scenario(case, hold_position, torque_by)
    runner = Runner(RunSetup.from_scenario(scenario, registry), keep_rows=True)
    summary = runner.run()
    wall, cpu = time.perf_counter() - began, time.process_time() - cpu_began
    if summary["status"] != "completed":
        raise RuntimeError(f"the dcsim run ended {summary['status']}: {summary['reason']}")
    rows = runner.recorder.rows
    attitudes = np.array([[row[k] for k in ("qx", "qy", "qz", "qw")] for row in rows])
    wheels = range(1, len(case.wheel_axes) + 1) if torque_by == "wheels" else []
    columns = [f"wheel_h_{i}" for i in wheels]
    momenta = np.array([[row[k] for k in columns] for row in rows]).reshape(len(rows), -1)
    return Flight(
        wall=wall,
        cpu=cpu,
        times=np.array([row["time"] for row in rows]),
        pointing_error=pointing_errors(attitudes, case.goal_attitude),
        position_error=np.array([row["position_error"] for row in rows]),
        peak_torque=float(
            np.max(np.linalg.norm([[row[k] for k in ("tx", "ty", "tz")] for row in rows], axis=1))
        ),
        wheel_speed=momenta / case.wheel_inertia,
        phases=dict(summary["wall_time_by_phase_s"]),
    )


# ---------------------------------------------------------------------- Basilisk's side
def basilisk_setup(
    case: SlewCase,
    hold_position: bool,
    inertia: np.ndarray,
    step: float,
    torque_by: TorqueBy = "ideal",
) -> BasiliskSetup:
    """The Basilisk loop of ``case``: same body and start, gains matched to ``pd``'s, the
    torque given as ``torque_by`` says.

    Raises
    ------
    ValueError
        If ``inertia`` is not the same about every axis: ``mrpFeedback``'s scalar gains
        match ``pd``'s law on every axis only then.
    """
    moment = float(np.mean(np.diag(inertia)))
    if not np.allclose(inertia, moment * np.eye(3), rtol=1e-9, atol=0.0):
        raise ValueError(f"the gains match on every axis only for an isotropic inertia: {inertia}")
    return BasiliskSetup(
        mass=case.mass,
        inertia=np.asarray(inertia, dtype=float),
        attitude=np.asarray(case.initial_attitude),
        angular_velocity=np.asarray(case.initial_angular_velocity),
        velocity=np.asarray(case.initial_velocity),
        goal_attitude=np.asarray(case.goal_attitude),
        mrp_gains=case.mrp_gains(moment),
        position_gains=case.position_gains if hold_position else None,
        dynamics_step=step,
        control_period=case.control_period,
        duration=case.duration,
        wheels=_wheel_setup(case) if torque_by == "wheels" else None,
        thrusters=_thruster_setup(case) if torque_by == "thrusters" else None,
    )


def _wheel_setup(case: SlewCase) -> WheelSetup:
    """The case's reaction wheels for the Basilisk loop."""
    axes = np.array(case.wheel_axes, dtype=float).T
    return WheelSetup(
        axes=axes / np.linalg.norm(axes, axis=0),
        inertia=case.wheel_inertia,
        max_torque=case.wheel_max_torque,
        max_momentum=case.wheel_max_momentum,
    )


def _thruster_setup(case: SlewCase) -> ThrusterSetup:
    """The case's thrusters for the Basilisk loop."""
    positions, directions = (np.array(part, dtype=float) for part in zip(*COUPLES, strict=True))
    return ThrusterSetup(
        positions=case.thruster_arm * positions,
        directions=directions,
        max_thrust=case.thruster_max_thrust,
    )


def fly_peer(setup: BasiliskSetup) -> Flight:
    """Fly the Basilisk loop and return its record."""
    flight = fly_basilisk(setup)
    return Flight(
        wall=flight.wall,
        cpu=flight.cpu,
        times=flight.times,
        pointing_error=pointing_errors(flight.attitudes, setup.goal_attitude),
        position_error=np.linalg.norm(flight.positions, axis=1),
        peak_torque=float(np.max(np.linalg.norm(flight.torques, axis=1))),
        wheel_speed=flight.wheel_speeds,
    )


# ---------------------------------------------------------------------- the bench
def pointing_errors(attitudes: np.ndarray, goal: np.ndarray | tuple[float, ...]) -> np.ndarray:
    """Angles (rad) of the rotations from ``attitudes`` (N, 4) to ``goal`` (4,), both
    ``[x, y, z, w]``."""
    error = quaternion_multiply(np.asarray(goal, dtype=float), quaternion_conjugate(attitudes))
    return np.linalg.norm(rotation_vector(error), axis=-1)


def bench_peers(
    duration: float,
    repeats: int,
    basilisk_step: float | None = None,
    progress: Callable[[str], None] = print,
) -> PeersResult:
    """Fly both rows on both sides ``repeats`` times, alternating sides.

    Parameters
    ----------
    duration : float
        Simulated span, s (rounded to whole control periods).
    repeats : int
        Timed runs per row and side.
    basilisk_step : float, optional
        Basilisk's dynamics step, s; dcsim's physics step if None.
    progress : callable
        Receives a line per finished run, and the reason when Basilisk is not flown.
    """
    base = SlewCase()
    periods = max(1, round(duration / base.control_period))
    case = replace(base, duration=periods * base.control_period)
    step = case.physics_step if basilisk_step is None else basilisk_step
    registry = PluginRegistry.discover()
    inertia = flyer_inertia(case)
    note = basilisk_missing()
    if note is not None:
        progress(f"Basilisk is not flown: {note}")
    rows = [
        PeerRow("attitude slew", False),
        PeerRow("slew + position hold", True),
        PeerRow(WHEEL_ROW, False, torque_by="wheels"),
        PeerRow(THRUSTER_ROW, False, torque_by="thrusters"),
    ]
    _warm_up(case, registry, inertia, step, basilisk=note is None)
    for repeat in range(1, repeats + 1):
        for row in rows:
            row.dcsim.append(fly_dcsim(case, row.hold_position, registry, row.torque_by))
            line = f"{row.name}, run {repeat}/{repeats}: dcsim {row.dcsim[-1].wall:.3f} s"
            if note is None:
                setup = basilisk_setup(case, row.hold_position, inertia, step, row.torque_by)
                row.basilisk.append(fly_peer(setup))
                line += f", Basilisk {row.basilisk[-1].wall:.3f} s"
            progress(line)
    return PeersResult(case, rows, float(np.mean(np.diag(inertia))), step, note)


def _warm_up(
    case: SlewCase, registry: PluginRegistry, inertia: np.ndarray, step: float, basilisk: bool
) -> None:
    """Short runs of each side on each actuator: imports and first-use costs stay out of
    the timings."""
    short = replace(case, duration=10 * case.control_period)
    for torque_by in TORQUES:
        fly_dcsim(short, True, registry, torque_by)
        if basilisk:
            fly_peer(basilisk_setup(short, True, inertia, step, torque_by))


# ---------------------------------------------------------------------- figures
def best_wall(flights: list[Flight]) -> float:
    """Shortest wall time of ``flights``, s: as timeit's best of N, the run least
    slowed by whatever else the machine was doing (load only ever adds time)."""
    return min(f.wall for f in flights)


def largest_gap(a: Flight, b: Flight) -> float:
    """Largest difference of the two pointing errors at the same times, rad."""
    n = min(len(a.times), len(b.times))
    if not np.allclose(a.times[:n], b.times[:n], atol=1e-9):
        raise ValueError("the two records are not sampled at the same times")
    return float(np.max(np.abs(a.pointing_error[:n] - b.pointing_error[:n])))


def markdown_table(result: PeersResult) -> str:
    """The rows as a Markdown table: best wall time per simulated second (ms),
    real-time factor, final pointing error (deg), dcsim/Basilisk wall-time ratio."""
    span = result.case.duration
    lines = [
        "| loop | dcsim ms / sim s | Basilisk ms / sim s | dcsim real-time factor | "
        "Basilisk real-time factor | dcsim final pointing error (deg) | "
        "Basilisk final pointing error (deg) | largest pointing-error gap (deg) | "
        f"dcsim / Basilisk | within {TARGET_RATIO:g}× |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---|",
    ]
    for row in result.rows:
        ours = best_wall(row.dcsim) / span
        cells = [row.name, f"{1e3 * ours:.2f}", "–", f"{1 / ours:.0f}", "–"]
        cells += [f"{np.degrees(row.dcsim[-1].pointing_error[-1]):.2g}", "–", "–"]
        if row.basilisk:
            theirs = best_wall(row.basilisk) / span
            ratio = ours / theirs
            cells[2], cells[4] = f"{1e3 * theirs:.2f}", f"{1 / theirs:.0f}"
            cells[6] = f"{np.degrees(row.basilisk[-1].pointing_error[-1]):.2g}"
            cells[7] = f"{np.degrees(largest_gap(row.dcsim[-1], row.basilisk[-1])):.2g}"
            cells += [f"{ratio:.2f}", "yes" if ratio <= TARGET_RATIO else "no"]
        else:
            cells += ["–", "–"]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def notes(result: PeersResult) -> str:
    """How the runs were set up, and the position-hold figures, as Markdown lines."""
    case = result.case
    kp, kd = case.attitude_gains
    big_k, big_p = case.mrp_gains(result.inertia)
    first = result.rows[0].dcsim[-1]
    lines = [
        f"- {case.duration:g} s simulated, control period {case.control_period:g} s, "
        f"dcsim physics step {case.physics_step:g} s, Basilisk dynamics step "
        f"{result.basilisk_step:g} s; best of {len(result.rows[0].dcsim)} runs per side.",
        f"- mass {case.mass:g} kg, inertia {result.inertia:g} kg·m² about each axis; "
        f"initial pointing error {np.degrees(first.pointing_error[0]):.1f}°.",
        f"- pd: kp = {kp:g} s⁻², kd = {kd:g} s⁻¹; mrpFeedback: K = {big_k:g} N·m, "
        f"P = {big_p:g} N·m·s.",
        _torque_line(result),
        _wheel_line(result),
        _thruster_line(result),
        _phase_line(result, result.rows[0]),
        _phase_line(result, _wheel_row(result)),
        _phase_line(result, _row(result, "thrusters")),
        _cpu_line(result),
    ]
    hold = result.rows[1]
    line = (
        f"- position hold: dcsim's largest / final distance from the hold point "
        f"{np.max(hold.dcsim[-1].position_error):.3g} / {hold.dcsim[-1].position_error[-1]:.2g} m"
    )
    if hold.basilisk:
        peer = hold.basilisk[-1]
        line += f", Basilisk's {np.max(peer.position_error):.3g} / {peer.position_error[-1]:.2g} m"
    lines.append(line + ".")
    if result.basilisk_note is not None:
        lines.append(f"- Basilisk was not flown: {result.basilisk_note}.")
    return "\n".join(lines)


def _torque_line(result: PeersResult) -> str:
    """The largest commanded torques against dcsim's limit."""
    row = result.rows[0]
    line = f"- largest commanded torque: dcsim {row.dcsim[-1].peak_torque:.3g} N·m"
    if row.basilisk:
        line += f", Basilisk {row.basilisk[-1].peak_torque:.3g} N·m"
    peaks = [f.peak_torque for f in (row.dcsim[-1], *row.basilisk[-1:])]
    limit = result.case.max_torque
    if max(peaks) < limit:
        return line + f", below dcsim's limit of {limit:g} N·m: no torque saturates."
    return line + f": dcsim's limit of {limit:g} N·m is reached, the laws differ there."


def _wheel_line(result: PeersResult) -> str:
    """The wheels, their limits, and each side's largest torque and wheel speed."""
    case, row = result.case, _wheel_row(result)
    limit = torque_limit(case, "wheels")
    flights = [("dcsim", row.dcsim[-1])] + [("Basilisk", f) for f in row.basilisk[-1:]]
    torques = ", ".join(f"{side} {flight.peak_torque:.3g} N·m" for side, flight in flights)
    speeds = ", ".join(
        f"{side} {flight.peak_wheel_speed:.4g} rad/s ({RPM * flight.peak_wheel_speed:.0f} rpm)"
        for side, flight in flights
    )
    fraction = max(f.peak_wheel_speed for _, f in flights) * case.wheel_inertia
    fraction /= case.wheel_max_momentum
    within = max(f.peak_torque for _, f in flights) < limit and fraction < 1.0
    line = (
        f"- {row.name}: {len(case.wheel_axes)} wheels in a pyramid about +z (axes 54.7° "
        f"from it), each {case.wheel_inertia:g} kg·m², {case.wheel_max_torque:g} N·m, "
        f"{case.wheel_max_momentum:g} N·m·s (the base's torque limit {limit:.3g} N·m in "
        f"its weakest direction); largest commanded torque {torques}; peak wheel speed "
        f"(momentum / wheel inertia) {speeds}, {100 * fraction:.0f} % of the momentum limit"
    )
    line += ": no wheel saturates" if within else ": a wheel limit is reached, the sides differ"
    if row.basilisk:
        gap = np.max(np.abs(row.dcsim[-1].wheel_speed[-1] - row.basilisk[-1].wheel_speed[-1]))
        line += f"; final wheel speeds differ by at most {gap:.2g} rad/s"
    return line + "."


def _thruster_line(result: PeersResult) -> str:
    """The thrusters, their limit, each side's largest torque and how still each side's
    pointing ends."""
    case, row = result.case, _row(result, "thrusters")
    flights = [("dcsim", row.dcsim[-1])] + [("Basilisk", f) for f in row.basilisk[-1:]]
    torques = ", ".join(f"{side} {flight.peak_torque:.3g} N·m" for side, flight in flights)
    tails = ", ".join(
        f"{side} {np.degrees(np.max(flight.pointing_error[-len(flight.times) // 10 :])):.2g}°"
        for side, flight in flights
    )
    return (
        f"- {row.name}: six opposed couples {case.thruster_arm:g} m from the centre of mass, "
        f"{case.thruster_max_thrust:g} N each (the base's torque limit "
        f"{torque_limit(case, 'thrusters'):.3g} N·m about each axis); largest commanded "
        f"torque {torques}; largest pointing error over the run's last tenth {tails}."
    )


def _wheel_row(result: PeersResult) -> PeerRow:
    """The reaction-wheel row of ``result``."""
    return _row(result, "wheels")


def _row(result: PeersResult, torque_by: TorqueBy) -> PeerRow:
    """The row of ``result`` whose torque ``torque_by`` gives."""
    return next(row for row in result.rows if row.torque_by == torque_by)


def _phase_line(result: PeersResult, row: PeerRow) -> str:
    """Where dcsim's best run of ``row`` spent its time, ms per simulated second."""
    best = min(row.dcsim, key=lambda f: f.wall)
    span = result.case.duration
    phases = sorted(best.phases.items(), key=lambda item: -item[1])
    parts = ", ".join(f"{name} {1e3 * seconds / span:.2f}" for name, seconds in phases)
    return f"- dcsim's best {row.name} run by phase of the run loop (ms / sim s): {parts}."


def _cpu_line(result: PeersResult) -> str:
    """Each side's least process CPU time per simulated second, and their ratio: a
    check on the wall times that waiting for a busy machine's cores does not inflate."""
    span = result.case.duration
    parts = []
    for row in result.rows:
        ours = min(f.cpu for f in row.dcsim) / span
        part = f"{row.name}: dcsim {1e3 * ours:.2f}"
        if row.basilisk:
            theirs = min(f.cpu for f in row.basilisk) / span
            part += f", Basilisk {1e3 * theirs:.2f} (ratio {ours / theirs:.2f})"
        parts.append(part)
    return "- by process CPU time (ms / sim s): " + "; ".join(parts) + "."


def verdict(result: PeersResult) -> str:
    """Whether dcsim is within :data:`TARGET_RATIO` of Basilisk's wall time, for the
    attitude loop (the attitude-only row) and for the wheel slew, one line each."""
    lines = []
    for row, what in ((result.rows[0], "attitude loop"), (_wheel_row(result), "wheel slew")):
        if not row.basilisk:
            lines.append(
                f"target (dcsim's {what} within {TARGET_RATIO:g}× of Basilisk): "
                "not measured, Basilisk was not flown"
            )
            continue
        ratio = best_wall(row.dcsim) / best_wall(row.basilisk)
        met = "met" if ratio <= TARGET_RATIO else "not met"
        lines.append(
            f"target (dcsim's {what} within {TARGET_RATIO:g}× of Basilisk's wall time): "
            f"{met}, {ratio:.2f}×"
        )
    return "\n".join(lines)


def plot(result: PeersResult, path: Path) -> None:
    """The two sides' runs against time, as a PNG at ``path``: pointing error during
    the slew and over the whole run (attitude-only row, the wheel row, the thruster
    row), distance from the hold point (position-hold row), and the wheels' speeds."""
    from dcsim.bench.figures import pyplot, save

    plt = pyplot()
    figure, axes = plt.subplots(3, 3, figsize=(14, 12.6))
    window = min(20.0, result.case.duration)
    shown = (0, min(60.0, result.case.duration))
    for (slew, tail, _), torque_by in zip(axes, TORQUES, strict=True):
        _pointing(_row(result, torque_by), slew, tail, window, result.case.duration)
    hold, speeds = axes[0][2], axes[1][2]
    for side, flight in _last_flights(result.rows[1]):
        hold.plot(flight.times, flight.position_error, color=_COLOURS[side], label=side)
    for side, flight in _last_flights(_wheel_row(result)):
        style = "-" if side == "dcsim" else "--"
        speeds.plot(flight.times, flight.wheel_speed, style, color=_COLOURS[side], lw=1.0)
    hold.set(
        xlabel="time [s]",
        ylabel="distance from the hold point [m]",
        title="slew + position hold",
        xlim=shown,
    )
    speeds.set(
        xlabel="time [s]",
        ylabel="wheel speed [rad/s]",
        title="wheel speeds (dcsim solid, Basilisk dashed)",
        xlim=shown,
    )
    for axis in (hold, speeds):
        axis.grid(alpha=0.3)
    axes[2][2].axis("off")
    axes[0][0].legend()
    figure.suptitle(
        "dcsim bench peers: pd (dcsim, PyBullet) beside mrpFeedback, hillFrameRelativeControl, "
        "rwMotorTorque and thrForceMapping (Basilisk)"
    )
    save(figure, path, dpi=90)


_COLOURS = {"dcsim": "tab:blue", "Basilisk": "tab:orange"}


def _pointing(row: PeerRow, slew: Any, tail: Any, window: float, duration: float) -> None:
    """Each side's pointing error of ``row``: the first ``window`` seconds (s) on
    ``slew``, the whole run of ``duration`` seconds on a log scale on ``tail``."""
    for side, flight in _last_flights(row):
        degrees = np.degrees(flight.pointing_error)
        shown = flight.times <= window
        slew.plot(flight.times[shown], degrees[shown], color=_COLOURS[side], label=side)
        tail.semilogy(flight.times, np.maximum(degrees, 1e-14), color=_COLOURS[side])
    slew.set(
        xlabel="time [s]", ylabel="pointing error [deg]", title=f"{row.name} (first {window:g} s)"
    )
    tail.set(
        xlabel="time [s]",
        ylabel="pointing error [deg]",
        title=f"{row.name}, the whole run ({duration:g} s)",
    )
    for axis in (slew, tail):
        axis.grid(alpha=0.3)


def _last_flights(row: PeerRow) -> list[tuple[str, Flight]]:
    """Each side's last run of ``row``."""
    flights = [("dcsim", row.dcsim[-1])]
    return flights + ([("Basilisk", row.basilisk[-1])] if row.basilisk else [])
