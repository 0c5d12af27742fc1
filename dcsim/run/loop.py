"""The run loop: world, localiser, mission, controller, recorded tick by tick.

One control tick (``docs/architecture.md``), the same for every mission::

    observations = world.observations()  # ranges, object tracks, attitude, joints
    localiser.predict(motion, dt); localiser.update(ranges); estimate = localiser.estimate()
    estimate += the attitude sensors' and encoders' readings
    reference = mission.tick(t, estimate, observations)    # may plan, grab, release
    command = controller.command(t, estimate, reference, mission.surroundings(...))
    record telemetry; fire dcsim_run_step
    world.step(command)                                     # fixed physics sub-steps

The runner knows no mission: the scenario's ``mission.type`` names the
:class:`~dcsim.missions.base.Mission`, which declares its plugin roles, its telemetry
columns, its summary fields and when it is finished. Plots are drawn into ``plots/``
of the run directory at the end. A run ends ``completed`` (the mission says so, or
``world.duration`` is reached), ``stopped`` (a collision with ``stop.on_collision``,
``stop.max_wall_time``, the mission says so, or an interrupt with Ctrl-C) or
``failed`` (a plugin or hook raised, or a plugin answered with something its kind may
not return: :mod:`dcsim.registry.answers`). Whatever the ending,
the telemetry, events and summary recorded so far are written.
"""

from __future__ import annotations

import dataclasses
import math
import sys
import time as wallclock
import warnings
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, TypedDict, cast

import numpy as np
from numpy.typing import ArrayLike

from dcsim.errors import CwValidityWarning, PlannerModelWarning
from dcsim.geometry import Vector, attitude_error
from dcsim.messages import (
    Command,
    Observations,
    Prior,
    Reference,
    StateEstimate,
    Surroundings,
)
from dcsim.missions import Mission, mission_class
from dcsim.registry.answers import ActuatorCounts, command_problem
from dcsim.registry.calls import PluginFailure, call_plugin
from dcsim.registry.hookspecs import RunInfo
from dcsim.registry.interfaces import Localiser
from dcsim.run.recording import (
    LEADING_COLUMNS,
    TRAILING_COLUMNS,
    Recorder,
    RecordingError,
    duty_columns,
    telemetry_columns,
    telemetry_units,
    wheel_columns,
)
from dcsim.run.seeding import component_rng
from dcsim.run.setup import RunSetup
from dcsim.scenario import dump_scenario
from dcsim.scenario.model import (
    ManipulatorSection,
    RobotSection,
    point_to_cartesian,
    robot_hardware,
)
from dcsim.world import World, WorldInputs
from dcsim.world.orbit.validity import cw_error_estimate

PLOT_POINTS = 2000
"""Telemetry rows the end-of-run plots draw at most (evenly spaced)."""

SUMMARY_FIGURES = (
    "sim_time_s",
    "wall_time_s",
    "real_time_factor",
    "collisions",
    "fuel_used_kg",
    "delta_v_mps",
    "localisation_rmse_m",
    "min_obstacle_distance_m",
)
"""The numeric fields of every run's summary; a mission adds its ``summary_names``."""

_PLANNER_KINDS = ("task_planner", "path_planner")
"""Plugin kinds that plan, and may model another orbit than the world's."""
_NO_COMMAND = Command()
"""The command of a period in which nothing is applied."""

_NO_SPREAD = np.zeros((6, 6))
_NO_SPREAD.setflags(write=False)  # the true state's covariance, shared by every tick's estimate

Progress = Callable[[float, float, str, str], None]
"""``progress(sim_time, duration, mode, mission_progress)``: times in s."""


class LapTimer:
    """Wall time spent in each phase of the run loop, s.

    Attributes
    ----------
    totals : dict of str to float
        Seconds per phase: ``sensors``, ``localiser``, ``mission`` (planners included),
        ``controller``, ``recording`` (telemetry, hooks, progress) and ``world``
        (the physics steps of each control period).
    """

    def __init__(self) -> None:
        self.totals: dict[str, float] = {}
        self._last = wallclock.perf_counter()

    def start(self) -> None:
        """Start timing from now."""
        self._last = wallclock.perf_counter()

    def lap(self, phase: str) -> None:
        """Charge the time since the previous lap to ``phase``."""
        now = wallclock.perf_counter()
        self.totals[phase] = self.totals.get(phase, 0.0) + now - self._last
        self._last = now


class HookFailure(Exception):
    """A lifecycle hook implementation raised during a run."""


class _RunEnded(Exception):
    """Internal: a stop rule ended the run."""

    def __init__(self, status: str, reason: str) -> None:
        super().__init__(reason)
        self.status, self.reason = status, reason


class Runner:
    """Runs one scenario, one control period at a time, and records it.

    :meth:`run` flies the scenario to its end. The same run can be driven step by step
    (the FMU slave does): :meth:`open` builds the world and decides the first control
    period, each :meth:`advance` flies one period and decides the next, and
    :meth:`close` writes the records and returns the summary.

    Parameters
    ----------
    setup : RunSetup
        The resolved scenario and its constructed plugins.
    out_dir : Path, optional
        Run directory to stream the records into (created if missing; see
        :func:`dcsim.run.directory.prepare_run_directory` for the checks the CLI makes first);
        None records in memory only.
    progress : callable, optional
        ``progress(sim_time, duration, mode, mission_progress)``, called about four
        times a second of wall time by :meth:`run` (``mission_progress`` is the
        mission's own few words, e.g. ``delivered 1/4``).
    keep_rows : bool, optional
        Keep every telemetry row in memory (``recorder.rows``); by default only when
        there is no run directory. A long run that needs only its summary (an FMU)
        passes False, so memory stays flat.
    plots : bool, optional
        Draw the mission's plots into ``plots/`` of the run directory at the end
        (default); a campaign's cases usually skip them.
    controller_on_demand : bool, optional
        Ask the controller for a period's command only when the period needs it: when
        :meth:`advance` is given no command, or a mapping that leaves fields to it. For
        runs an agent flies with whole commands (the Gymnasium environments), which then
        pay nothing for the controller; ``outputs["command"]`` is None until the
        period's command is known, and the last row records no command. By default the
        controller decides every period's command as it is decided (an FMU outputs it).

    Attributes
    ----------
    world : World or None
        The world, from :meth:`open` on.
    status, reason : str or None, str
        How the run ended (``completed``, ``stopped`` or ``failed``) and why; None
        while it goes on.
    mission : Mission or None
        The scenario's mission, from :meth:`open` on.
    estimate : StateEstimate or None
        The estimate at the current time (the localiser's, with the attitude sensors').
    surroundings : Surroundings or None
        What the controller is told of its neighbourhood at the current time: the
        tracked obstacles and the gap to keep from them.
    failure : PluginFailure or None
        The plugin failure that ended the run, if one did (its ``traceback`` is the
        plugin's own, when it raised).
    mode : str or None
        The mission mode decided for the current control period.
    outputs : dict of str to object
        The world's outputs (:meth:`World.outputs`) at the current time; while the run
        goes on, also the last ``command`` and ``attitude_error`` (rad, as recorded).
    """

    def __init__(
        self,
        setup: RunSetup,
        out_dir: Path | None = None,
        progress: Progress | None = None,
        keep_rows: bool | None = None,
        plots: bool = True,
        controller_on_demand: bool = False,
    ) -> None:
        self.setup = setup
        self.plots = plots
        self.scenario = setup.scenario
        self.plugins = setup.plugins
        self.mission_class = mission_class(self.scenario.mission.type)
        self._actuator_counts = actuator_counts(self.scenario.robot)
        self._wheel_columns = wheel_columns(self._actuator_counts.wheels)
        self._duty_columns = duty_columns(self._actuator_counts.thrusters)
        hardware = self._actuator_counts.thrusters, self._actuator_counts.wheels
        mission_columns = self.mission_class.telemetry_columns(self.scenario)
        columns = telemetry_columns(mission_columns, *hardware)
        mission_units = self.mission_class.telemetry_units(self.scenario)
        units = telemetry_units(mission_units, self._actuator_counts.wheels)
        self.recorder = Recorder(out_dir, columns, keep_rows, units)
        self.info = RunInfo(self.scenario, self.scenario.world.seed, out_dir)
        self.progress = progress
        self.world: World | None = None
        self.mission: Mission | None = None
        self.status: str | None = None
        self.reason = ""
        self.estimate: StateEstimate | None = None
        self.surroundings: Surroundings | None = None
        self.outputs: dict[str, Any] = {}
        self.summary: dict[str, Any] = {}
        self.laps = LapTimer()
        self.failure: PluginFailure | None = None
        self.controller_on_demand = controller_on_demand
        self._command: Command | None = None
        self._actuators = ActuatorCounts()
        self._pending: tuple[float, StateEstimate, str] | None = None
        self._reference: Reference | None = None
        self._robot_changes = 0
        self._started = 0.0
        self._squared_error_sum = 0.0
        self._converged_rows = 0
        self._min_gap = float("inf")
        self._max_separation = 0.0
        self._step_observed = True

    @property
    def ended(self) -> bool:
        """Whether the run has ended (see :attr:`status`)."""
        return self.status is not None

    @property
    def _opened_world(self) -> World:
        """The world, which exists once :meth:`open` has built it."""
        if self.world is None:
            raise RuntimeError("the run is not open: call open() first")
        return self.world

    @property
    def _opened_mission(self) -> Mission:
        """The mission, which exists once :meth:`open` has started the run."""
        if self.mission is None:
            raise RuntimeError("the run is not open: call open() first")
        return self.mission

    @property
    def reference(self) -> Reference | None:
        """The mission's reference for the current control period (what the controller
        tracks); None before :meth:`open`."""
        return self._reference

    @property
    def mode(self) -> str | None:
        """The mission mode decided for the current control period."""
        return None if self.mission is None else self.mission.mode

    # ------------------------------------------------------------------ public
    def run(self) -> dict[str, Any]:
        """Run to the end; return the summary (also written to ``summary.json``).

        Whatever ends the run — a stop rule, a failing plugin, Ctrl-C or a bug — the
        records made so far are written; an unexpected exception is raised again after.
        """
        last_progress = -np.inf
        try:
            self.open()
            while not self.ended:
                self.advance()
                wall = wallclock.perf_counter()
                if self.progress is not None and wall - last_progress > 0.25:
                    last_progress = wall
                    self._report_progress()
                self.laps.lap("recording")
        except KeyboardInterrupt:
            if self.world is None:
                raise
            self._end("stopped", "interrupted")
            self._event("interrupted")
        except BaseException as error:
            if self.world is not None:
                self._end("failed", f"{type(error).__name__}: {error}")
                self.close()
            raise
        return self.close()

    def open(self) -> None:
        """Build the world, reset the plugins and decide the first control period."""
        self._started = wallclock.perf_counter()
        self.world = World(
            self.scenario,
            component_rng(self.scenario.world.seed, "world"),
            self.setup.registry,
        )
        self._guarded(self._start)

    def advance(
        self,
        disturbance_force: np.ndarray | None = None,
        disturbance_torque: np.ndarray | None = None,
        command: Command | Mapping[str, ArrayLike] | None = None,
    ) -> None:
        """Fly one control period, then decide the next.

        The period is flown with the controller's command, or with ``command`` in its
        place (an agent's: a Gymnasium environment's step, a replay). Once the run has
        ended the world coasts: the period is flown without thrust and nothing more is
        recorded.

        Parameters
        ----------
        disturbance_force : ndarray (3,), optional
            External force on the collector over the period, world frame, N (none if
            None).
        disturbance_torque : ndarray (3,), optional
            External torque on the collector over the period, world frame, N·m.
        command : Command or mapping, optional
            What the actuators apply over the period instead of the controller's
            command: a :class:`~dcsim.messages.Command` replaces all of it; a mapping
            of some of its fields to values (``{"force": [0.1, 0, 0]}``: world frame,
            SI) replaces those fields, the controller's command giving the others (its
            torque holding the attitude, say). It is recorded as the tick's command.

        Raises
        ------
        ValueError
            If ``command`` names a field a :class:`Command` does not have, or has
            non-finite numbers or the wrong number of joint torques, thruster on-times
            or wheel torques (nothing is flown).
        """
        disturbance_force = np.zeros(3) if disturbance_force is None else disturbance_force
        disturbance_torque = np.zeros(3) if disturbance_torque is None else disturbance_torque
        if self.ended:
            world = self._opened_world
            world.step(
                WorldInputs(
                    disturbance_force=disturbance_force, disturbance_torque=disturbance_torque
                )
            )
            self.outputs = world.outputs()
            return
        self._guarded(self._advance, disturbance_force, disturbance_torque, command)

    def close(self) -> dict[str, Any]:
        """End the run, close the world, write the records; return the summary."""
        if not self.ended:
            self._end("stopped", "closed before the end")
        linearisation = self._cw_error()
        self.summary = self._summary(wallclock.perf_counter() - self._started)
        if linearisation is not None:
            self.summary["cw_error_estimate_m"] = linearisation
        self._opened_world.close()
        try:
            for name, text in self._opened_mission.records().items():
                self.recorder.write_file(name, text)
            self.recorder.finish(self.summary)
            self._plot()
        except RecordingError as failure:
            if self.status != "failed":
                self._end("failed", str(failure))
                self.summary.update(status=self.status, reason=self.reason)
        self._hook("dcsim_run_end", run=self.info, summary=self.summary)
        return self.summary

    def _cw_error(self) -> float | None:
        """The estimated Clohessy–Wiltshire linearisation error of a ``cw`` run (m), said
        in an event and a warning when above ``world.orbit.cw_tolerance``; None for
        other worlds."""
        world_spec = self.scenario.world
        orbit = world_spec.orbit
        world = self._opened_world
        if world_spec.frame != "lvlh" or orbit.model != "cw":
            return None
        objects = [world.field.free_states(t)[0] for t in (0.0, world.time)]
        separation = max(
            self._max_separation,
            *(float(np.max(np.linalg.norm(p, axis=1), initial=0.0)) for p in objects),
        )
        error = cw_error_estimate(separation, world.time, orbit.semi_major_axis, orbit.mean_motion)
        if error > orbit.cw_tolerance:
            self._event(
                "cw_linearisation", error=error, tolerance=orbit.cw_tolerance, separation=separation
            )
            warnings.warn(
                f"Clohessy-Wiltshire may be off by up to {error:.3g} m here ({separation:.0f} m "
                f"from the chief for {world.time:.0f} s), more than world.orbit.cw_tolerance "
                f"({orbit.cw_tolerance:g} m); set world.orbit.model to two-body or j2 for the "
                "exact relative motion",
                CwValidityWarning,
                stacklevel=2,
            )
        return error

    def _plot(self) -> None:
        """Draw the run's pictures from its telemetry file."""
        if self.info.out_dir is None or not self.plots:
            return
        try:
            self._opened_mission.plot(
                self.info.out_dir,
                self.recorder.telemetry(max_points=PLOT_POINTS),
                self.recorder.events,
            )
        except OSError as error:
            raise RecordingError(f"cannot draw the plots: {error}") from error

    # ------------------------------------------------------------------ loop
    def _guarded(self, step: Callable[..., None], *args: Any) -> None:
        """Call ``step``; turn the ways a run ends into :attr:`status`."""
        try:
            step(*args)
        except _RunEnded as end:
            self._end(end.status, end.reason)
        except PluginFailure as failure:
            failure.time = self._opened_world.time
            self.failure = failure
            self._end("failed", str(failure))
            error = failure.problem if failure.error is None else str(failure.error)
            details: dict[str, Any] = (
                {} if failure.traceback is None else {"traceback": failure.traceback}
            )
            self._event(
                "plugin_failed",
                role=failure.role,
                plugin=failure.plugin,
                method=failure.method,
                error=error,
                **details,
            )
        except (HookFailure, RecordingError) as failure:
            self._end("failed", str(failure))

    def _end(self, status: str, reason: str) -> None:
        self.status, self.reason = status, reason
        self._commit_row()

    def _start(self) -> None:
        world = self._opened_world
        self.mission = self.mission_class(self.scenario, world, self.plugins, self._event)
        writes = self.recorder.out_dir is not None  # else scenario.yaml is not written
        scenario_yaml = dump_scenario(self.scenario) if writes else ""
        self.recorder.start(scenario_yaml, self._summary_head("running", ""))
        self._hook("dcsim_run_start", run=self.info)
        self._note_planner_models()
        # every tick's hook is called only when a plugin implements it
        self._step_observed = bool(self.setup.registry.hook.dcsim_run_step.get_hookimpls())
        if "localiser" in self.plugins:
            call_plugin(self.plugins, "localiser", "reset", self._prior(), 0.0)
        if "tracker" in self.plugins:
            call_plugin(self.plugins, "tracker", "reset", self.scenario.frame_dynamics, 0.0)
        call_plugin(self.plugins, "controller", "reset", world.robot_spec())
        self._robot_changes = world.robot_changes
        self.laps.start()
        self._decide()

    def _note_planner_models(self) -> None:
        """Record which planners plan with another orbit model than the world's."""
        world_model = self.scenario.frame_dynamics.model
        if world_model is None:
            return
        for role, source in self.setup.sources.items():
            models = getattr(self.plugins[role], "orbit_models", None)
            if source.kind not in _PLANNER_KINDS or models is None or world_model in models:
                continue
            name = source.name
            self._event(
                "planner_model_differs",
                role=role,
                plugin=name,
                world_model=str(world_model),
                planner_models=list(models),
            )
            warnings.warn(
                f"{role.replace('_', ' ')} {name!r} models {', '.join(models) or 'no'} orbital "
                f"dynamics, not the world's {world_model}: its plans are flown in a world it "
                "does not model (world.orbit.model)",
                PlannerModelWarning,
                stacklevel=2,
            )

    def _decide(self) -> None:
        """Sense, localise, run the mission and the controller at the current time."""
        world, mission = self._opened_world, self._opened_mission
        laps, plugins = self.laps, self.plugins
        t = world.time
        observations = world.observations()
        laps.lap("sensors")
        estimate = self.estimate = self._localise(observations)
        laps.lap("localiser")
        if "tracker" in plugins:
            observations = self._tracked(t, observations, estimate)
            laps.lap("tracker")
        self._reference = mission.tick(t, estimate, observations)
        laps.lap("mission")
        if world.robot_changes != self._robot_changes:  # a grab or a release
            self._robot_changes = world.robot_changes
            call_plugin(plugins, "controller", "reset", world.robot_spec())
        self.surroundings = mission.surroundings(observations)
        self._actuators = self._actuator_counts._replace(joints=len(observations.joint_positions))
        self._command = None
        if not self.controller_on_demand:
            self._controller_command()
        self._record(t, estimate, mission.mode)
        self._check_stop(t)
        laps.lap("recording")

    def _controller_command(self) -> Command:
        """The controller's command for the current control period, asked once (its time
        charged to the ``controller`` phase)."""
        if self._command is None:
            world = self._opened_world
            assert self.estimate is not None and self._reference is not None  # decided
            self._command = call_plugin(
                self.plugins,
                "controller",
                "command",
                world.time,
                self.estimate,
                self._reference,
                self.surroundings,
                actuators=self._actuators,
            )
            self.laps.lap("controller")
        return self._command

    def _localise(self, observations: Observations) -> StateEstimate:
        """The localiser's estimate now, or the true state when the mission flies without
        one; its attitude and rates are the sensors' readings (:func:`_with_readings`)
        unless the localiser estimates attitude from the star tracker and the gyros."""
        world, plugins = self._opened_world, self.plugins
        if "localiser" not in plugins:
            position, velocity, _, _ = world.base_state()
            truth = StateEstimate(
                world.time, position, velocity=velocity, covariance=_NO_SPREAD, converged=True
            )
            return _with_readings(truth, observations)
        if world.time > 0:
            call_plugin(plugins, "localiser", "predict", world.motion_input(), world.control_period)
        call_plugin(plugins, "localiser", "update", list(observations.ranges))
        own_attitude = (
            cast(Localiser, plugins["localiser"]).estimates_attitude
            and not world.sensing.ideal_attitude
        )
        if own_attitude:
            call_plugin(
                plugins,
                "localiser",
                "update_attitude",
                observations.star_tracker,
                observations.gyros,
            )
        estimate = call_plugin(plugins, "localiser", "estimate")
        return estimate if own_attitude else _with_readings(estimate, observations)

    def _tracked(
        self, t: float, observations: Observations, estimate: StateEstimate
    ) -> Observations:
        """``observations`` with the tracker's tracks, from its detections and ``estimate``."""
        tracks = call_plugin(
            self.plugins, "tracker", "update", t, observations.detections, estimate
        )
        return Observations.trusted(**{**observations.__dict__, "tracks": tracks})

    def _take_command(self, command: Command | Mapping[str, ArrayLike]) -> None:
        """Fly ``command`` (all of it, or the fields it maps) instead of the controller's
        this period, and record it as the tick's command."""
        if isinstance(command, Command):
            chosen = command
        else:
            fields = Command.__dataclass_fields__.keys()
            unknown = sorted(set(command) - fields)
            if unknown:
                raise ValueError(
                    f"a Command has no field {', '.join(unknown)} (it has {', '.join(fields)})"
                )
            # the controller gives the fields the mapping leaves out (none: not asked)
            rest = self._controller_command() if fields - set(command) else _NO_COMMAND
            try:
                values = {name: np.asarray(value, dtype=float) for name, value in command.items()}
                chosen = dataclasses.replace(rest, **values)
            except (TypeError, ValueError) as error:
                raise ValueError(f"the command is not a Command: {error}") from None
        problem = command_problem(chosen, self._actuators)
        if problem is not None:
            raise ValueError(f"the command {problem.removeprefix('returned ')}")
        self._command = self.outputs["command"] = chosen

    def _advance(
        self,
        disturbance_force: np.ndarray,
        disturbance_torque: np.ndarray,
        command: Command | Mapping[str, ArrayLike] | None = None,
    ) -> None:
        if self.controller_on_demand:
            self.laps.lap("agent")  # what the agent did since the period was decided
        if command is not None:
            self._take_command(command)
        flown = self._command
        if flown is None:  # asked on demand: no command was given
            flown = self.outputs["command"] = self._controller_command()
        self._commit_row()
        self.laps.lap("recording")
        inputs = WorldInputs(
            force=flown.force,
            torque=flown.torque,
            disturbance_force=disturbance_force,
            disturbance_torque=disturbance_torque,
            joint_torques=flown.joint_torques,
            thruster_on_times=flown.thruster_on_times,
            wheel_torques=flown.wheel_torques,
        )
        world = self._opened_world
        actuators = world.actuators
        seen = 0 if actuators is None else len(actuators.events)
        collisions = world.step(inputs)
        self.laps.lap("world")
        if actuators is not None:
            for event in actuators.events[seen:]:
                self._event(event.name, at=event.time, **event.data)
        for collision in collisions:
            self._event(
                "collision",
                at=collision.time,
                object=collision.object_id,
                body=collision.body,
                penetration=collision.penetration,
            )
            if self.scenario.stop.on_collision:
                self._record_final(self._opened_mission.mode)
                raise _RunEnded("stopped", f"collision with object {collision.object_id}")
        self._decide()

    def _report_progress(self) -> None:
        if self.progress is None:
            return
        mission = self._opened_mission
        self.progress(
            self._opened_world.time, self.scenario.world.duration, mission.mode, mission.progress()
        )

    def _check_stop(self, t: float) -> None:
        stop = self.scenario.stop
        finished = self._opened_mission.finished()
        if finished is None and t >= self.scenario.world.duration - 1e-9:
            finished = "completed", "duration reached"
        if (
            finished is None
            and stop.max_wall_time is not None
            and wallclock.perf_counter() - self._started > stop.max_wall_time
        ):
            finished = "stopped", f"wall-time limit of {stop.max_wall_time:g} s reached"
        if finished is not None:
            self._commit_row()  # the last row: no command follows
            raise _RunEnded(*finished)

    def _prior(self) -> Prior:
        """The localiser's initial belief: the true start, blurred by the stated sigmas."""
        initial = self.scenario.robot.initial
        rng = component_rng(self.scenario.world.seed, "prior")
        position = point_to_cartesian(initial.position) + rng.normal(0, initial.position_sigma, 3)
        velocity = np.asarray(initial.velocity) + rng.normal(0, initial.velocity_sigma, 3)
        return Prior(position, initial.position_sigma, velocity, initial.velocity_sigma)

    # ------------------------------------------------------------------ records
    def _record(self, t: float, estimate: StateEstimate, mode: str) -> None:
        """Take the world's outputs of this tick, with its command if it is known; its
        telemetry row is recorded once the command is sure (:meth:`_commit_row`)."""
        out = self.outputs = self._opened_world.outputs()
        out["command"] = self._command
        held = None if self._reference is None else self._reference.attitude
        out["attitude_error"] = math.nan if held is None else attitude_error(out["attitude"], held)
        self._pending = t, estimate, mode

    def _commit_row(self) -> None:
        """Record the current tick's telemetry row, its command (``outputs["command"]``)
        now known: the controller's, or what :meth:`advance` was given in its place."""
        pending, self._pending = self._pending, None
        if pending is None:
            return
        if self.outputs["command"] is None:  # the run ends before the controller was asked
            self.outputs["command"] = _NO_COMMAND
        row = self._telemetry_row(*pending, self.outputs)
        self._accumulate(self.outputs, pending[1])
        self.recorder.row(row)
        if self._step_observed:
            self._hook("dcsim_run_step", run=self.info, row=row)

    def _telemetry_row(
        self, t: float, estimate: StateEstimate, mode: str, out: dict[str, Any]
    ) -> dict[str, Any]:
        """One tick's telemetry row from the world's outputs and the estimate."""
        leading = (  # floats from tolist(): the same values, quicker
            t,
            *out["position"].tolist(),
            *out["velocity"].tolist(),
            *estimate.position.tolist(),
            *estimate.velocity.tolist(),
            *out["attitude"].tolist(),
            mode,
            int(estimate.converged),
        )
        row: dict[str, Any] = dict(zip(LEADING_COLUMNS, leading, strict=True))
        row.update(self._opened_mission.telemetry(out))
        trailing = (
            out["fuel_used"],
            out["delta_v"],
            out["nearest_obstacle_distance"],
            *out["command"].force.tolist(),
            *out["angular_velocity"].tolist(),
            *_position_sigmas(estimate.covariance),
            out["attitude_error"],
        )
        row.update(zip(TRAILING_COLUMNS, trailing, strict=True))
        if self._wheel_columns:
            momenta = out["wheel_momentum"].tolist()
            row.update(zip(self._wheel_columns, momenta, strict=True))
        if self._duty_columns:
            duty = out["thruster_duty"].tolist()
            row.update(zip(self._duty_columns, duty, strict=True))
        return row

    def _record_final(self, mode: str) -> None:
        """Record the state reached by the last step (the run ends after it), with the
        last estimate (no new one is made)."""
        assert self.estimate is not None  # every control period's decision makes one
        self._command = _NO_COMMAND
        self._record(self._opened_world.time, self.estimate, mode)
        self._commit_row()

    def _event(self, name: str, at: float | None = None, **data: Any) -> None:
        event = {"t": self._opened_world.time if at is None else at, "event": name, **data}
        self.recorder.event(event)
        self._hook("dcsim_run_event", run=self.info, event=event)

    def _hook(self, name: str, **kwargs: Any) -> None:
        try:
            getattr(self.setup.registry.hook, name)(**kwargs)
        except KeyboardInterrupt:
            raise
        except Exception as error:  # a hook implementation's own bug
            raise HookFailure(f"hook {name} raised: {type(error).__name__}: {error}") from error

    def _localiser_note(self) -> str:
        """Which localiser the estimate came from, or that it was the truth."""
        if "localiser" in self.plugins:
            return self.plugins["localiser"].name
        return "none: the mission was fed the true state"

    def _accumulate(self, outputs: dict[str, Any], estimate: StateEstimate) -> None:
        """Update the running figures of the summary with one recorded tick."""
        if estimate.converged and "localiser" in self.plugins:
            error = outputs["position"] - estimate.position
            self._squared_error_sum += float(error @ error)
            self._converged_rows += 1
        self._min_gap = min(self._min_gap, float(outputs["nearest_obstacle_distance"]))
        self._max_separation = max(self._max_separation, math.hypot(*outputs["position"]))

    def _summary_head(self, status: str, reason: str) -> dict[str, Any]:
        """The fields that say what ran and how it ended (or that it is running)."""
        return {
            "status": status,
            "reason": reason,
            "scenario": self.scenario.name,
            "mission": self.mission_class.type,
            "seed": self.scenario.world.seed,
        }

    def _hardware_summary(self) -> dict[str, Any]:
        """The reaction wheels' largest momentum as a fraction of their limit (each its
        own) over the whole run, and the propellant burnt for attitude (kg, with
        thrusters); nothing without the hardware."""
        world = self._opened_world
        fields: dict[str, Any] = {}
        if world.wheels is not None:
            fields["peak_wheel_momentum_fraction"] = world.wheels.peak_fraction
        if world.actuators is not None and world.actuators.thrusters is not None:
            fields["fuel_attitude_kg"] = world.attitude_fuel_used
            fields["fuel_translation_kg"] = world.fuel_used - world.attitude_fuel_used
        return fields

    def _summary(self, wall: float) -> dict[str, Any]:
        world, mission = self._opened_world, self._opened_mission
        assert self.status is not None  # close() ends the run before it sums it up
        sim_time = world.time
        rmse = (
            float(np.sqrt(self._squared_error_sum / self._converged_rows))
            if self._converged_rows
            else None
        )
        return {
            **self._summary_head(self.status, self.reason),
            "sim_time_s": sim_time,
            "wall_time_s": wall,
            "real_time_factor": sim_time / wall if wall > 0 else None,
            "outcome": mission.progress(),
            "goal_met": mission.goal_met(),
            **mission.summary_fields(),
            "collisions": len(world.collisions),
            "fuel_used_kg": world.fuel_used,
            "delta_v_mps": world.delta_v,
            "localisation_rmse_m": rmse,
            "min_obstacle_distance_m": self._min_gap if self.recorder.count else None,
            **self._hardware_summary(),
            "plugins": self.setup.plugin_versions(),
            "localiser": self._localiser_note(),
            "wall_time_by_phase_s": dict(sorted(self.laps.totals.items())),
        }


def actuator_counts(robot: RobotSection | ManipulatorSection) -> ActuatorCounts:
    """How many thrusters and reaction wheels the robot has (its joints are counted
    from its observations)."""
    thrusters, wheels = robot_hardware(robot)
    return ActuatorCounts(thrusters=len(thrusters), wheels=len(wheels))


def _position_sigmas(covariance: np.ndarray) -> list[float]:
    """Standard deviations (m) along x, y and z from the first three diagonal entries of
    an estimate's covariance (NaN for an axis a smaller covariance does not cover)."""
    variances = np.maximum(covariance.diagonal()[:3], 0.0)
    return [*np.sqrt(variances).tolist(), *[float("nan")] * (3 - len(variances))]


class _Readings(TypedDict):
    """The attitude sensors' and encoders' readings that an estimate carries."""

    attitude: Vector
    angular_velocity: Vector
    joint_positions: Vector
    joint_velocities: Vector


def _with_readings(estimate: StateEstimate, observations: Observations) -> StateEstimate:
    """The localiser's estimate with the attitude sensors' and encoders' readings.

    A plain :class:`StateEstimate` is copied without its checks (every tick): its own
    fields were checked when it was made, and the readings are the world's read-only
    arrays (PyBullet's unit quaternion, and as many joint rates as angles). A subclass
    a plugin returns is rebuilt through its constructor, so its own rules still apply.
    """
    readings: _Readings = {
        "attitude": observations.attitude,
        "angular_velocity": observations.angular_velocity,
        "joint_positions": observations.joint_positions,
        "joint_velocities": observations.joint_velocities,
    }
    if type(estimate) is StateEstimate:
        return StateEstimate.trusted(**{**estimate.__dict__, **readings})
    return dataclasses.replace(estimate, **readings)


def terminal_progress(stream: Any = None) -> Progress | None:
    """A progress line for an interactive terminal, or None when output is piped."""
    stream = stream or sys.stderr
    if not stream.isatty():
        return None

    def show(sim_time: float, duration: float, mode: str, mission_progress: str) -> None:
        fraction = min(sim_time / duration, 1.0)
        bar = "#" * int(30 * fraction)
        stream.write(
            f"\r[{bar:<30}] {100 * fraction:5.1f}%  t = {sim_time:7.1f} s  "
            f"{mode:<12}  {mission_progress} "
        )
        stream.flush()

    return show
