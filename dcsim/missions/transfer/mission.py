"""The ``transfer`` mission: from the robot's initial state to a goal region among obstacles.

The free-flyer problems of the source documents (the Boeing paper's grid search near a
space station, the kinodynamic RRT escape from an asteroid field, the ant colony among
spheres) share this shape. Modes::

    PLAN ──trajectory──► FLY ──inside the goal region, within its tolerances──► ARRIVED
      ▲ │ no path          │ strayed beyond tracking_tolerance
      │ ▼                  │
     HOLD ◄────────────────┘ (re-plans at once from the estimate)

Without a path planner (``path_planner: null``) the reference is the goal region's
centre from the start: the controller, or an agent flying through
:meth:`~dcsim.run.loop.Runner.advance`, flies there in FLY.

The path planner is asked once at the start and again from the current estimate when it
said "no path" (after ``retry`` seconds) or when the estimate strays from the trajectory
by more than ``tracking_tolerance``. The controller tracks the trajectory's full state
(position, velocity, attitude, angular velocity); per-segment forces and torques of the
trajectory are fed forward as accelerations. After ``max_plan_attempts`` "no path"
answers in a row the mission gives up and the run ends ``stopped`` with the reason.
"""

from __future__ import annotations

import io
import time as wallclock
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from dcsim.geometry import rotate
from dcsim.messages import (
    Bounds,
    CostWeights,
    NoPath,
    ObjectTrack,
    Observations,
    PathProblem,
    Reference,
    RobotSpec,
    RobotState,
    StateEstimate,
    Trajectory,
)
from dcsim.missions.base import Emit, Mission, MissionWorld
from dcsim.missions.transfer.settings import TransferMissionSection
from dcsim.registry.interfaces import Plugin
from dcsim.scenario.model import Scenario

_TRAJECTORY_HEADER = (
    "time_s,x_m,y_m,z_m,qx,qy,qz,qw,vx_mps,vy_mps,vz_mps,wx_radps,wy_radps,wz_radps,"
    "fx_N,fy_N,fz_N,tx_Nm,ty_Nm,tz_Nm"
)


class TransferMission(Mission):
    """Plans a path to the goal region, flies it, re-plans when needed, stops on arrival.

    Parameters
    ----------
    scenario : Scenario
        The resolved scenario; ``scenario.mission`` is a :class:`TransferMissionSection`.
    world : MissionWorld
        The world (its frame, the robot's properties).
    plugins : mapping of str to Plugin
        The path planner, the controller and, if the scenario names one, the localiser.
    emit : callable
        ``emit(event_name, **data)`` records an event.
    """

    type = "transfer"
    summary = "fly from the initial state to a goal region among obstacles"
    Settings = TransferMissionSection
    roles = ("path_planner", "controller")
    summary_names = (
        "reached",
        "time_to_goal_s",
        "planned_delta_v_mps",
        "planning_time_s",
        "replans",
        "nodes_expanded",
        "min_clearance_m",
        "max_tracking_error_m",
    )
    modes = ("PLAN", "HOLD", "FLY", "ARRIVED")
    columns = ("ref_x", "ref_y", "ref_z", "tracking_error", "goal_distance")
    units = dict.fromkeys(columns, "m")
    settings: TransferMissionSection

    def __init__(
        self, scenario: Scenario, world: MissionWorld, plugins: Mapping[str, Plugin], emit: Emit
    ) -> None:
        super().__init__(scenario, world, plugins, emit)
        self.goal = self.settings.goal.build()
        self.state = "PLAN"
        self.trajectory: Trajectory | None = None
        self.reference: Reference | None = None
        self.hold: RobotState | None = None
        self.retry_at = 0.0
        self.failures = 0
        self.reason = ""
        self.reached_at: float | None = None
        self.planned: list[Trajectory] = []
        self.planning_time = 0.0
        self.nodes_expanded = 0.0
        self.tracking_error = 0.0
        self.max_tracking_error = 0.0
        self.min_clearance = np.inf

    # ------------------------------------------------------------------ the tick
    @property
    def mode(self) -> str:
        """PLAN, HOLD, FLY or ARRIVED."""
        return self.state

    @property
    def safety_distance(self) -> float:
        """The least surface gap the controller is asked to keep, m."""
        return self.settings.safety_distance

    def tick(self, time: float, estimate: StateEstimate, observations: Observations) -> Reference:
        """Plan when needed, follow the trajectory, and check arrival."""
        state = estimate.as_state()
        if self.goal.contains(state):
            if self.reached_at is None:
                self.reached_at = time
                self.emit("arrived", time_to_goal=time)
            self._go("ARRIVED")
            return self._holding(state)
        if "path_planner" not in self.plugins:
            self._go("FLY")
            return self._toward_goal(time)
        if self.trajectory is None and time >= self.retry_at:
            self._plan(state, observations)
        if self.trajectory is None:
            return self._holding(state)
        reference = self._follow(self.trajectory, time)
        self.tracking_error = float(np.linalg.norm(reference.position - estimate.position))
        if self.tracking_error > self.settings.tracking_tolerance:
            self.emit("off_track", error=self.tracking_error)
            self._plan(state, observations)
            if self.trajectory is None:
                return self._holding(state)
            reference = self._follow(self.trajectory, time)
            self.tracking_error = float(np.linalg.norm(reference.position - estimate.position))
        return reference

    def finished(self) -> tuple[str, str] | None:
        """Completed in the goal region; stopped once planning is given up."""
        if self.reached_at is not None:
            return "completed", "goal reached"
        if self.failures >= self.settings.max_plan_attempts:
            return "stopped", f"no path after {self.failures} attempts: {self.reason}"
        return None

    # ------------------------------------------------------------------ planning
    def _plan(self, start: RobotState, observations: Observations) -> None:
        """Ask the path planner for a trajectory from ``start``."""
        self._go("PLAN")
        problem = transfer_problem(
            self.scenario, start, observations.obstacles(), self.world.robot_spec()
        )
        began = wallclock.perf_counter()
        result = self.call("path_planner", "plan", problem)
        self.planning_time += wallclock.perf_counter() - began
        if isinstance(result, NoPath):
            self.trajectory = None
            self.failures += 1
            self.reason = result.reason
            self.retry_at = start.time + self.settings.retry
            self.emit("no_path", reason=result.reason)
            self._go("HOLD")
            return
        self.failures = 0
        self.trajectory = result
        self.planned.append(result)
        self.nodes_expanded += float(result.statistics.get("nodes_expanded", 0.0))
        self.hold = None
        self.emit(
            "path",
            duration=result.duration,
            length=result.length,
            delta_v=result.delta_v,
            statistics=dict(result.statistics),
        )
        self.note_plan_end(start.time, float(result.times[-1]))
        self._go("FLY")

    # ------------------------------------------------------------------ references
    def _follow(self, trajectory: Trajectory, time: float) -> Reference:
        """The trajectory's state at ``time`` with its feed-forward (held after the end)."""
        state = trajectory.state_at(time)
        attitude = state.attitude if trajectory.attitudes is not None else self._held_attitude()
        acceleration, angular_acceleration = self._feed_forward(trajectory, time)
        self.reference = Reference(
            time=time,
            position=state.position,
            velocity=state.velocity,
            acceleration=acceleration,
            attitude=attitude,
            angular_velocity=state.angular_velocity,
            angular_acceleration=angular_acceleration,
        )
        return self.reference

    def _feed_forward(self, trajectory: Trajectory, time: float) -> tuple[np.ndarray, np.ndarray]:
        """Linear and angular acceleration that deliver, over the control period from
        ``time``, the impulse the trajectory's forces and torques give in that period
        (zero outside the trajectory): a burn that does not fill whole periods is neither
        lengthened nor cut short."""
        zero = np.zeros(3)
        if not trajectory.times[0] <= time < trajectory.times[-1]:
            return zero, zero
        period = self.scenario.world.control_period
        overlap = np.diff(np.clip(trajectory.times, time, time + period))  # s per segment
        spec = self.world.robot_spec()
        acceleration = (
            zero if trajectory.forces is None else overlap @ trajectory.forces / period / spec.mass
        )
        if trajectory.torques is None:
            return acceleration, zero
        attitude = (
            trajectory.attitude_at(time)
            if trajectory.attitudes is not None
            else self._held_attitude()
        )
        rotation = np.column_stack([rotate(attitude, axis) for axis in np.eye(3)])
        inertia = rotation @ spec.inertia @ rotation.T
        torque = overlap @ trajectory.torques / period
        return acceleration, np.linalg.solve(inertia, torque)

    def _held_attitude(self) -> np.ndarray:
        """The attitude held when the trajectory leaves it free: the goal's, or the start's."""
        if self.goal.attitude is not None:
            return self.goal.attitude
        initial = np.asarray(self.scenario.robot.initial.attitude, dtype=float)
        return initial / np.linalg.norm(initial)

    def _toward_goal(self, time: float) -> Reference:
        """The goal region's centre and velocity as the reference, attitude held: what
        the controller (or an agent) flies at without a path planner."""
        self.reference = Reference(
            time=time,
            position=self.goal.position,
            velocity=self.goal.velocity,
            attitude=self._held_attitude(),
        )
        return self.reference

    def _holding(self, state: RobotState) -> Reference:
        """Hold where the robot was when holding began, at rest, attitude held."""
        if self.hold is None:
            self.hold = state
        self.reference = Reference(
            time=state.time, position=self.hold.position, attitude=self._held_attitude()
        )
        return self.reference

    def _go(self, mode: str) -> None:
        if mode != self.state:
            self.emit("mode", previous=self.state, mode=mode)
            self.state = mode

    # ------------------------------------------------------------------ records
    def telemetry(self, outputs: Mapping[str, Any]) -> dict[str, Any]:
        """Reference position, tracking error and distance to the goal centre."""
        self.max_tracking_error = max(self.max_tracking_error, self.tracking_error)
        self.min_clearance = min(self.min_clearance, float(outputs["nearest_obstacle_distance"]))
        reference = self.reference.position if self.reference is not None else outputs["position"]
        return {
            "ref_x": float(reference[0]),
            "ref_y": float(reference[1]),
            "ref_z": float(reference[2]),
            "tracking_error": self.tracking_error,
            "goal_distance": float(np.linalg.norm(outputs["position"] - self.goal.position)),
        }

    def plot(
        self,
        out_dir: Path,
        telemetry: Mapping[str, np.ndarray],
        events: Sequence[Mapping[str, Any]],
    ) -> list[Path]:
        """Draw ``path.png`` and ``timeline.png`` into ``out_dir/plots``.

        See :func:`dcsim.missions.transfer.plots.write_transfer_plots`: the path with every
        obstacle in its true shape and the last planned trajectory (``trajectory.csv``,
        written before the plots), and a timeline marked with the events' mode changes
        and planner answers.
        """
        from dcsim.missions.transfer.plots import write_transfer_plots  # loads matplotlib

        return write_transfer_plots(
            out_dir, self.scenario, telemetry, events, self.modes, self.safety_distance
        )

    def progress(self) -> str:
        """Whether the goal is reached."""
        if self.reached_at is not None:
            return f"goal reached at t = {self.reached_at:.1f} s"
        return f"{len(self.planned)} plan(s), goal not reached"

    def goal_met(self) -> bool:
        """Whether the goal region was reached."""
        return self.reached_at is not None

    def summary_fields(self) -> dict[str, Any]:
        """Arrival, planning effort and tracking figures."""
        planned = self.planned[-1].delta_v if self.planned else None
        return {
            "reached": self.reached_at is not None,
            "time_to_goal_s": self.reached_at,
            "planned_delta_v_mps": planned,
            "planning_time_s": self.planning_time,
            "replans": max(len(self.planned) - 1, 0),
            "nodes_expanded": self.nodes_expanded,
            "min_clearance_m": self.min_clearance,
            "max_tracking_error_m": self.max_tracking_error,
        }

    def records(self) -> dict[str, str]:
        """``trajectory.csv``: the last planned trajectory, SI units in the header."""
        if not self.planned:
            return {}
        return {"trajectory.csv": trajectory_csv(self.planned[-1])}


def transfer_problem(
    scenario: Scenario, start: RobotState, obstacles: tuple[ObjectTrack, ...], robot: RobotSpec
) -> PathProblem:
    """The path problem the transfer mission poses from ``start``.

    Parameters
    ----------
    scenario : Scenario
        A transfer scenario: its goal, bounds, weights, limits, budget, safety distance
        (the planner's safety margin) and frame.
    start : RobotState
        Where the path starts (the mission's estimate).
    obstacles : tuple of ObjectTrack
        The obstacles in sensor range.
    robot : RobotSpec
        The robot's mass, inertia, radius and limits (cargo included).

    Returns
    -------
    PathProblem
        With the acceleration limit ``acceleration_fraction`` of the thrust-limited one
        and the angular acceleration the torque gives about the stiffest axis.
    """
    settings = scenario.mission_as(TransferMissionSection)
    bounds = None
    if settings.bounds is not None:
        bounds = Bounds(np.array(settings.bounds.lower), np.array(settings.bounds.upper))
    weights = settings.weights
    max_delta_v = np.inf if settings.max_delta_v is None else settings.max_delta_v
    return PathProblem(
        start=start,
        goal=settings.goal.build(),
        obstacles=obstacles,
        frame=scenario.frame_dynamics,
        robot_radius=robot.radius,
        robot_mass=robot.mass,
        max_speed=robot.max_speed,
        max_acceleration=settings.acceleration_fraction * robot.max_force / robot.mass,
        max_delta_v=max_delta_v,
        max_angular_acceleration=robot.max_torque
        / float(np.max(np.linalg.eigvalsh(robot.inertia))),
        bounds=bounds,
        weights=CostWeights(weights.delta_v, weights.length, weights.time),
        time_budget=settings.planning_budget,
        safety_margin=settings.safety_distance,
    )


def trajectory_csv(trajectory: Trajectory) -> str:
    """A trajectory as CSV: time, position, attitude, velocity, angular velocity, force, torque.

    Attitudes and angular velocities the trajectory leaves free are empty; so are the
    force and torque of the last sample (they hold over the segment after each sample).
    """
    n = len(trajectory.times)
    columns = [
        trajectory.times[:, None],
        trajectory.positions,
        _or_empty(trajectory.attitudes, n, 4),
        trajectory.velocities,
        _or_empty(trajectory.angular_velocities, n, 3),
        _padded(trajectory.forces, n),
        _padded(trajectory.torques, n),
    ]
    table = np.hstack(columns)
    out = io.StringIO()
    out.write(_TRAJECTORY_HEADER + "\n")
    for row in table:
        out.write(",".join("" if np.isnan(v) else repr(float(v)) for v in row) + "\n")
    return out.getvalue()


def _or_empty(values: np.ndarray | None, rows: int, width: int) -> np.ndarray:
    return np.full((rows, width), np.nan) if values is None else values


def _padded(values: np.ndarray | None, rows: int) -> np.ndarray:
    padded = np.full((rows, 3), np.nan)
    if values is not None:
        padded[:-1] = values
    return padded
