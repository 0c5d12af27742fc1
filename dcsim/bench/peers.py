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

Two rows: the attitude slew alone (no translation command), and the same slew while
the position is held (dcsim's ``pd`` translation loop; Basilisk's
``hillFrameRelativeControl`` about a constant chief at the hold point).

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

import numpy as np

from dcsim.bench.basilisk_loop import (
    BasiliskSetup,
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
    phases: dict[str, float] = field(default_factory=dict)


@dataclass
class PeerRow:
    """One closed loop flown by both sides, ``repeats`` times each.

    Attributes
    ----------
    name : str
        What the row flies.
    hold_position : bool
        Whether the position is held too.
    dcsim : list of Flight
        dcsim's runs.
    basilisk : list of Flight
        Basilisk's runs (empty when it was not flown).
    """

    name: str
    hold_position: bool
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
        Attitude only, then with the position held.
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
def slew_scenario(case: SlewCase, hold_position: bool) -> Scenario:
    """dcsim's scenario of ``case``: a ``hold`` mission of the goal attitude, ``pd``,
    no localiser, a force-free (geocentric) world with nothing else in it."""
    return scenario_model(HoldMissionSection).model_validate(
        {
            "name": "peers-slew" + ("-hold" if hold_position else ""),
            "world": {
                "frame": "geocentric",
                "physics_step": case.physics_step,
                "control_period": case.control_period,
                "duration": case.duration,
            },
            "robot": {
                "mass": case.mass,
                "radius": case.radius,
                "max_torque": case.max_torque,
                "initial": {
                    "attitude": list(case.initial_attitude),
                    "angular_velocity": list(case.initial_angular_velocity),
                    "velocity": list(case.initial_velocity),
                },
            },
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


def fly_dcsim(case: SlewCase, hold_position: bool, registry: PluginRegistry) -> Flight:
    """Fly ``case`` through dcsim's runner and return its record."""
    began, cpu_began = time.perf_counter(), time.process_time()
    runner = Runner(
        RunSetup.from_scenario(slew_scenario(case, hold_position), registry), keep_rows=True
    )
    summary = runner.run()
    wall, cpu = time.perf_counter() - began, time.process_time() - cpu_began
    if summary["status"] != "completed":
        raise RuntimeError(f"the dcsim run ended {summary['status']}: {summary['reason']}")
    rows = runner.recorder.rows
    attitudes = np.array([[row[k] for k in ("qx", "qy", "qz", "qw")] for row in rows])
    return Flight(
        wall=wall,
        cpu=cpu,
        times=np.array([row["time"] for row in rows]),
        pointing_error=pointing_errors(attitudes, case.goal_attitude),
        position_error=np.array([row["position_error"] for row in rows]),
        peak_torque=float(
            np.max(np.linalg.norm([[row[k] for k in ("tx", "ty", "tz")] for row in rows], axis=1))
        ),
        phases=dict(summary["wall_time_by_phase_s"]),
    )


# ---------------------------------------------------------------------- Basilisk's side
def basilisk_setup(
    case: SlewCase, hold_position: bool, inertia: np.ndarray, step: float
) -> BasiliskSetup:
    """The Basilisk loop of ``case``: same body and start, gains matched to ``pd``'s.

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
    rows = [PeerRow("attitude slew", False), PeerRow("slew + position hold", True)]
    _warm_up(case, registry, inertia, step, basilisk=note is None)
    for repeat in range(1, repeats + 1):
        for row in rows:
            row.dcsim.append(fly_dcsim(case, row.hold_position, registry))
            line = f"{row.name}, run {repeat}/{repeats}: dcsim {row.dcsim[-1].wall:.3f} s"
            if note is None:
                setup = basilisk_setup(case, row.hold_position, inertia, step)
                row.basilisk.append(fly_peer(setup))
                line += f", Basilisk {row.basilisk[-1].wall:.3f} s"
            progress(line)
    return PeersResult(case, rows, float(np.mean(np.diag(inertia))), step, note)


def _warm_up(
    case: SlewCase, registry: PluginRegistry, inertia: np.ndarray, step: float, basilisk: bool
) -> None:
    """One short run of each side: imports and first-use costs stay out of the timings."""
    short = replace(case, duration=10 * case.control_period)
    fly_dcsim(short, True, registry)
    if basilisk:
        fly_peer(basilisk_setup(short, True, inertia, step))


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
        _phase_line(result),
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


def _phase_line(result: PeersResult) -> str:
    """Where dcsim's best attitude-slew run spent its time, ms per simulated second."""
    best = min(result.rows[0].dcsim, key=lambda f: f.wall)
    span = result.case.duration
    phases = sorted(best.phases.items(), key=lambda item: -item[1])
    parts = ", ".join(f"{name} {1e3 * seconds / span:.2f}" for name, seconds in phases)
    return f"- dcsim's best attitude-slew run by phase of the run loop (ms / sim s): {parts}."


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
    """Whether dcsim's attitude loop is within :data:`TARGET_RATIO` of Basilisk's wall
    time (the attitude-only row), in one line."""
    row = result.rows[0]
    if not row.basilisk:
        return (
            f"target (within {TARGET_RATIO:g}× of Basilisk): not measured, Basilisk was not flown"
        )
    ratio = best_wall(row.dcsim) / best_wall(row.basilisk)
    met = "met" if ratio <= TARGET_RATIO else "not met"
    return (
        f"target (dcsim's attitude loop within {TARGET_RATIO:g}× of Basilisk's wall time): "
        f"{met}, {ratio:.2f}×"
    )


def plot(result: PeersResult, path: Path) -> None:
    """The two sides' runs against time, as a PNG at ``path``: pointing error during
    the slew and over the whole run (attitude-only row), and distance from the hold
    point (position-hold row)."""
    from dcsim.bench.figures import pyplot, save

    plt = pyplot()
    figure, (slew, tail, hold) = plt.subplots(1, 3, figsize=(14, 4.2))
    colours = {"dcsim": "tab:blue", "Basilisk": "tab:orange"}
    window = min(20.0, result.case.duration)
    attitude, position = result.rows
    for side, flight in _last_flights(attitude):
        degrees = np.degrees(flight.pointing_error)
        shown = flight.times <= window
        slew.plot(flight.times[shown], degrees[shown], color=colours[side], label=side)
        tail.semilogy(flight.times, np.maximum(degrees, 1e-14), color=colours[side])
    for side, flight in _last_flights(position):
        hold.plot(flight.times, flight.position_error, color=colours[side], label=side)
    slew.set(
        xlabel="time [s]", ylabel="pointing error [deg]", title=f"the slew (first {window:g} s)"
    )
    tail.set(
        xlabel="time [s]",
        ylabel="pointing error [deg]",
        title=f"the whole run ({result.case.duration:g} s)",
    )
    hold.set(
        xlabel="time [s]",
        ylabel="distance from the hold point [m]",
        title="slew + position hold",
        xlim=(0, min(60.0, result.case.duration)),
    )
    for axis in (slew, tail, hold):
        axis.grid(alpha=0.3)
    slew.legend()
    figure.suptitle(
        "dcsim bench peers: pd (dcsim, PyBullet) beside mrpFeedback and "
        "hillFrameRelativeControl (Basilisk)"
    )
    save(figure, path, dpi=90)


def _last_flights(row: PeerRow) -> list[tuple[str, Flight]]:
    """Each side's last run of ``row``."""
    flights = [("dcsim", row.dcsim[-1])]
    return flights + ([("Basilisk", row.basilisk[-1])] if row.basilisk else [])
