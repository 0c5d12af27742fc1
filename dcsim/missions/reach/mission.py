"""The ``reach`` mission: a space manipulator's end effector from its start to a target.

The space manipulator thesis's experiment (its §7.4–7.5). Modes::

    PLAN ──end-effector path──► REACH ──path ended, end effector within tolerance──► ARRIVED
      │ no path
      ▼
     HOLD (the run ends stopped, with the planner's reason)

The path planner is asked once, from the estimate at the start, for the end effector's
path to the target (:class:`~dcsim.messages.PathProblem` with the robot's model: the
end effector's speed and acceleration limits, a goal region of radius ``tolerance``
about the target). Inverse kinematics turns the path into joint references
(:class:`~dcsim.robots.joint_path.JointPath`: resolved rates with the least joint
motion, the base held where it started); the controller is given the base's start pose
at rest and those joint angles, rates and accelerations. After the path's end the
references hold its last values; the run completes once the end effector is within
``tolerance`` of the target, or goes on to the scenario's duration.

Telemetry (world frame, SI units, true state): the end effector and its reference, the
tracking and target errors, every joint angle and its reference, det(J Jᵀ) of the arm's
position Jacobian, the angle between the base's target-facing side and the target, the
base's and the end effector's displacement from the start, the commanded base torque and
joint torques, and the robot's total linear and angular momentum (about the world's
origin).
"""

from __future__ import annotations

import time as wallclock
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from dcsim.geometry import facing_axis, sight_angle
from dcsim.messages import (
    GoalRegion,
    NoPath,
    Observations,
    PathProblem,
    Reference,
    RobotState,
    StateEstimate,
    Trajectory,
)
from dcsim.missions.base import Emit, Mission, MissionWorld
from dcsim.missions.reach.settings import ReachMissionSection
from dcsim.registry.interfaces import Plugin
from dcsim.robots.joint_path import JointPath, SingularPath
from dcsim.robots.manipulator import ManipulatorModel
from dcsim.scenario.model import ManipulatorSection, Scenario


class ReachMission(Mission):
    """Plans the end effector's path to the target, turns it into joint references, tracks.

    Parameters
    ----------
    scenario : Scenario
        The resolved scenario; ``scenario.mission`` is a :class:`ReachMissionSection` and
        ``scenario.robot`` a manipulator.
    world : MissionWorld
        The world, for the robot's model and the true state recorded in telemetry.
    plugins : mapping of str to Plugin
        The path planner, the controller and, if the scenario names one, the localiser.
    emit : callable
        ``emit(event_name, **data)`` records an event.
    """

    type = "reach"
    summary = "move a space manipulator's end effector to a target"
    Settings = ReachMissionSection
    roles = ("path_planner", "controller")
    summary_names = (
        "reached",
        "time_to_target_s",
        "path_duration_s",
        "planning_time_s",
        "final_target_distance_m",
        "max_ee_tracking_error_m",
        "max_joint_tracking_error_deg",
        "min_det_jjt",
        "max_target_angle_deg",
        "max_base_displacement_m",
        "ee_displacement_m",
    )
    modes = ("PLAN", "HOLD", "REACH", "ARRIVED")
    robots = ("manipulator",)
    settings: ReachMissionSection

    def __init__(
        self, scenario: Scenario, world: MissionWorld, plugins: Mapping[str, Plugin], emit: Emit
    ) -> None:
        super().__init__(scenario, world, plugins, emit)
        self.model = self._arm_model()
        self.target = np.asarray(self.settings.target, dtype=float)
        self.state = "PLAN"
        self.joint_path: JointPath | None = None
        self.base_reference: RobotState | None = None
        self.trajectory: Trajectory | None = None
        self.reference: Reference | None = None
        self.reference_end_effector: np.ndarray | None = None
        self.reason = ""
        self.reached_at: float | None = None
        self.planning_time = 0.0
        start = world.robot_state()
        self.start_base = start.position
        self.start_end_effector = self._end_effector(start)
        self.facing_axis = self._facing_axis(start)
        self.figures = _RunningFigures()

    @classmethod
    def telemetry_columns(cls, scenario: Scenario) -> tuple[str, ...]:
        """End effector, joints (one column each), singularity, sight, displacements,
        commanded torques and momentum."""
        return tuple(_column_units(scenario))

    @classmethod
    def telemetry_units(cls, scenario: Scenario) -> dict[str, str]:
        """Metres, radians (joints, joint error, sight angle), m⁶ (det(J Jᵀ) of the
        position rows), N·m (torques), N·s and N·m·s (linear and angular momentum)."""
        return {name: unit for name, unit in _column_units(scenario).items() if unit}

    # ------------------------------------------------------------------ the tick
    @property
    def mode(self) -> str:
        """PLAN, HOLD, REACH or ARRIVED."""
        return self.state

    def tick(self, time: float, estimate: StateEstimate, observations: Observations) -> Reference:
        """Plan at the start; then the joint references of the path at ``time``."""
        if self.state == "PLAN":
            self._plan(estimate.as_state())
        if self.joint_path is None:
            reference = self._holding(estimate)
            if self.state == "REACH":  # no path planner: whatever drives the arm reaches
                self._check_arrival(time, estimate)
            return reference
        sample = self.joint_path.at(time)
        self.reference_end_effector = sample.end_effector
        base = self.base_reference
        assert base is not None  # set by the plan the joint path follows
        self.reference = Reference(
            time=time,
            position=base.position,
            attitude=base.attitude,
            joint_positions=sample.angles,
            joint_velocities=sample.rates,
            joint_accelerations=sample.accelerations,
        )
        if time >= self.joint_path.end_time:
            self._check_arrival(time, estimate)
        return self.reference

    def _check_arrival(self, time: float, estimate: StateEstimate) -> None:
        """Say the target is reached, once, when the end effector is within tolerance."""
        if self.reached_at is not None:
            return
        distance = float(np.linalg.norm(self._end_effector(estimate) - self.target))
        if distance <= self.settings.tolerance:
            self.reached_at = time
            self.emit("arrived", time_to_target=time, distance=distance)
            self._go("ARRIVED")

    def finished(self) -> tuple[str, str] | None:
        """Completed at the target; stopped when there is no path."""
        if self.reached_at is not None:
            return "completed", "target reached"
        if self.state == "HOLD":
            return "stopped", f"no path: {self.reason}"
        return None

    def _arm_model(self) -> ManipulatorModel:
        """The world's model of the arm now (its base's mass follows the propellant used)."""
        model = self.world.robot_spec().model
        assert isinstance(model, ManipulatorModel)  # the mission flies only manipulators
        return model

    # ------------------------------------------------------------------ planning
    def _plan(self, start: RobotState) -> None:
        """Ask for the end effector's path and derive the joint references; the base is
        to stay where it is. Without a path planner (``path_planner: null``) the arm
        holds its start until something else drives it (an agent's joint torques)."""
        self.base_reference = start
        if "path_planner" not in self.plugins:
            self._go("REACH")
            return
        began = wallclock.perf_counter()
        result = self.call("path_planner", "plan", self._problem(start))
        self.planning_time += wallclock.perf_counter() - began
        if isinstance(result, NoPath):
            self._refuse(result.reason)
            return
        q = start.configuration
        try:
            self.joint_path = JointPath(self.model, q, result, gain=self.settings.ik_gain)
        except SingularPath as error:
            self._refuse(str(error))
            return
        except ValueError as error:  # a planner's malformed answer
            self._refuse(f"the path planner's answer cannot be followed: {error}")
            return
        self.trajectory = result
        self.emit("path", duration=result.duration, length=result.length)
        self.note_plan_end(start.time, float(result.times[-1]))
        self._go("REACH")

    def _problem(self, start: RobotState) -> PathProblem:
        return reach_problem(self.scenario, start, self.model)

    def _refuse(self, reason: str) -> None:
        self.reason = reason
        self.emit("no_path", reason=reason)
        self._go("HOLD")

    def _holding(self, estimate: StateEstimate) -> Reference:
        """Hold the configuration the robot had when holding began, at rest."""
        if self.reference is None:
            self.reference = Reference(
                time=estimate.time,
                position=estimate.position,
                attitude=estimate.attitude,
                joint_positions=estimate.joint_positions,
            )
        return self.reference

    def _go(self, mode: str) -> None:
        if mode != self.state:
            self.emit("mode", previous=self.state, mode=mode)
            self.state = mode

    # ------------------------------------------------------------------ geometry
    def _end_effector(self, state: RobotState) -> np.ndarray:
        return self.model.forward_kinematics(state.configuration).end_effector

    def _facing_axis(self, start: RobotState) -> np.ndarray:
        """The base-frame direction of the side that must face the target."""
        if self.settings.facing_axis is not None:
            return np.asarray(self.settings.facing_axis, dtype=float)
        return facing_axis(start.attitude, self.target - start.position)

    def _target_angle(self, state: RobotState) -> float:
        """Angle between the base's target-facing side and the target's direction, rad."""
        return sight_angle(state.attitude, self.facing_axis, self.target - state.position)

    # ------------------------------------------------------------------ records
    def telemetry(self, outputs: Mapping[str, Any]) -> dict[str, Any]:
        """The columns of :meth:`telemetry_columns` from the true state."""
        state = self.world.robot_state()
        q = state.configuration
        end_effector = self.model.forward_kinematics(q).end_effector
        reference = self.reference
        ref_end_effector = (
            end_effector if self.reference_end_effector is None else self.reference_end_effector
        )
        ref_joints = (
            state.joint_positions
            if reference is None or not reference.joint_positions.size
            else reference.joint_positions
        )
        momentum = self._arm_model().momentum(q, state.generalised_velocity)
        angular = momentum[3:] + np.cross(state.position, momentum[:3])
        command = outputs["command"]
        values = _Row(
            end_effector=end_effector,
            ref_end_effector=ref_end_effector,
            joints=state.joint_positions,
            ref_joints=ref_joints,
            det_jjt=self.model.det_jjt(q, position_only=True),
            target_angle=self._target_angle(state),
            base_displacement=float(np.linalg.norm(state.position - self.start_base)),
            ee_displacement=float(np.linalg.norm(end_effector - self.start_end_effector)),
            target_distance=float(np.linalg.norm(end_effector - self.target)),
        )
        tracking = self.state in ("REACH", "ARRIVED")
        self.figures.add(values, tracking)
        row = values.columns()
        row.update(zip(("tx", "ty", "tz"), command.torque, strict=True))
        torques = command.joint_torques if command.joint_torques.size else np.zeros(q.size - 7)
        row.update({f"joint_torque_{i}": float(v) for i, v in enumerate(torques, 1)})
        row.update(
            zip(("px", "py", "pz", "hx", "hy", "hz"), (*momentum[:3], *angular), strict=True)
        )
        return row

    def plot(
        self,
        out_dir: Path,
        telemetry: Mapping[str, np.ndarray],
        events: Sequence[Mapping[str, Any]],
    ) -> list[Path]:
        """Draw ``path.png``, ``timeline.png`` and ``joints.png`` into ``out_dir/plots``
        (:func:`dcsim.missions.reach.plots.write_reach_plots`)."""
        from dcsim.missions.reach.plots import write_reach_plots  # on use: it loads matplotlib

        return write_reach_plots(out_dir, self.scenario, telemetry, events)

    def progress(self) -> str:
        """Whether the target is reached."""
        if self.reached_at is not None:
            return f"target reached at t = {self.reached_at:.2f} s"
        return f"end effector {self.figures.target_distance:.4f} m from the target"

    def goal_met(self) -> bool:
        """Whether the end effector reached the target."""
        return self.reached_at is not None

    def summary_fields(self) -> dict[str, Any]:
        """Arrival, tracking errors and the thesis's path criteria."""
        figures = self.figures
        return {
            "reached": self.reached_at is not None,
            "time_to_target_s": self.reached_at,
            "path_duration_s": None if self.trajectory is None else self.trajectory.duration,
            "planning_time_s": self.planning_time,
            "final_target_distance_m": figures.target_distance,
            "max_ee_tracking_error_m": figures.max_ee_error,
            "max_joint_tracking_error_deg": float(np.degrees(figures.max_joint_error)),
            "min_det_jjt": figures.min_det,
            "max_target_angle_deg": float(np.degrees(figures.max_target_angle)),
            "max_base_displacement_m": figures.max_base_displacement,
            "ee_displacement_m": figures.ee_displacement,
        }


def _column_units(scenario: Scenario) -> dict[str, str]:
    """The mission's telemetry columns in order, each with its unit suffix."""
    robot = scenario.robot
    assert isinstance(robot, ManipulatorSection)  # other robots are refused before a run
    joints = range(1, len(robot.links) + 1)
    return {
        **dict.fromkeys(("ee_x", "ee_y", "ee_z", "ref_ee_x", "ref_ee_y", "ref_ee_z"), "m"),
        **dict.fromkeys(("ee_error", "target_distance"), "m"),
        **dict.fromkeys((f"joint_{i}" for i in joints), "rad"),
        **dict.fromkeys((f"ref_joint_{i}" for i in joints), "rad"),
        "joint_error": "rad",
        "det_jjt": "m6",
        "target_angle": "rad",
        **dict.fromkeys(("base_displacement", "ee_displacement"), "m"),
        **dict.fromkeys(("tx", "ty", "tz", *(f"joint_torque_{i}" for i in joints)), "Nm"),
        **dict.fromkeys(("px", "py", "pz"), "Ns"),
        **dict.fromkeys(("hx", "hy", "hz"), "Nms"),
    }


@dataclass(frozen=True)
class _Row:
    """One tick's geometric telemetry (everything but commands and momentum), true state."""

    end_effector: np.ndarray
    ref_end_effector: np.ndarray
    joints: np.ndarray
    ref_joints: np.ndarray
    det_jjt: float
    target_angle: float
    base_displacement: float
    ee_displacement: float
    target_distance: float

    @property
    def ee_error(self) -> float:
        """End-effector distance from its reference, m."""
        return float(np.linalg.norm(self.end_effector - self.ref_end_effector))

    @property
    def joint_error(self) -> float:
        """Largest joint angle error, rad."""
        return float(np.max(np.abs(self.ref_joints - self.joints), initial=0.0))

    def columns(self) -> dict[str, float]:
        """The row's telemetry columns."""
        row: dict[str, float] = {}
        row.update(zip(("ee_x", "ee_y", "ee_z"), self.end_effector, strict=True))
        row.update(zip(("ref_ee_x", "ref_ee_y", "ref_ee_z"), self.ref_end_effector, strict=True))
        row.update(ee_error=self.ee_error, target_distance=self.target_distance)
        row.update({f"joint_{i}": float(v) for i, v in enumerate(self.joints, 1)})
        row.update({f"ref_joint_{i}": float(v) for i, v in enumerate(self.ref_joints, 1)})
        row.update(
            joint_error=self.joint_error,
            det_jjt=self.det_jjt,
            target_angle=self.target_angle,
            base_displacement=self.base_displacement,
            ee_displacement=self.ee_displacement,
        )
        return row


class _RunningFigures:
    """The summary's figures, kept as the run goes (the telemetry is on disk)."""

    def __init__(self) -> None:
        self.max_ee_error = 0.0
        self.max_joint_error = 0.0
        self.min_det = np.inf
        self.max_target_angle = 0.0
        self.max_base_displacement = 0.0
        self.ee_displacement = 0.0
        self.target_distance = np.inf

    def add(self, row: _Row, tracking: bool) -> None:
        """Take one tick's row; tracking errors count only while a path is tracked."""
        if tracking:
            self.max_ee_error = max(self.max_ee_error, row.ee_error)
            self.max_joint_error = max(self.max_joint_error, row.joint_error)
        self.min_det = min(self.min_det, row.det_jjt)
        self.max_target_angle = max(self.max_target_angle, row.target_angle)
        self.max_base_displacement = max(self.max_base_displacement, row.base_displacement)
        self.ee_displacement = row.ee_displacement
        self.target_distance = row.target_distance


def reach_problem(scenario: Scenario, start: RobotState, model: Any) -> PathProblem:
    """The path problem a reach scenario poses from ``start``.

    Parameters
    ----------
    scenario : Scenario
        A reach scenario: its target, tolerance, limits and planning budget.
    start : RobotState
        The robot's state (base and joints) the path starts from.
    model : ManipulatorModel
        The robot's model, carried by the problem.

    Returns
    -------
    PathProblem
        For the end effector: a goal region of radius ``tolerance`` about the target, the
        end effector's speed and acceleration limits.
    """
    settings = scenario.mission_as(ReachMissionSection)
    return PathProblem(
        start=start,
        goal=GoalRegion(position=np.array(settings.target), tolerance=settings.tolerance),
        robot_radius=scenario.robot.radius,
        max_speed=settings.max_speed,
        max_acceleration=settings.max_acceleration,
        time_budget=settings.planning_budget,
        model=model,
    )
