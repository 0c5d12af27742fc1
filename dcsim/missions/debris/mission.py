"""The ``debris`` mission: the executer state machine of the source thesis.

Modes (the thesis's §2.2.1 and §5.2)::

    LOCALIZE ──converged──► DEVISE_PLAN ──plan──► SELECT_NEXT ──pickup──► MOVE_TO_NEXT
        ▲                        ▲                 │   ▲   drop              │ in reach
        │                        │ replan          ▼   │                     ▼
        └──── plan done ─────────┴──────────── MOVE_TO_DROP ◄──full/last── GRAB
                                  IDLE: converged, no target known

When a plan is done (the last drop of the plan made), the executer goes back to
LOCALIZE to plan afresh, or to IDLE when nothing is left to do: no target in sight and
no cargo on board (after the last delivery, say). Replanning happens when a new target
enters sensor range, a grab fails, or a pickup can no longer be met. After
``max_plan_attempts`` "no path" answers of the path planner in a row the executer gives
up and the run ends ``stopped`` with the planner's reason. Every mode change, plan,
grab, release and path failure is reported through the ``emit`` callback as an event.

Without a path planner (``path_planner: null``) the collector is given the target's
stand-off point, or the drop point, as it moves: the controller, or an agent flying
through :meth:`~dcsim.run.loop.Runner.advance`, flies there directly.

Every reference holds the collector's initial attitude, fixed in the world frame
(``mission.attitude: hold``, the default), or leaves it free (``free``).
"""

from __future__ import annotations

import enum
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from dcsim.geometry import length, row_lengths, unit
from dcsim.messages import (
    DropPoint,
    DropVisit,
    GoalRegion,
    NoPath,
    ObjectKind,
    ObjectTrack,
    Observations,
    PathProblem,
    Plan,
    PlanTask,
    Reference,
    StateEstimate,
    TaskRequest,
    Trajectory,
)
from dcsim.missions.base import Emit, Mission, MissionWorld
from dcsim.missions.debris.services import grab, release
from dcsim.missions.debris.settings import DebrisMissionSection
from dcsim.registry.interfaces import Plugin
from dcsim.scenario.model import Scenario
from dcsim.world.objects import ObjectStatus

#: Gap kept between carried cargo and a target being approached, m.
CARGO_CLEARANCE = 0.1

#: How far out of an obstacle's keep-out a held point is moved, as a multiple of the
#: keep-out's radius.
KEEP_OUT_EXIT = 1.1

#: Where a collector leaving a keep-out counts as out of it, as a multiple of the
#: keep-out's radius: half-way to the held point.
KEEP_OUT_LEFT = 0.5 * (1.0 + KEEP_OUT_EXIT)


class Mode(enum.IntEnum):
    """Mission modes, with the integer each is reported as."""

    LOCALIZE = 0
    DEVISE_PLAN = 1
    SELECT_NEXT = 2
    MOVE_TO_NEXT = 3
    GRAB = 4
    MOVE_TO_DROP = 5
    IDLE = 6


_INSTANT = {Mode.DEVISE_PLAN, Mode.SELECT_NEXT, Mode.GRAB}


class DebrisMission(Mission):
    """The executer: turns estimates and tracks into references, grabs and releases.

    Parameters
    ----------
    scenario : Scenario
        The resolved scenario (mission settings, robot limits).
    world : MissionWorld
        The world: its objects and the payload the grab and release services use.
    plugins : mapping of str to Plugin
        The plugin of each role in :attr:`roles`.
    emit : callable
        ``emit(event_name, **data)`` records an event.

    Attributes
    ----------
    drop_point : DropPoint
        Where cargo is delivered (the section's ``drop_point``).
    attitude : ndarray (4,) or None
        The attitude every reference holds ``[x, y, z, w]``; None leaves it free.
    """

    type = "debris"
    summary = "collect drifting targets and deliver them to a drop point (the debris thesis)"
    Settings = DebrisMissionSection
    roles = ("localiser", "task_planner", "path_planner", "controller")
    summary_names = ("targets", "captured", "delivered")
    modes = tuple(mode.name for mode in Mode)
    columns = ("carried", "delivered")
    settings: DebrisMissionSection

    def __init__(
        self, scenario: Scenario, world: MissionWorld, plugins: Mapping[str, Plugin], emit: Emit
    ) -> None:
        super().__init__(scenario, world, plugins, emit)
        self.robot = scenario.robot
        drop = self.settings.drop_point
        self.drop_point = DropPoint(drop.build(scenario.mean_motion), drop.tolerance)
        self.state = Mode.LOCALIZE
        self.known: dict[int, ObjectTrack] = {}
        self.planned: set[int] = set()
        self.steps: deque[PlanTask | DropVisit] = deque()
        self.task: PlanTask | None = None
        self.visit: DropVisit | None = None
        self.trajectory: Trajectory | None = None
        self.approach = np.zeros(3)
        self.hold: np.ndarray | None = None
        self.retry_at = -np.inf
        self.release_refused = False
        self.refusals = 0
        self.refusal = ""
        self.pickup_refused = False
        self.time = 0.0
        self._keep_outs_now: tuple[float, np.ndarray, np.ndarray] | None = None
        self.attitude = _held_attitude(scenario, self.settings.attitude)
        self._handlers: dict[Mode, Callable[[], Reference]] = {
            Mode.LOCALIZE: self._localize,
            Mode.IDLE: self._idle,
            Mode.DEVISE_PLAN: self._devise_plan,
            Mode.SELECT_NEXT: self._select_next,
            Mode.MOVE_TO_NEXT: self._move_to_next,
            Mode.GRAB: self._grab,
            Mode.MOVE_TO_DROP: self._move_to_drop,
        }

    # ------------------------------------------------------------------ tick
    @property
    def mode(self) -> str:
        """The executer's mode (a :class:`Mode` name)."""
        return self.state.name

    @property
    def safety_distance(self) -> float:
        """The thesis's SAFETY_DISTANCE, m."""
        return self.settings.safety_distance

    def tick(self, time: float, estimate: StateEstimate, observations: Observations) -> Reference:
        """Advance the state machine at ``time`` and return the reference to track."""
        self.time = time
        self.estimate = estimate
        self.visible = {t.id: t for t in observations.tracks}
        self.known.update(self.visible)
        for _ in range(len(Mode) + 2):
            before = self.state
            reference = self._step()
            if self.state is before or self.state not in _INSTANT:
                break
        if self.attitude is None:
            return reference
        return Reference.trusted(**{**reference.__dict__, "attitude": self.attitude})

    def telemetry(self, outputs: Mapping[str, Any]) -> dict[str, Any]:
        """Targets carried and delivered now."""
        return {"carried": outputs["carried"], "delivered": outputs["delivered"]}

    def plot(
        self,
        out_dir: Path,
        telemetry: Mapping[str, np.ndarray],
        events: Sequence[Mapping[str, Any]],
    ) -> list[Path]:
        """Draw the trajectory with every object's path, the timeline of modes (grabs
        and releases marked), then the motion and the estimation error
        (:func:`dcsim.missions.debris.plots.write_debris_plots`)."""
        from dcsim.missions.debris.plots import write_debris_plots  # loads matplotlib

        return write_debris_plots(
            out_dir, self.scenario, telemetry, events, self.modes, self.safety_distance
        )

    def progress(self) -> str:
        """Targets delivered out of all, and captured."""
        field = self.world.field
        delivered = field.count(ObjectStatus.REMOVED)
        captured = field.count(ObjectStatus.CARRIED) + delivered
        return f"delivered {delivered}/{int(field.is_target.sum())}, captured {captured}"

    def finished(self) -> tuple[str, str] | None:
        """Completed once every target is delivered, if the stop rules say so; stopped
        once the path planner has said "no path" ``max_plan_attempts`` times in a row."""
        if self.refusals >= self.settings.max_plan_attempts:
            return "stopped", f"no path after {self.refusals} attempts: {self.refusal}"
        field = self.world.field
        targets = int(field.is_target.sum())
        if (
            self.settings.stop_on_all_delivered
            and targets
            and field.count(ObjectStatus.REMOVED) == targets
        ):
            return "completed", "all targets delivered"
        return None

    def goal_met(self) -> bool:
        """Whether every target was delivered."""
        field = self.world.field
        return field.count(ObjectStatus.REMOVED) == int(field.is_target.sum())

    def summary_fields(self) -> dict[str, Any]:
        """Targets, and how many were captured and delivered."""
        field = self.world.field
        return {
            "targets": int(field.is_target.sum()),
            "captured": field.count(ObjectStatus.CARRIED) + field.count(ObjectStatus.REMOVED),
            "delivered": field.count(ObjectStatus.REMOVED),
        }

    def _go(self, mode: Mode, reason: str) -> None:
        if mode is not self.state:
            self.emit("mode", previous=self.state.name, mode=mode.name, reason=reason)
            self.state = mode
            self.hold = None

    def _step(self) -> Reference:
        return self._handlers[self.state]()

    # ------------------------------------------------------------------ helpers
    def _free_targets(self) -> list[ObjectTrack]:
        return [t for t in self.visible.values() if t.kind is ObjectKind.TARGET]

    def _obstacles(self) -> tuple[ObjectTrack, ...]:
        return tuple(t for t in self.visible.values() if t.kind is ObjectKind.OBSTACLE)

    def _max_acceleration(self) -> float:
        """Acceleration plans may count on, m/s²: a share of thrust over current mass."""
        return (
            self.settings.acceleration_fraction * self.robot.max_force / self.world.assembly_mass()
        )

    def _holding(self) -> Reference:
        """Hold where the robot was when it began to wait; after a path planner's
        refusal, moved out of any obstacle's keep-out it lies in (obstacles drift, and a
        planner refuses a start inside one)."""
        if self.hold is None:
            self.hold = np.array(self.estimate.position)
        if self.refusals > 0:
            self.hold = self._clear_of_obstacles(self.hold)
        return Reference(time=self.time, position=self.hold)

    def _keep_outs(self) -> tuple[np.ndarray, np.ndarray]:
        """Centres (k, 3) (m) and radii (k,) (m) now of the seen obstacles' keep-outs:
        each one's bounding sphere, the robot's radius and the safety distance (no
        smaller than a planner's keep-out of the obstacle's own shape); worked out once a
        tick (the wait's check and its held point both read them)."""
        if self._keep_outs_now is None or self._keep_outs_now[0] != self.time:
            obstacles = self._obstacles()
            clearance = self.world.robot_spec().radius + self.settings.safety_distance
            centres = np.array([t.predict(self.time)[0] for t in obstacles]).reshape(-1, 3)
            radii = np.array([t.radius + clearance for t in obstacles])
            self._keep_outs_now = (self.time, centres, radii)
        return self._keep_outs_now[1], self._keep_outs_now[2]

    def _clear_of_obstacles(self, point: np.ndarray) -> np.ndarray:
        """``point`` (m) as it is, or moved straight away from the centre of each
        obstacle whose keep-out it lies in, to :data:`KEEP_OUT_EXIT` times that
        keep-out's radius; passes are repeated while a move out of one keep-out lands in
        another, at most once per obstacle (the point may stay inside where keep-outs
        crowd it)."""
        centres, radii = self._keep_outs()
        for _ in range(len(radii)):
            offsets = point - centres
            distances = row_lengths(offsets)
            inside = np.flatnonzero(distances < radii)
            if not len(inside):
                break
            i = inside[0]  # away from its centre (along x from the centre itself: unit())
            point = centres[i] + KEEP_OUT_EXIT * radii[i] * unit(offsets[i])
        return point

    def _may_plan(self) -> bool:
        """Whether a path may be asked for now: not before the retry time and, after a
        refusal, not while the robot is still inside an obstacle's keep-out on its way
        to a held point clear of them all (a planner would refuse that start again). It
        counts as out at :data:`KEEP_OUT_LEFT` times a keep-out's radius, beyond the
        estimate's jitter; it waits no longer than its refusals would have taken
        (``max_plan_attempts`` times ``path_retry``), nor at all when keep-outs crowd
        the held point."""
        if self.time < self.retry_at:
            return False
        waited = self.time - self.retry_at
        patience = self.settings.max_plan_attempts * self.settings.path_retry
        if self.refusals == 0 or self.hold is None or waited >= patience:
            return True
        centres, radii = self._keep_outs()
        held_clear = bool(np.all(row_lengths(self.hold - centres) >= radii))
        distances = row_lengths(self.estimate.position - centres)
        return bool(np.all(distances >= KEEP_OUT_LEFT * radii)) or not held_clear

    def _new_target(self) -> ObjectTrack | None:
        return next((t for t in self._free_targets() if t.id not in self.planned), None)

    @property
    def plans_paths(self) -> bool:
        """Whether a path planner is asked for the way to each target and to the drop
        point; without one (``path_planner: null``) the references are the live
        stand-off and drop-point states themselves."""
        return "path_planner" in self.plugins

    def _plan_path(self, goal: GoalRegion, max_speed: float | None = None) -> Trajectory | None:
        """Ask the path planner for a way to ``goal`` at up to ``max_speed`` (the robot's)."""
        problem = PathProblem(
            start=self.estimate.as_state(self.time),
            goal=goal,
            obstacles=self._obstacles(),
            frame=self.scenario.frame_dynamics,
            robot_radius=self.world.robot_spec().radius,
            max_speed=self.robot.max_speed if max_speed is None else max_speed,
            max_acceleration=self._max_acceleration(),
            time_budget=self.settings.planning_budget,
            safety_margin=self.settings.safety_distance,
        )
        result = self.call("path_planner", "plan", problem)
        if isinstance(result, NoPath):
            self.emit("no_path", reason=result.reason)
            self.refusals += 1
            self.refusal = result.reason
            self.retry_at = self.time + self.settings.path_retry
            return None
        self.refusals = 0
        self.emit("path", duration=result.duration, length=result.length, delta_v=result.delta_v)
        return result

    def _follow(self, live: Callable[[], tuple[np.ndarray, np.ndarray]]) -> Reference:
        """Track the trajectory while it lasts, then the live goal state."""
        if self.trajectory is not None and self.time < self.trajectory.times[-1]:
            position, velocity = self.trajectory.sample(self.time)
        else:
            position, velocity = live()
        return Reference(time=self.time, position=position, velocity=velocity)

    # ------------------------------------------------------------------ modes
    def _localize(self) -> Reference:
        if self.estimate.converged:
            if self.world.carried_ids() or self._free_targets():
                self._go(Mode.DEVISE_PLAN, "localised")
            else:
                self._go(Mode.IDLE, "localised, no target in sight")
        return self._holding()

    def _idle(self) -> Reference:
        if self._free_targets() or self.world.carried_ids():
            self._go(Mode.DEVISE_PLAN, "target in sight")
        return self._holding()

    def _devise_plan(self) -> Reference:
        targets = tuple(self._free_targets())
        request = TaskRequest(
            time=self.time,
            robot=self.estimate,
            targets=targets,
            drop_point=self.drop_point,
            capacity=self.robot.capacity,
            carried=len(self.world.carried_ids()),
            max_speed=self.robot.max_speed,
            max_acceleration=self._max_acceleration(),
            time_budget=self.settings.planning_budget,
        )
        plan: Plan = self.call("task_planner", "plan", request)
        self.planned = {t.id for t in targets}
        self.steps = deque(_ordered_steps(plan))
        self.emit(
            "plan",
            tasks=[[t.target_id, t.pickup_time] for t in plan.tasks],
            drops=[[v.after_task, v.time] for v in plan.drop_visits],
            cost=plan.cost,
        )
        if self.steps:
            self._go(Mode.SELECT_NEXT, "plan ready")
        else:
            self._go(Mode.IDLE, "nothing to plan")
        return self._holding()

    def _plan_done(self, reason: str) -> None:
        """Leave a finished plan: IDLE when nothing is left to do, else LOCALIZE."""
        nothing_left = not (self._free_targets() or self.world.carried_ids())
        self._go(Mode.IDLE if nothing_left else Mode.LOCALIZE, reason)

    def _select_next(self) -> Reference:
        if not self.steps:
            self._plan_done("plan done")
            return self._holding()
        step = self.steps.popleft()
        self.trajectory = None
        if isinstance(step, DropVisit):
            self.visit = step
            self._go(Mode.MOVE_TO_DROP, "drop visit")
        else:
            self.task = step
            track = self.known[step.target_id]
            target_at_pickup = track.predict(step.pickup_time)[0]
            self.approach = unit(self.estimate.position - target_at_pickup)
            self.retry_at = -np.inf
            self.pickup_refused = False
            self._go(Mode.MOVE_TO_NEXT, f"pickup of target {step.target_id}")
        return self._holding()

    def _drop_speed(self) -> float:
        """Speed limit on the way to the drop point (DROP_SPEED), m/s."""
        drop_speed = self.settings.drop_speed or np.inf
        return min(self.robot.max_speed, drop_speed)

    def _standoff_gap(self) -> float:
        """Surface gap to hold from a target: half the reach, or clear of any cargo.

        Cargo sticks out of the collector on whatever side it was grabbed, and the
        assembly may turn, so with cargo on board the collector stops where the cargo
        cannot touch the target on any side, if that is within grab distance.
        """
        clear = self.world.cargo_protrusion() + CARGO_CLEARANCE
        return min(
            max(0.5 * self.settings.reach, clear), self.robot.grab_distance - CARGO_CLEARANCE
        )

    def _standoff(self, track: ObjectTrack, time: float) -> tuple[np.ndarray, np.ndarray]:
        position, velocity = track.predict(time)
        distance = self.robot.radius + track.sensed_radius + self._standoff_gap()
        return position + self.approach * distance, velocity

    def _move_to_next(self) -> Reference:
        task = self.task
        assert task is not None  # the pickup that selected this mode set it
        track = self.known[task.target_id]
        newcomer = self._new_target()
        if newcomer is not None:
            self._go(Mode.DEVISE_PLAN, f"new target {newcomer.id} in sight")
            return self._holding()
        if self.trajectory is None and self.plans_paths and self._may_plan():
            if self.pickup_refused:  # the pickup as planned has no path: plan the tasks anew
                self._go(Mode.DEVISE_PLAN, "no path to the pickup")
                return self._holding()
            goal_position, goal_velocity = self._standoff(track, task.pickup_time)
            arrive = task.pickup_time if task.pickup_time > self.time else None
            self.trajectory = self._plan_path(
                GoalRegion(goal_position, 0.5 * self.settings.reach, goal_velocity, arrive)
            )
            self.pickup_refused = self.trajectory is None
        if self.trajectory is None and self.plans_paths:
            if self.world.carried_ids():
                self.steps.clear()  # deliver what is on board, then plan afresh
                self.visit = None
                self._go(Mode.MOVE_TO_DROP, "no path to the target")
            elif self.time > task.pickup_time + self.settings.pickup_slack:
                self._go(Mode.DEVISE_PLAN, "pickup missed")
            return self._holding()
        target_position = track.predict(self.time)[0]
        gap = (
            length(self.estimate.position - target_position)
            - self.robot.radius
            - track.sensed_radius
        )
        if gap <= min(self._standoff_gap() + 0.5 * self.settings.reach, self.robot.grab_distance):
            self._go(Mode.GRAB, f"target {task.target_id} in reach")
        elif self.time > task.pickup_time + self.settings.pickup_slack:
            self.emit("pickup_missed", target=task.target_id, planned=task.pickup_time)
            self._go(Mode.DEVISE_PLAN, "pickup missed")
        return self._follow(lambda: self._standoff(track, self.time))

    def _grab(self) -> Reference:
        task = self.task
        assert task is not None  # the pickup that selected this mode set it
        result = grab(self.world, task.target_id, self.robot.capacity, self.robot.grab_distance)
        self.emit(
            "grab",
            target=result.target_id,
            success=result.success,
            reason=result.reason,
            gap=result.gap,
        )
        track = self.known[task.target_id]
        reference = Reference(self.time, *self._standoff(track, self.time))
        if not result.success:
            self._go(Mode.DEVISE_PLAN, "grab failed")
            return reference
        self.known.pop(task.target_id, None)
        self.trajectory = None
        full = len(self.world.carried_ids()) >= self.robot.capacity
        following = self.steps[0] if self.steps else None
        if isinstance(following, DropVisit):
            self.steps.popleft()
            self.visit = following
            self._go(Mode.MOVE_TO_DROP, "drop visit")
        elif full or not self.steps:
            self.visit = None
            self._go(Mode.MOVE_TO_DROP, "full" if full else "last pickup")
        else:
            self._go(Mode.SELECT_NEXT, "grabbed")
        return reference

    def _move_to_drop(self) -> Reference:
        drop = self.drop_point
        if self.trajectory is None and self.plans_paths and self._may_plan():
            arrive = self.visit.time if self.visit and self.visit.time > self.time else None
            position, velocity = drop.state_at(self.time if arrive is None else arrive)
            self.trajectory = self._plan_path(
                GoalRegion(position, 0.5 * drop.tolerance, velocity, arrive), self._drop_speed()
            )
            self.release_refused = False
        if self.trajectory is None and self.plans_paths:  # refused: wait for the retry
            followed = self._holding()
        else:
            followed = self._follow(lambda: drop.state_at(self.time))
        # The limit also holds once the trajectory is flown and the drop point is tracked.
        reference = Reference.trusted(**{**followed.__dict__, "max_speed": self._drop_speed()})
        distance = length(self.estimate.position - drop.state_at(self.time)[0])
        if distance <= self.settings.release_fraction * drop.tolerance:
            result = release(self.world, drop)
            if result.delivered or not self.world.carried_ids():
                self.emit("release", delivered=list(result.delivered), reason=result.reason)
                self.trajectory = None
                self.visit = None
                if self.steps:
                    self._go(Mode.SELECT_NEXT, "delivered")
                else:
                    self._plan_done("delivered")
            elif not self.release_refused:
                self.emit("release", delivered=[], reason=result.reason)
                self.release_refused = True
        return reference


def _held_attitude(scenario: Scenario, attitude: str) -> np.ndarray | None:
    """The attitude the collector holds ``[x, y, z, w]`` (its initial one, unit length),
    or None when the mission leaves it free."""
    if attitude == "free":
        return None
    initial = np.asarray(scenario.robot.initial.attitude, dtype=float)
    held = initial / np.linalg.norm(initial)
    held.setflags(write=False)  # given to every reference as it is
    return held


def _ordered_steps(plan: Plan) -> list[PlanTask | DropVisit]:
    """A plan as the sequence of pickups and drop visits the collector flies."""
    drops = {visit.after_task: visit for visit in plan.drop_visits}
    steps: list[PlanTask | DropVisit] = [drops[-1]] if -1 in drops else []
    for index, task in enumerate(plan.tasks):
        steps.append(task)
        if index in drops:
            steps.append(drops[index])
    return steps
