"""The ``capture`` mission: a space manipulator grasps a tumbling body and detumbles it.

Modes::

    ACQUIRE ─watched acquisition_time─► APPROACH ─base at the standoff─► OBSERVE
        ─watched, path planned─► INTERCEPT ─end effector on the fixture─► GRASP
        ─grip held─► DETUMBLE ─stack still─► CAPTURED

    ACQUIRE (target not tracked, no approach path, a start inside the keep-out off the
    approach line), OBSERVE (no path), GRASP (grip not held) ─► ABORT

- **ACQUIRE**: the robot holds at its start while the tracker follows the target, for
  ``acquisition_time`` (no wait for an exact track, under ideal object sensing); then
  the standoff point is chosen from the target's track, and the approach planner is
  asked for the base's flight to the gate. A target whose rotation is not tracked by
  then, or a refused flight, aborts the capture.
- **APPROACH**: the standoff point is ``standoff`` from the target's centre of mass
  along its angular momentum as the track gives it (the fixture's side) and
  ``standoff_height`` below it along the base's z axis. The base flies the approach
  planner's path to the gate on the same line, clear of the sphere the tumbling body
  sweeps by ``approach_clearance``, turning its arm side to face the target (if the
  path gives attitudes), then moves straight in along the axis to the standoff by a
  minimum-jerk move within ``approach_speed`` and ``approach_acceleration``, finishing
  the turn; the arm holds its start configuration. A robot that starts inside the
  keep-out is not planned for: on the line between standoff and gate it moves straight
  in, anywhere else the capture is aborted.
- **OBSERVE**: the base holds there for ``observation_time`` while the target's track
  is watched; then the path planner is asked for the end effector's trajectory onto
  the fixture (a :class:`~dcsim.messages.PathProblem` with a
  :class:`~dcsim.messages.GraspGoal` built from the target's track).
- **INTERCEPT**: the planned pose trajectory becomes joint references by closed-loop
  inverse kinematics (:class:`~dcsim.robots.pose_path.PosePath`, the base held).
- **GRASP**: from the planned grasp time the pads close; the grip counts as held once
  both pads have pressed with at least half the grip force and the bar has moved less
  than ``slip_speed`` relative to them for ``hold_time``. The latch then holds the body
  to the palm. If the planned trajectory ends first, the capture is aborted.
- **DETUMBLE**: the base holds its attitude and position at the latch and the arm its
  configuration (the controller's stiffness gives way to the loads); the stack is
  detumbled when the base's and the target's angular rates, as the robot senses them,
  both stay below ``detumbled_rate_deg_s`` for one second: the base's from its
  estimate, the target's as the palm's it is latched to (the base's rate and the
  joints' through the arm's Jacobian).

Any link of the arm other than the gripper's, or its base, that strikes the target is
named in an ``arm_contact`` event (once per link); the summary counts them
(``arm_links_struck``).

Telemetry (world frame, SI, true state): the bar's centre relative to the point between
the pads and its relative velocity, the pads' normal forces, the peak contact (or
latch) force and the contact impulse of each control period, the target's and the
base's angular rates and the base's turn from its attitude at the standoff.
"""

from __future__ import annotations

import dataclasses
import time as wallclock
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from dcsim.geometry import (
    attitude_error,
    quaternion_between,
    quaternion_multiply,
    rotate,
    slerp,
    unit,
)
from dcsim.messages import (
    GoalRegion,
    GraspGoal,
    NoPath,
    ObjectTrack,
    Observations,
    PathProblem,
    Reference,
    RobotState,
    Shape,
    ShapeKind,
    StateEstimate,
    Trajectory,
)
from dcsim.minimum_jerk import minimum_jerk_profile, shortest_duration
from dcsim.missions.base import Emit, Mission, MissionWorld, RoleKind
from dcsim.missions.capture.settings import CaptureMissionSection
from dcsim.registry.interfaces import Plugin
from dcsim.robots.kinematics import rotation_matrix
from dcsim.robots.manipulator import ManipulatorModel
from dcsim.robots.pose_path import PosePath
from dcsim.scenario.model import GripperSpec, ManipulatorSection, Scenario

TARGET_POSE_COLUMNS = (
    "target_x",
    "target_y",
    "target_z",
    "target_qx",
    "target_qy",
    "target_qz",
    "target_qw",
)
"""Telemetry columns of the target's centre of mass (m) and attitude (body to world,
``[x, y, z, w]``): what the viewer draws it from."""
_STILL_TIME = 1.0
"""Time (s) the stack's rates must stay below the detumbled rate."""
_PRESSING = 0.5
"""Fraction of the grip force each pad must press with for the grip to count."""


class CaptureMission(Mission):
    """Approaches a tumbling body, grasps its fixture, latches and detumbles the stack.

    Parameters
    ----------
    scenario : Scenario
        The resolved scenario; ``scenario.mission`` is a :class:`CaptureMissionSection`
        and ``scenario.robot`` a manipulator with a gripper.
    world : MissionWorld
        The world; it has a :class:`~dcsim.world.capture_rig.CaptureRig` (``capture``).
    plugins : mapping of str to Plugin
        The approach planner (a path planner for the base as a free flyer), the path
        planner of the arm's intercept and the controller (and a localiser, if the
        scenario names one).
    emit : callable
        ``emit(event_name, **data)`` records an event.
    """

    type = "capture"
    summary = "grasp a tumbling body with a space manipulator and detumble it"
    Settings = CaptureMissionSection
    roles = ("approach_planner", "path_planner", "controller")
    role_kinds = {"approach_planner": RoleKind("path_planner", "free-flyer")}
    modes = (
        "ACQUIRE",
        "APPROACH",
        "OBSERVE",
        "INTERCEPT",
        "GRASP",
        "DETUMBLE",
        "CAPTURED",
        "ABORT",
    )
    robots = ("manipulator",)
    columns = (
        "fixture_dx",
        "fixture_dy",
        "fixture_dz",
        "fixture_dvx",
        "fixture_dvy",
        "fixture_dvz",
        "pad_force_left",
        "pad_force_right",
        "contact_force",
        "impulse_x",
        "impulse_y",
        "impulse_z",
        "target_rate",
        "base_rate",
        "base_turn",
        *TARGET_POSE_COLUMNS,
    )
    units = {
        **dict.fromkeys(("fixture_dx", "fixture_dy", "fixture_dz"), "m"),
        **dict.fromkeys(("fixture_dvx", "fixture_dvy", "fixture_dvz"), "mps"),
        **dict.fromkeys(("pad_force_left", "pad_force_right", "contact_force"), "N"),
        **dict.fromkeys(("impulse_x", "impulse_y", "impulse_z"), "Ns"),
        **dict.fromkeys(("target_rate", "base_rate"), "radps"),
        "base_turn": "rad",
        **dict.fromkeys(TARGET_POSE_COLUMNS[:3], "m"),
    }

    @classmethod
    def telemetry_columns(cls, scenario: Scenario) -> tuple[str, ...]:
        """:attr:`columns`, then each joint's angle (``joint_1`` … ``joint_n``)."""
        return (*cls.columns, *_joint_columns(scenario))

    @classmethod
    def telemetry_units(cls, scenario: Scenario) -> dict[str, str]:
        """:attr:`units`, and radians for the joints."""
        return {**cls.units, **dict.fromkeys(_joint_columns(scenario), "rad")}

    summary_names = (
        "captured",
        "detumbled",
        "contact_time_s",
        "latch_time_s",
        "detumble_time_s",
        "planned_grasp_time_s",
        "planning_time_s",
        "peak_contact_force_N",
        "force_limit_exceeded",
        "max_base_turn_deg",
        "base_turn_exceeded",
        "final_target_rate_deg_s",
        "arm_links_struck",
    )
    settings: CaptureMissionSection

    def __init__(
        self, scenario: Scenario, world: MissionWorld, plugins: Mapping[str, Plugin], emit: Emit
    ) -> None:
        super().__init__(scenario, world, plugins, emit)
        rig = world.capture
        if rig is None:
            raise TypeError("a capture needs a world with a gripper and a tumbling body")
        self.rig = rig
        robot = scenario.robot
        assert isinstance(robot, ManipulatorSection) and robot.gripper is not None
        self.gripper = robot.gripper
        self.base_size = robot.size
        self.state = "ACQUIRE"
        self.start = world.robot_state()
        self.mount = np.array(robot.mount)
        self.standoff: _Standoff | None = None
        self.approach_path: Trajectory | None = None
        self.final_move: _StraightMove | None = None
        self.held_since: float | None = None
        self.still_since: float | None = None
        self.hold_reference: Reference | None = None
        self.path: PosePath | None = None
        self.planned_base: RobotState | None = None
        self.grasp_time: float | None = None
        self.standoff_attitude = self.start.attitude
        self.times: dict[str, float | None] = dict.fromkeys(
            ("contact", "latch", "detumbled", "observe"), None
        )
        self.planning_time = 0.0
        self.struck: set[int] = set()
        self.joint_columns = _joint_columns(scenario)
        self.reason = ""
        self.figures = {"peak_force": 0.0, "max_turn": 0.0, "target_rate": 0.0}

    # ------------------------------------------------------------------ the tick
    @property
    def mode(self) -> str:
        """The mode of the current control period."""
        return self.state

    def tick(self, time: float, estimate: StateEstimate, observations: Observations) -> Reference:
        """Advance the mode machine and give the reference of the coming period."""
        self._note_contact(time)
        if self.state == "ACQUIRE":
            return self._acquire(time, estimate, observations)
        if self.state == "APPROACH":
            return self._approach(time, estimate)
        if self.state == "OBSERVE":
            return self._observe(time, estimate, observations)
        if self.state in ("INTERCEPT", "GRASP"):
            return self._intercept(time, estimate)
        if self.state == "DETUMBLE":
            self._check_still(time, estimate)
        assert self.hold_reference is not None  # set on the way to DETUMBLE or ABORT
        return self.hold_reference

    def _acquire(
        self, time: float, estimate: StateEstimate, observations: Observations
    ) -> Reference:
        """Hold at the start until the target's track has been watched long enough, then
        choose the standoff from it and plan the approach from where the robot is."""
        track, missing = self._target_track(observations)
        exact = track is not None and track.covariance is None
        if exact or time - self.start.time >= self.settings.acquisition_time:
            if track is None:
                self._abort(missing)
            else:
                self._plan_approach(time, estimate.as_state(), track)
        return self._hold(self.start)

    def _plan_approach(self, time: float, start: RobotState, track: ObjectTrack) -> None:
        """Choose the standoff from the target's track and ask the approach planner for
        the flight to its gate, clear of the target's bounding sphere.

        The target's centre of mass is taken at rest where the track puts it now, as the
        standoff and the gate are: the capture does not follow a drifting body. A robot
        that starts inside the keep-out is not planned for: on the approach line it
        moves straight in, anywhere else the capture is aborted."""
        held = _held_radius(self._model(), start, self.base_size, self.gripper)
        clearance = self.settings.approach_clearance
        gate = max(self.settings.standoff, track.radius + held + 2.0 * clearance)
        self.standoff = standoff = _Standoff(start, track, self.settings, self.mount, gate)
        keep_out = track.radius + held + clearance
        distance = float(np.linalg.norm(start.position - track.position))
        if distance < keep_out:
            self._start_within_keep_out(time, start.position, distance, keep_out)
            return
        result = self._ask("approach_planner", self._approach_problem(start, track, held))
        if isinstance(result, NoPath):
            self._abort(f"no approach path: {result.reason}")
            return
        self.approach_path = result
        self.emit("approach_path", duration=result.duration, length=result.length)
        move_in = _move_duration(standoff.point - result.positions[-1], self.settings)
        self.note_plan_end(time, float(result.times[-1]) + move_in)
        self._go("APPROACH")

    def _approach_problem(self, start: RobotState, track: ObjectTrack, held: float) -> PathProblem:
        """The base's flight to the gate, as a free flyer of radius ``held`` (m), clear of
        the target's bounding sphere at rest by the approach clearance."""
        assert self.standoff is not None  # chosen first
        keep_out = dataclasses.replace(
            track,
            velocity=np.zeros(3),  # at rest, as the standoff and the gate take it
            motion=None,
            shape=Shape(ShapeKind.SPHERE, radius=track.radius),  # all a tumbling body sweeps
        )
        return PathProblem(
            start=start,
            goal=GoalRegion(position=self.standoff.gate, attitude=self.standoff.attitude),
            obstacles=(keep_out,),
            frame=self.scenario.frame_dynamics,
            robot_radius=held,
            robot_mass=self.world.robot_spec().mass,
            max_speed=self.settings.approach_speed,
            max_acceleration=self.settings.approach_acceleration,
            time_budget=self.settings.planning_budget,
            safety_margin=self.settings.approach_clearance,
        )

    def _start_within_keep_out(
        self, time: float, position: np.ndarray, distance: float, keep_out: float
    ) -> None:
        """Move straight in from a start inside the keep-out on the approach line; abort
        from anywhere else inside it, where a straight move could cross the tumble."""
        assert self.standoff is not None  # chosen first
        clearance = self.settings.approach_clearance
        if not self.standoff.on_approach_line(position, clearance):
            self._abort(
                f"the robot starts {distance:.2f} m from the target's centre, inside the "
                f"approach planner's keep-out of {keep_out:.2f} m and more than {clearance:g} m "
                "off the approach line between the standoff and the gate: start it farther "
                "out, or on that line"
            )
            return
        self.emit("approach_within_keep_out", distance=distance, keep_out=keep_out)
        move_in = _move_duration(self.standoff.point - position, self.settings)
        self.note_plan_end(time, time + self.scenario.world.control_period + move_in)
        self._go("APPROACH")

    def _ask(self, role: str, problem: PathProblem) -> Trajectory | NoPath:
        """One of the path planners' answer, its wall time added to the planning time; a
        refusal is recorded as a ``no_path`` event naming the role."""
        began = wallclock.perf_counter()
        result = self.call(role, "plan", problem)
        self.planning_time += wallclock.perf_counter() - began
        assert isinstance(result, Trajectory | NoPath)  # checked at the plugin boundary
        if isinstance(result, NoPath):
            self.emit("no_path", role=role, reason=result.reason)
        return result

    def _approach(self, time: float, estimate: StateEstimate) -> Reference:
        """The planned flight to the gate (none from the approach line inside the
        keep-out), then the straight move in to the standoff, from rest."""
        assert self.standoff is not None  # chosen on the way out of ACQUIRE
        path = self.approach_path
        if self.final_move is None:
            if path is not None and time < path.times[-1]:
                return self._follow_approach(path, time)
            origin = (  # the joints as at the start, as the planned flight holds them
                Reference(
                    time=time,
                    position=estimate.position,
                    attitude=estimate.attitude,
                    joint_positions=self.start.joint_positions,
                )
                if path is None
                else self._follow_approach(path, float(path.times[-1]))
            )
            self.final_move = _StraightMove(
                origin, self.standoff.point, self.standoff.attitude, self.settings
            )
        reference = self.final_move.reference(time)
        if time >= self.final_move.end_time:
            self.times["observe"] = time
            self.standoff_attitude = estimate.attitude
            self._go("OBSERVE")
        return reference

    def _follow_approach(self, path: Trajectory, time: float) -> Reference:
        """The approach path's state at ``time``, the arm held. A path that leaves the
        attitude free holds the start's, and the move in turns the base (the transfer
        mission holds the goal's instead: a transfer has no move after its path)."""
        assert self.standoff is not None  # chosen with the path
        state = path.state_at(time)
        return Reference(
            time=time,
            position=state.position,
            velocity=state.velocity,
            attitude=self.standoff.start_attitude if path.attitudes is None else state.attitude,
            angular_velocity=state.angular_velocity,
            joint_positions=self.start.joint_positions,
        )

    def _observe(
        self, time: float, estimate: StateEstimate, observations: Observations
    ) -> Reference:
        assert self.final_move is not None  # flown in APPROACH
        reference = self.final_move.reference(time)
        observed = self.times["observe"]
        assert observed is not None
        if time - observed >= self.settings.observation_time:
            self._plan(time, estimate, observations)
        return reference

    def _plan(self, time: float, estimate: StateEstimate, observations: Observations) -> None:
        """Ask the path planner for the end effector's intercept of the fixture."""
        track, missing = self._target_track(observations)
        if track is None:
            self._abort(missing)
            return
        start = estimate.as_state()
        result = self._ask("path_planner", self._problem(start, track))
        if isinstance(result, NoPath):
            self._abort(f"no path: {result.reason}")
            return
        try:
            self.path = PosePath(self._model(), start.configuration, result)
        except ValueError as error:
            self._abort(f"the path planner's answer cannot be followed: {error}")
            return
        self.planned_base = start
        self.grasp_time = float(result.statistics.get("grasp_time", result.times[-1]))
        self.emit(
            "path", duration=result.duration, length=result.length, grasp_time=self.grasp_time
        )
        self.note_plan_end(time, float(result.times[-1]))
        self._go("INTERCEPT")

    def _problem(self, start: RobotState, track: ObjectTrack) -> PathProblem:
        fixture = self.settings.target.fixture
        return PathProblem(
            start=start,
            goal=GoalRegion(position=track.position, tolerance=self.settings.grasp_tolerance),
            max_speed=self.settings.arm_speed,
            max_acceleration=self.settings.arm_acceleration,
            time_budget=self.settings.planning_budget,
            model=self._model(),
            grasp=GraspGoal(
                target=track,
                fixture=np.array(fixture.position),
                approach_axis=unit(fixture.approach_axis),
                bar_axis=unit(fixture.bar_axis),
                tool_offset=self.gripper.reach,
            ),
        )

    def _intercept(self, time: float, estimate: StateEstimate) -> Reference:
        """The arm on its planned path (the base held as it was at planning); the pads
        close at the grasp time and the grip is judged from then on."""
        path, base = self.path, self.planned_base
        assert path is not None and self.grasp_time is not None and base is not None
        sample = path.at(time)
        if self.state == "INTERCEPT" and time >= self.grasp_time:
            self.rig.gripper.command(True)
            self.emit("gripper_closing")
            self._go("GRASP")
        if self.state == "GRASP":
            self._judge_grip(time, estimate)
            if self.state == "GRASP" and time >= path.end_time:
                self._abort("the grip did not hold before the path ended")
        if self.hold_reference is not None:
            return self.hold_reference
        return Reference(
            time=time,
            position=base.position,
            attitude=base.attitude,
            joint_positions=sample.angles,
            joint_velocities=sample.rates,
            joint_accelerations=sample.accelerations,
        )

    def _judge_grip(self, time: float, estimate: StateEstimate) -> None:
        """Latch once the grip has held for ``hold_time``."""
        reading = self.rig.period.last
        _, velocity = self.rig.fixture_from_pads()
        pressing = reading is not None and bool(
            np.all(reading.normal >= _PRESSING * self.gripper.grip_force)
        )
        holding = pressing and float(np.linalg.norm(velocity)) <= self.settings.slip_speed
        if not holding:
            self.held_since = None
            return
        if self.held_since is None:
            self.held_since = time
        if time - self.held_since >= self.settings.hold_time:
            self.rig.latch()
            self.times["latch"] = time
            self.emit("latched", held_for=time - self.held_since)
            self.hold_reference = self._hold(estimate.as_state())
            self._go("DETUMBLE")

    def _check_still(self, time: float, estimate: StateEstimate) -> None:
        """Say the stack is detumbled once both sensed rates stay low for a second."""
        limit = np.radians(self.settings.detumbled_rate_deg_s)
        state = estimate.as_state()
        twist = self._model().jacobian(state.configuration) @ state.generalised_velocity
        palm_rate = twist[3:]  # the latched target's angular velocity, world frame
        still = (
            max(float(np.linalg.norm(state.angular_velocity)), float(np.linalg.norm(palm_rate)))
            <= limit
        )
        if not still:
            self.still_since = None
            return
        if self.still_since is None:
            self.still_since = time
        if time - self.still_since >= _STILL_TIME:
            self.times["detumbled"] = time
            self.emit("detumbled")
            self._go("CAPTURED")

    def _note_contact(self, time: float) -> None:
        if self.times["contact"] is None and not self.rig.target.free:
            self.times["contact"] = time
            self.emit("contact")
        struck = self.rig.period.struck - self.struck
        if struck:
            self.struck |= struck
            self.emit("arm_contact", links=sorted(self.rig.link_name(k) for k in struck))

    def _hold(self, state: RobotState) -> Reference:
        """Hold the base's pose and the joints where they are, at rest."""
        return Reference(
            time=state.time,
            position=state.position,
            attitude=state.attitude,
            joint_positions=state.joint_positions,
        )

    def _abort(self, reason: str) -> None:
        """Stop the capture: the robot holds where it is."""
        if self.hold_reference is None:
            self.hold_reference = self._hold(self.world.robot_state())
        self.reason = reason
        self.emit("abort", reason=reason)
        self._go("ABORT")

    def _go(self, mode: str) -> None:
        if mode != self.state:
            self.emit("mode", previous=self.state, mode=mode)
            self.state = mode

    def _model(self) -> ManipulatorModel:
        model = self.world.robot_spec().model
        assert isinstance(model, ManipulatorModel)
        return model

    def _target_track(self, observations: Observations) -> tuple[ObjectTrack | None, str]:
        """The target's track if it tracks the rotation too, else None and why not."""
        target_id = self.settings.target.id
        for track in observations.tracks:
            if track.id != target_id:
                continue
            if track.attitude is None or track.angular_velocity is None:
                return None, (
                    "the target's rotation is not tracked: its track has no attitude "
                    "(under an object sensor model, give it an attitude_noise so that it "
                    "measures poses)"
                )
            if track.inertia is None:
                return None, "the target's track has no inertia to predict its tumble with"
            return track, ""
        return None, "the target is not tracked (out of the object sensor's reach or view)"

    # ------------------------------------------------------------------ records
    def telemetry(self, outputs: Mapping[str, Any]) -> dict[str, Any]:
        """The columns of :attr:`columns` from the true state."""
        target = self.rig.target_state()
        offset, velocity = self.rig.fixture_from_pads(target)
        record = self.rig.period
        normal = record.last.normal if record.last is not None else np.zeros(2)
        base = self.world.robot_state()
        target_rate = float(np.linalg.norm(target.angular_velocity))
        turn = attitude_error(base.attitude, self.standoff_attitude)
        figures = self.figures
        figures["peak_force"] = max(figures["peak_force"], record.peak_force)
        if self.times["observe"] is not None:
            figures["max_turn"] = max(figures["max_turn"], turn)
        figures["target_rate"] = target_rate
        row = dict(zip(("fixture_dx", "fixture_dy", "fixture_dz"), offset.tolist(), strict=True))
        row.update(
            zip(("fixture_dvx", "fixture_dvy", "fixture_dvz"), velocity.tolist(), strict=True)
        )
        row.update(pad_force_left=float(normal[0]), pad_force_right=float(normal[1]))
        row.update(contact_force=record.peak_force)
        row.update(
            zip(("impulse_x", "impulse_y", "impulse_z"), record.impulse.tolist(), strict=True)
        )
        row.update(
            target_rate=target_rate,
            base_rate=float(np.linalg.norm(base.angular_velocity)),
            base_turn=turn,
        )
        pose = (*target.position.tolist(), *target.attitude.tolist())
        row.update(zip(TARGET_POSE_COLUMNS, pose, strict=True))
        angles = base.joint_positions.tolist()
        row.update(zip(self.joint_columns, angles, strict=True))
        return row

    def plot(
        self,
        out_dir: Path,
        telemetry: Mapping[str, np.ndarray],
        events: Sequence[Mapping[str, Any]],
    ) -> list[Path]:
        """Draw ``capture.png`` into ``out_dir/plots``
        (:func:`dcsim.missions.capture.plots.write_capture_plots`)."""
        from dcsim.missions.capture.plots import write_capture_plots  # loads matplotlib

        return write_capture_plots(out_dir, self.scenario, telemetry, events)

    def progress(self) -> str:
        """The mode and, once held, when."""
        if self.state == "CAPTURED":
            return f"captured and detumbled at t = {self.times['detumbled']:.1f} s"
        if self.state == "ABORT":
            return f"aborted: {self.reason}"
        return f"{self.state.lower()}"

    def finished(self) -> tuple[str, str] | None:
        """Completed once detumbled; stopped on an abort."""
        if self.state == "CAPTURED":
            return "completed", "target captured and detumbled"
        if self.state == "ABORT":
            return "stopped", self.reason
        return None

    def goal_met(self) -> bool:
        """Whether the target was captured and detumbled."""
        return self.state == "CAPTURED"

    def summary_fields(self) -> dict[str, Any]:
        """Capture, detumble, loads and the base's turn."""
        figures, times = self.figures, self.times
        latch, detumbled = times["latch"], times["detumbled"]
        return {
            "captured": latch is not None,
            "detumbled": detumbled is not None,
            "contact_time_s": times["contact"],
            "latch_time_s": latch,
            "detumble_time_s": None if detumbled is None or latch is None else detumbled - latch,
            "planned_grasp_time_s": self.grasp_time,
            "planning_time_s": self.planning_time,
            "peak_contact_force_N": figures["peak_force"],
            "force_limit_exceeded": figures["peak_force"] > self.gripper.force_limit,
            "max_base_turn_deg": float(np.degrees(figures["max_turn"])),
            "base_turn_exceeded": figures["max_turn"]
            > np.radians(self.settings.max_base_excursion_deg),
            "final_target_rate_deg_s": float(np.degrees(figures["target_rate"])),
            "arm_links_struck": len(self.struck | self.rig.period.struck),
        }


def _joint_columns(scenario: Scenario) -> tuple[str, ...]:
    """``joint_1`` … ``joint_n``: the arm's angles, as the reach mission records them."""
    robot = scenario.robot
    links = robot.links if isinstance(robot, ManipulatorSection) else []
    return tuple(f"joint_{i}" for i in range(1, len(links) + 1))


def _held_radius(
    model: ManipulatorModel, state: RobotState, size: Sequence[float], gripper: GripperSpec
) -> float:
    """Radius of a sphere about the base's centre of mass holding the base and the arm in
    ``state``'s configuration, m: the base's corners, the arm's frames, and the gripper's
    pads ahead of the last one."""
    kinematics = model.kinematics(state.configuration)
    frames = float(np.max(np.linalg.norm(kinematics.origins - kinematics.base_position, axis=1)))
    pads = gripper.reach + 0.5 * (gripper.opening + float(np.linalg.norm(gripper.pad_size)))
    return max(0.5 * float(np.linalg.norm(size)), frames + pads)


class _Standoff:
    """Where the base stops to reach for the fixture, and the gate its planned flight
    ends at.

    The standoff point lies on the target's angular momentum axis through its centre of
    mass, on the fixture's side: points of a tumbling body near that axis move least.
    A body that does not turn gives no axis; the fixture's approach axis stands in. The
    gate lies on the same line, ``gate_distance`` out; from it the base moves straight
    in along the axis, where the body does not sweep. The target is as its track gives
    it (position, attitude, angular velocity and inertia): ``track.attitude``,
    ``track.angular_velocity`` and ``track.inertia`` are set.

    Attributes
    ----------
    point, gate : ndarray (3,)
        The standoff point and the gate, world frame, m.
    attitude : ndarray (4,)
        The base's attitude there: its arm side (the mount's direction) facing the
        target, turned the least from ``start``'s.
    start_attitude : ndarray (4,)
        The attitude the approach starts from.
    """

    def __init__(
        self,
        start: RobotState,
        track: ObjectTrack,
        settings: CaptureMissionSection,
        mount: np.ndarray,
        gate_distance: float,
    ) -> None:
        assert track.attitude is not None and track.angular_velocity is not None
        assert track.inertia is not None  # _target_track answers only such tracks
        fixture = settings.target.fixture
        rotation = rotation_matrix(track.attitude)
        momentum = rotation @ track.inertia @ rotation.T @ track.angular_velocity
        out = rotation @ np.array(fixture.position)
        approach_axis = rotation @ np.array(fixture.approach_axis)
        axis = momentum if np.linalg.norm(momentum) > 1e-9 else approach_axis
        axis = axis / np.linalg.norm(axis)
        axis = axis if axis @ out >= 0.0 else -axis
        facing = rotate(start.attitude, mount) if np.linalg.norm(mount) > 0 else -axis
        self.start_attitude = start.attitude
        self.attitude = quaternion_multiply(quaternion_between(facing, -axis), start.attitude)
        below = settings.standoff_height * rotate(self.attitude, [0.0, 0.0, 1.0])
        self.point = track.position + settings.standoff * axis - below
        self.gate = track.position + gate_distance * axis - below

    def on_approach_line(self, position: np.ndarray, tolerance: float) -> bool:
        """Whether ``position`` (m, world frame) lies within ``tolerance`` (m) of the
        segment from the standoff point to the gate."""
        line = self.gate - self.point
        length = float(np.linalg.norm(line))
        along = (
            0.0
            if length == 0.0
            else float(np.clip((position - self.point) @ line / length**2, 0.0, 1.0))
        )
        return float(np.linalg.norm(position - (self.point + along * line))) <= tolerance


def _move_duration(offset: np.ndarray, settings: CaptureMissionSection) -> float:
    """Duration (s) of the base's minimum-jerk move by ``offset`` (m), from rest to rest
    within ``approach_speed`` and ``approach_acceleration``."""
    length = float(np.linalg.norm(offset))
    return max(
        shortest_duration(length, settings.approach_speed, settings.approach_acceleration),
        1e-9,
    )


class _StraightMove:
    """The base's move in to the standoff point from where its planned flight ended (the
    gate) or from its start on the approach line: a minimum-jerk move at rest at both
    ends within ``approach_speed`` and ``approach_acceleration``, turning onto the
    standoff's attitude if the flight has not, the joints held as ``origin``'s."""

    def __init__(
        self,
        origin: Reference,
        goal: np.ndarray,
        attitude: np.ndarray,
        settings: CaptureMissionSection,
    ) -> None:
        assert origin.attitude is not None and origin.joint_positions is not None
        self.origin, self.goal = origin.position, goal
        self.start_attitude, self.attitude = origin.attitude, attitude
        self.joints = origin.joint_positions
        self.start_time = origin.time
        self.duration = _move_duration(goal - origin.position, settings)
        self.end_time = self.start_time + self.duration

    def reference(self, time: float) -> Reference:
        """The base on its move at ``time`` (s), the joints held."""
        tau = (time - self.start_time) / self.duration
        shape, rate, curve = minimum_jerk_profile(tau, self.duration)
        offset = self.goal - self.origin
        return Reference(
            time=time,
            position=self.origin + shape * offset,
            velocity=rate * offset,
            acceleration=curve * offset,
            attitude=slerp(self.start_attitude, self.attitude, shape),
            joint_positions=self.joints,
        )
