"""Checks specific to each plugin kind (sensor model, tracker, localiser, task planner, path
planner, controller)."""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from functools import partial

import numpy as np

from dcsim.geometry import (
    quaternion_conjugate,
    quaternion_from_matrix,
    quaternion_from_rotation_vector,
    quaternion_multiply,
    rotation_vector,
)
from dcsim.messages import (
    AttitudeReading,
    BeaconRange,
    Detection,
    NoPath,
    ObjectTrack,
    PathProblem,
    RateReading,
    Reference,
    RobotState,
    SensedTruth,
    SensorSetup,
    StateEstimate,
    Surroundings,
    Trajectory,
)
from dcsim.registry.answers import ActuatorCounts
from dcsim.registry.interfaces import SENSOR_SLOTS, Controller, PathPlanner, Plugin, TaskPlanner
from dcsim.testing import problems
from dcsim.testing.contracts import (
    LOCALISER_ERROR_BOUND,
    TIME_SLACK,
    checked_answer,
    contract,
    fail,
    make,
    not_derived,
    problem_robot,
    run_plugin,
    standard_inputs,
)
from dcsim.testing.manipulator import simulate
from dcsim.yardsticks.clearance import RESOLUTION, path_clearance

START_TOLERANCES = (1e-6, 1e-9, 1e-6)
"""How far a trajectory may start from the start state: position (m), time (s), attitude (rad)."""
_START_TEXT = "{:g} µm, {:g} ns and, when it gives attitudes, {:g} µrad".format(
    *np.multiply(START_TOLERANCES, (1e6, 1e9, 1e6))
)

ACCELERATION_TOLERANCE = 0.01
"""Fraction by which the sampled acceleration may exceed ``max_acceleration``."""

# --------------------------------------------------------------------- sensor model


@contract(
    "measures_a_sensor_slot",
    f"`measures` names one of the robot's sensors ({', '.join(SENSOR_SLOTS)}), the slot "
    "a scenario gives the model under `sensors:`",
    kinds=("sensor",),
)
def check_sensor_slot(plugin_class: type[Plugin]) -> None:
    measures = getattr(plugin_class, "measures", None)
    if measures not in SENSOR_SLOTS:
        fail(f"measures {measures!r}; a sensor model measures one of {', '.join(SENSOR_SLOTS)}")


def _reading_times(
    reading: BeaconRange | AttitudeReading | RateReading | tuple | None,
) -> list[float]:
    """The times a reading says it was made (beacon ranges carry none)."""
    items = reading if isinstance(reading, tuple) else (reading,)
    return [
        item.time for item in items if isinstance(item, (AttitudeReading, RateReading, Detection))
    ]


def _unseen(reading: object, setup: SensorSetup, truth: SensedTruth) -> str | None:
    """What a reading reports that its sensor cannot see, in words, or None: a beacon
    that is not one of the setup's, an object that is not known, not free, or beyond the
    object sensor's range."""
    items = reading if isinstance(reading, tuple) else ()
    known = {obj.id: index for index, obj in enumerate(setup.objects)}
    for item in items:
        if isinstance(item, BeaconRange) and not 0 <= item.beacon_id < len(setup.beacons):
            return f"a range to beacon {item.beacon_id}; the setup has {len(setup.beacons)}"
        if isinstance(item, Detection):
            index = known.get(item.id)
            if index is None:
                return f"object {item.id}, which is not one of the setup's objects"
            if not truth.free[index]:
                return f"object {item.id}, which is not free (held or delivered)"
            distance = float(np.linalg.norm(truth.object_positions[index] - truth.position))
            if distance > setup.object_range:
                return f"object {item.id} {distance:.1f} m away, beyond {setup.object_range:g} m"
    return None


@contract(
    "reads_its_sensor",
    "over 20 s of the standard sensing problem (10 Hz; five beacons; four objects within "
    "the object sensor's 30 m, one of them held after 10 s, and one 55 m off) every "
    "`measure` answer is what its slot says (`dcsim.api.SENSOR_SLOTS`), made no later "
    "than the truth's time, and reports only what the sensor can see (the setup's "
    "beacons; known, free objects within range); and the sensor gives at least one reading",
    kinds=("sensor",),
)
def check_sensor_readings(plugin_class: type[Plugin]) -> None:
    setup, truths = problems.sensor_setup(), problems.sensed_truths()
    readings = run_plugin(plugin_class, [setup, truths], "the standard sensing problem")
    for truth, reading in zip(truths, readings, strict=True):
        late = [t for t in _reading_times(reading) if t > truth.time]
        if late:
            fail(f"at t = {truth.time:g} s it gave a reading made at {late[0]:g} s, in the future")
        unseen = _unseen(reading, setup, truth)
        if unseen is not None:
            fail(f"at t = {truth.time:g} s it reported {unseen}")
    if all(reading is None or reading == () for reading in readings):
        fail(f"it gave no reading in {len(truths)} ticks ({truths[-1].time:g} s)")


# --------------------------------------------------------------------- tracker

TRACK_GATE = 14.16
"""Squared Mahalanobis distance within which a 3-dof Gaussian error lies 99.73 % of the
time (three standard deviations)."""

TRACK_INSIDE = 0.95
"""Fraction of a tracker's position errors after start-up that must lie within
:data:`TRACK_GATE` of their covariance."""

TRACK_START = 5.0
"""Start-up time of the standard tracking problem not scored, s."""


def _track(
    plugin_class: type[Plugin],
) -> tuple[list[tuple[ObjectTrack, ...]], problems.TrackerProblem]:
    problem = problems.tracker_problem()
    inputs = [
        problem.frame,
        problem.start_time,
        [(tick.time, tick.detections, tick.robot) for tick in problem.ticks],
    ]
    return run_plugin(plugin_class, inputs, "the standard tracking problem"), problem


def _covariance_problem(track: ObjectTrack) -> str | None:
    """What is wrong with a track's covariance, or None."""
    c = track.covariance
    if c is None:
        return "has no covariance"
    scale = max(float(np.abs(c).max()), 1e-300)
    if np.abs(c - c.T).max() > 1e-9 * scale:
        return f"has a covariance that is not symmetric:\n{c}"
    if np.linalg.eigvalsh(0.5 * (c + c.T)).min() < -1e-9 * scale:
        return f"has a covariance with a negative eigenvalue:\n{c}"
    return None


@contract(
    "keeps_the_detected_objects",
    "on the standard tracking problem (five objects drifting in an orbit's LVLH frame, "
    "detected at 10 Hz for 30 s, one of them for 15 s only), each answer holds one track "
    "of every object detected at that tick, tracks of detected objects only, each with a "
    "symmetric positive semi-definite 6×6 covariance, the tick's time and a shape margin "
    "from 0 to its radius (its sensed radius, radius less margin, not negative)",
    kinds=("tracker",),
)
def check_detected_kept(plugin_class: type[Plugin]) -> None:
    answers, problem = _track(plugin_class)
    ever: set[int] = set()
    for tick, tracks in zip(problem.ticks, answers, strict=True):
        ever |= set(tick.truth)
        ids = [track.id for track in tracks]
        if len(ids) != len(set(ids)):
            fail(f"at t = {tick.time:g} s it gave two tracks of one object: ids {ids}")
        if set(tick.truth) - set(ids) or set(ids) - ever:
            fail(
                f"at t = {tick.time:g} s it gave tracks of {sorted(ids)} for detections of "
                f"{sorted(tick.truth)} (objects detected so far: {sorted(ever)})"
            )
        for track in tracks:
            problem_text = _covariance_problem(track)
            if problem_text is not None:
                fail(f"at t = {tick.time:g} s the track of object {track.id} {problem_text}")
            if track.time != tick.time:
                fail(
                    f"at t = {tick.time:g} s the track of object {track.id} is for "
                    f"t = {track.time:g} s"
                )
            if not 0.0 <= track.shape_margin <= track.radius:
                fail(
                    f"at t = {tick.time:g} s the track of object {track.id} has a shape "
                    f"margin of {track.shape_margin!r} m for a radius of {track.radius!r} m"
                )


@contract(
    "follows_within_its_covariance",
    f"on the standard tracking problem (5 cm detection noise, 2 cm on the robot's "
    f"position), after {TRACK_START:g} s at least {100 * TRACK_INSIDE:g} % of the detected "
    "objects' tracks are within three standard deviations of the true position by their "
    f"own position covariance (squared Mahalanobis distance ≤ {TRACK_GATE}, chi-square "
    "with 3 degrees of freedom), and none is more than 0.5 m off",
    kinds=("tracker",),
)
def check_tracks_follow(plugin_class: type[Plugin]) -> None:
    answers, problem = _track(plugin_class)
    inside, scored = 0, 0
    for tick, tracks in zip(problem.ticks, answers, strict=True):
        if tick.time < TRACK_START:
            continue
        for track in tracks:
            truth = tick.truth.get(track.id)
            if truth is None or track.covariance is None:
                continue
            error = track.position - truth
            miss = float(np.linalg.norm(error))
            if miss > 0.5:
                fail(f"at t = {tick.time:g} s the track of object {track.id} is {miss:.3f} m off")
            try:
                distance = float(error @ np.linalg.solve(track.covariance[:3, :3], error))
            except np.linalg.LinAlgError:
                fail(
                    f"at t = {tick.time:g} s the track of object {track.id} has a singular "
                    "position covariance"
                )
            inside += distance <= TRACK_GATE
            scored += 1
    if scored == 0 or inside < TRACK_INSIDE * scored:
        fail(
            f"{inside} of {scored} position errors after {TRACK_START:g} s are within three "
            f"standard deviations of the tracks' covariances; at least {100 * TRACK_INSIDE:g} % "
            "must be"
        )


# --------------------------------------------------------------------- localiser


def _localise(plugin_class: type[Plugin]) -> tuple[list[StateEstimate], problems.BeaconProblem]:
    problem = problems.beacon_problem()
    inputs = [
        problem.prior,
        problem.start_time,
        [(s.motion, s.dt, list(s.ranges)) for s in problem.steps],
    ]
    return run_plugin(plugin_class, inputs, "the standard beacon problem"), problem


@contract(
    "converges",
    f"on the standard beacon problem, from a prior 50 m wide, the final position error is below "
    f"{LOCALISER_ERROR_BOUND} m and the estimate reports converged",
    kinds=("localiser",),
)
def check_convergence(plugin_class: type[Plugin]) -> None:
    estimates, problem = _localise(plugin_class)
    final = estimates[-1]
    error = float(np.linalg.norm(final.position - problem.steps[-1].truth))
    if error >= LOCALISER_ERROR_BOUND:
        fail(f"final position error {error:.3f} m after {len(estimates)} updates")
    if not final.converged:
        fail(f"the estimate never reported converged (final error {error:.3f} m)")


@contract(
    "covariance_is_valid",
    "every reported covariance is symmetric and positive semi-definite",
    kinds=("localiser",),
)
def check_covariance(plugin_class: type[Plugin]) -> None:
    estimates, _ = _localise(plugin_class)
    for index, estimate in enumerate(estimates):
        c = estimate.covariance
        scale = max(float(np.abs(c).max()), 1e-300)
        if np.abs(c - c.T).max() > 1e-9 * scale:
            fail(f"covariance {index} is not symmetric:\n{c}")
        if np.linalg.eigvalsh(0.5 * (c + c.T)).min() < -1e-9 * scale:
            fail(f"covariance {index} has a negative eigenvalue:\n{c}")


# --------------------------------------------------------------------- task planner


def _plan(plugin_class: type[Plugin], request=None):
    request = request or problems.task_request()
    return run_plugin(plugin_class, [request], "the standard task request")[0], request


@contract(
    "plans_known_targets_once",
    "every planned target is one of the request's targets, and none is planned twice",
    kinds=("task_planner",),
)
def check_known_targets(plugin_class: type[Plugin]) -> None:
    plan, request = _plan(plugin_class)
    known = {t.id for t in request.targets}
    ids = [task.target_id for task in plan.tasks]
    if set(ids) - known:
        fail(f"planned unknown targets {sorted(set(ids) - known)}; the request has {sorted(known)}")
    if len(ids) != len(set(ids)):
        fail(f"planned a target more than once: {ids}")


def _events(plan) -> list[tuple[float, str]]:
    """Pickups and drop visits in flying order, as (time, label)."""
    drops = {visit.after_task: visit for visit in plan.drop_visits}
    events = [(drops[-1].time, "drop before the first pickup")] if -1 in drops else []
    for index, task in enumerate(plan.tasks):
        events.append((task.pickup_time, f"pickup of target {task.target_id}"))
        if index in drops:
            events.append((drops[index].time, f"drop visit after task {index}"))
    return events


@contract(
    "times_increase",
    "pickup and drop-visit times are strictly increasing and not before the request time",
    kinds=("task_planner",),
)
def check_times(plugin_class: type[Plugin]) -> None:
    plan, request = _plan(plugin_class)
    events = _events(plan)
    if events and events[0][0] < request.time:
        fail(
            f"the {events[0][1]} is at {events[0][0]:g} s, "
            f"before the request time {request.time:g} s"
        )
    for (t0, a), (t1, b) in zip(events, events[1:], strict=False):
        if t1 <= t0:
            fail(f"the {b} at {t1:g} s is not after the {a} at {t0:g} s")


@contract(
    "respects_capacity",
    "the collector never carries more than its capacity, and every run ends with a drop visit",
    kinds=("task_planner",),
)
def check_capacity(plugin_class: type[Plugin]) -> None:
    plan, request = _plan(plugin_class)
    drops = {visit.after_task for visit in plan.drop_visits}
    carried = 0 if -1 in drops else request.carried
    for index, task in enumerate(plan.tasks):
        carried += 1
        if carried > request.capacity:
            fail(
                f"target {task.target_id} would be the {carried}th on board; "
                f"capacity is {request.capacity}"
            )
        if index in drops:
            carried = 0
    if plan.tasks and (len(plan.tasks) - 1) not in drops:
        fail("the last pickup is not followed by a drop visit")


@contract(
    "plans_every_reachable_target",
    "every target of the standard request (all reachable in minutes) is planned",
    kinds=("task_planner",),
)
def check_completeness(plugin_class: type[Plugin]) -> None:
    plan, request = _plan(plugin_class)
    missing = {t.id for t in request.targets} - {task.target_id for task in plan.tasks}
    if missing:
        fail(f"targets {sorted(missing)} were left out of the plan")


@contract(
    "honours_time_budget",
    "a request for 15 targets (task planners), or a path problem whose goal is walled in by "
    "60 obstacles (path planners; the reach problem for a manipulator's), with a 0.3 s budget "
    "is answered within the budget "
    f"(plus 20 % and {TIME_SLACK} s)",
    kinds=("task_planner", "path_planner"),
)
def check_budget(plugin_class: type[Plugin]) -> None:
    budget = 0.3
    plan: Callable[[], object]
    if plugin_class.kind == "task_planner":
        request = problems.task_request(targets=15, time_budget=budget)
        if not issubclass(plugin_class, TaskPlanner):
            not_derived(plugin_class, TaskPlanner)
        plan = partial(make(plugin_class).plan, request)
    else:
        if problem_robot(plugin_class) == "manipulator":
            problem = problems.reach_problem(budget)
        else:
            problem = problems.posed(plugin_class, problems.enclosed_goal_problem(budget))
        if not issubclass(plugin_class, PathPlanner):
            not_derived(plugin_class, PathPlanner)
        plan = partial(make(plugin_class).plan, problem)
    start = time.perf_counter()
    answer = plan()
    elapsed = time.perf_counter() - start
    if elapsed > 1.2 * budget + TIME_SLACK:
        fail(f"took {elapsed:.3f} s with a budget of {budget} s")
    checked_answer(plugin_class.kind, answer, f"a problem with a {budget:g} s budget")


DEADLINE_AWAY = 0.3
"""How far the deadline of the deadline check lies when the planner is called, s."""

LONG_BUDGET = 30.0
"""The deadline check's ``time_budget``, s: far beyond its deadline."""


@contract(
    "honours_deadline",
    "the problem of honours_time_budget, its deadline (`PathProblem.deadline`, "
    f"`time.monotonic()` seconds) {DEADLINE_AWAY:g} s away and its time_budget "
    f"{LONG_BUDGET:g} s, is answered by the deadline (plus 20 % of {DEADLINE_AWAY:g} s and "
    f"{TIME_SLACK} s): the deadline rules, as `PathProblem.due()` gives it",
    kinds=("path_planner",),
)
def check_deadline(plugin_class: type[Plugin]) -> None:
    if problem_robot(plugin_class) == "manipulator":
        problem = problems.reach_problem(LONG_BUDGET)
    else:
        problem = problems.posed(plugin_class, problems.enclosed_goal_problem(LONG_BUDGET))
    if not issubclass(plugin_class, PathPlanner):
        not_derived(plugin_class, PathPlanner)
    plugin = make(plugin_class)
    deadline = time.monotonic() + DEADLINE_AWAY
    answer = plugin.plan(dataclasses.replace(problem, deadline=deadline))
    late = time.monotonic() - deadline
    if late > 0.2 * DEADLINE_AWAY + TIME_SLACK:
        fail(
            f"answered {late:.3f} s after the problem's deadline (its time_budget of "
            f"{LONG_BUDGET:g} s counts only when no deadline is given: plan by problem.due())"
        )
    checked_answer(plugin_class.kind, answer, "a problem with a deadline")


# --------------------------------------------------------------------- path planner


def _path(
    plugin_class: type[Plugin], problem: PathProblem, what: str
) -> tuple[Trajectory, PathProblem]:
    problem = problems.posed(plugin_class, problem)
    result = run_plugin(plugin_class, [problem], what)[0]
    if not isinstance(result, Trajectory):
        fail(f"found no path on {what}, which has one: {result!r}")
    return result, problem


def _standard_path(plugin_class: type[Plugin]) -> tuple[Trajectory, PathProblem]:
    return _path(plugin_class, problems.path_problem(), "the standard path problem")


def _fine_samples(trajectory: Trajectory, problem: PathProblem) -> tuple[np.ndarray, ...]:
    """Times, positions and velocities ten times finer than the trajectory's own samples,
    and no farther apart than a quarter of the robot radius."""
    lengths = np.linalg.norm(np.diff(trajectory.positions, axis=0), axis=1)
    pieces = np.maximum(10, np.ceil(lengths / (0.25 * problem.robot_radius))).astype(int)
    segment = np.repeat(np.arange(len(pieces)), pieces)
    first = np.repeat(np.cumsum(pieces) - pieces, pieces)
    fraction = (np.arange(pieces.sum()) - first) / pieces[segment]
    start, span = trajectory.times[:-1], np.diff(trajectory.times)
    times = np.append(start[segment] + fraction * span[segment], trajectory.times[-1])
    return times, *trajectory.sample(times)


def _turn_angle(a: np.ndarray, b: np.ndarray) -> float:
    """Angle of the rotation from attitude ``b`` to attitude ``a``, rad."""
    return float(np.linalg.norm(rotation_vector(quaternion_multiply(a, quaternion_conjugate(b)))))


def _check_start(trajectory: Trajectory, start: RobotState, what: str) -> None:
    gap = float(np.linalg.norm(trajectory.positions[0] - start.position))
    lag = float(trajectory.times[0] - start.time)
    turn = (
        0.0
        if trajectory.attitudes is None
        else _turn_angle(trajectory.attitudes[0], start.attitude)
    )
    position_tolerance, time_tolerance, attitude_tolerance = START_TOLERANCES
    if gap > position_tolerance or abs(lag) > time_tolerance or turn > attitude_tolerance:
        fail(
            f"on {what} it starts {gap:.3g} m, {lag:.3g} s and {turn:.3g} rad from the start state"
        )


@contract(
    "reaches_the_goal",
    f"the trajectory starts at the start state (within {_START_TEXT}) and its final state "
    "is inside the goal region within every "
    "tolerance (`GoalRegion.contains`): on the standard problem, and on one whose goal asks "
    "to arrive at rest, turned, at a set time (a trajectory that leaves the attitude free "
    "arrives at the goal's attitude, which the transfer mission holds)",
    kinds=("path_planner",),
    robots=("free-flyer",),
)
def check_endpoints(plugin_class: type[Plugin]) -> None:
    for problem, what in (
        (problems.path_problem(), "the standard path problem"),
        (problems.arrival_problem(), "the arrival problem"),
    ):
        trajectory, problem = _path(plugin_class, problem, what)
        _check_start(trajectory, problem.start, what)
        final = trajectory.end_state(problem.goal)
        if not problem.goal.contains(final):
            fail(
                f"on {what} it ends at t = {final.time:.3f} s at {final.position}, moving at "
                f"{final.velocity}, attitude {final.attitude}: outside {problem.goal!r}"
            )


@contract(
    "stays_in_bounds",
    "the trajectory, sampled finely, stays inside the problem's bounds",
    kinds=("path_planner",),
    robots=("free-flyer",),
)
def check_bounds(plugin_class: type[Plugin]) -> None:
    trajectory, problem = _standard_path(plugin_class)
    times, positions, _ = _fine_samples(trajectory, problem)
    assert problem.bounds is not None  # the standard path problem is posed in a box
    outside = ~problem.bounds.contains(positions)
    if outside.any():
        i = int(np.flatnonzero(outside)[0])
        fail(f"at t = {times[i]:.2f} s it is at {positions[i]}, outside {problem.bounds!r}")


def _implied_delta_v(trajectory: Trajectory, start: RobotState) -> float:
    """The velocity changes the samples imply: from the start's velocity to the first
    sample's, then between samples (thrust in an inertial frame), m/s."""
    velocities = np.vstack([start.velocity, trajectory.velocities])
    return float(np.linalg.norm(np.diff(velocities, axis=0), axis=1).sum())


@contract(
    "respects_limits",
    "speeds never exceed max_speed, and neither the reported delta-v nor the one its "
    "samples imply (the start's velocity change plus every change between samples, in the "
    "standard problem's inertial frame) exceeds max_delta_v",
    kinds=("path_planner",),
    robots=("free-flyer",),
)
def check_limits(plugin_class: type[Plugin]) -> None:
    trajectory, problem = _standard_path(plugin_class)
    times, _, velocities = _fine_samples(trajectory, problem)
    speeds = np.linalg.norm(velocities, axis=1)
    if speeds.max() > problem.max_speed * (1 + 1e-6):
        i = int(np.argmax(speeds))
        fail(f"speed {speeds[i]:.4f} m/s at t = {times[i]:.2f} s exceeds {problem.max_speed} m/s")
    implied = _implied_delta_v(trajectory, problem.start)
    for delta_v, which in ((trajectory.delta_v, "reported"), (implied, "sampled")):
        if delta_v > problem.max_delta_v * (1 + 1e-6):
            fail(
                f"needs {delta_v:.3f} m/s of delta-v ({which}); "
                f"the limit is {problem.max_delta_v} m/s"
            )


@contract(
    "respects_acceleration_limit",
    "the acceleration between consecutive samples, ‖v(i+1) − v(i)‖ / (t(i+1) − t(i)) (exact "
    "for velocities linear between samples, in the standard problem's inertial frame), never "
    f"exceeds max_acceleration by more than {100 * ACCELERATION_TOLERANCE:g} %",
    kinds=("path_planner",),
    robots=("free-flyer",),
)
def check_acceleration(plugin_class: type[Plugin]) -> None:
    trajectory, problem = _standard_path(plugin_class)
    times = trajectory.times
    rates = np.linalg.norm(np.diff(trajectory.velocities, axis=0), axis=1) / np.diff(times)
    i = int(np.argmax(rates))
    if rates[i] > problem.max_acceleration * (1 + ACCELERATION_TOLERANCE):
        fail(
            f"accelerates at {rates[i]:.4g} m/s² between t = {times[i]:.2f} s and "
            f"{times[i + 1]:.2f} s; the limit is {problem.max_acceleration} m/s²"
        )


def _check_margin(trajectory: Trajectory, problem: PathProblem, what: str) -> None:
    """Fail unless the trajectory keeps the problem's safety margin from every obstacle."""
    closest = path_clearance(trajectory, problem)
    if closest.collides:
        fail(
            f"on {what} it overlaps obstacle {closest.obstacle_id} by {-closest.distance:.3f} m "
            f"at t = {closest.time:.2f} s, at {closest.position}"
        )
    if closest.distance < problem.safety_margin:
        fail(
            f"on {what} it comes {closest.distance:.3f} m from obstacle {closest.obstacle_id} "
            f"at t = {closest.time:.2f} s, at {closest.position}: inside the problem's "
            f"safety_margin of {problem.safety_margin:g} m"
        )


@contract(
    "collision_free",
    "against every obstacle's true shape (sphere, or turned box or cylinder) moving by its "
    "predicted motion, the robot's sphere never comes closer than the problem's "
    f"safety_margin ({problems.SAFETY_MARGIN:g} m on the standard problem); checked by "
    "`dcsim.yardsticks.clearance.path_clearance` at every sample of the trajectory and at "
    f"steps over which no gap changes by more than {RESOLUTION:g} robot radius",
    kinds=("path_planner",),
    robots=("free-flyer",),
)
def check_collisions(plugin_class: type[Plugin]) -> None:
    trajectory, problem = _standard_path(plugin_class)
    _check_margin(trajectory, problem, "the standard path problem")


@contract(
    "keeps_safety_margin",
    f"on the margin problem, whose direct line passes {problems.DIRECT_GAP:g} m from a "
    f"sphere, a trajectory keeps the problem's safety_margin of {problems.WIDE_MARGIN:g} m "
    "(measured as in collision_free; a planner that cannot bend may answer NoPath): the "
    "margin is the problem's, not the planner's own",
    kinds=("path_planner",),
    robots=("free-flyer",),
)
def check_safety_margin(plugin_class: type[Plugin]) -> None:
    problem = problems.posed(plugin_class, problems.margin_problem())
    answer = run_plugin(plugin_class, [problem], "the margin problem")[0]
    if isinstance(answer, Trajectory):
        _check_margin(answer, problem, "the margin problem")


_IMPOSSIBLE: tuple[tuple[str, Callable[[float], PathProblem]], ...] = (
    ("a goal inside obstacle 9", problems.impossible_path_problem),
    ("a start inside obstacle 9", problems.blocked_start_problem),
    ("a goal walled in by 60 obstacles", problems.enclosed_goal_problem),
    ("a goal outside the bounds", problems.outside_bounds_problem),
)


def _describe(result: object) -> str:
    if isinstance(result, Trajectory):
        return f"a trajectory ending at {result.positions[-1]} at t = {result.times[-1]:.1f} s"
    return repr(result)


@contract(
    "answers_no_path",
    "with the goal inside an obstacle, the start inside an obstacle, the goal walled in by "
    "obstacles, or the goal outside the bounds, it answers NoPath with a reason, within its "
    "time budget",
    kinds=("path_planner",),
    robots=("free-flyer",),
)
def check_impossible(plugin_class: type[Plugin]) -> None:
    for what, build in _IMPOSSIBLE:
        problem = problems.posed(plugin_class, build(1.0))
        start = time.perf_counter()
        result = run_plugin(plugin_class, [problem], f"a problem with {what}")[0]
        elapsed = time.perf_counter() - start
        if not isinstance(result, NoPath) or not result.reason.strip():
            fail(f"answered {_describe(result)} for {what}")
        if elapsed > 1.2 * problem.time_budget + TIME_SLACK:
            fail(f"took {elapsed:.3f} s with a budget of {problem.time_budget} s for {what}")


_STATIC_ONLY_TEXT = "static obstacles only (`handles_moving_obstacles = False`)"


@contract(
    "declares_obstacle_motion",
    "a planner that handles moving obstacles (the default) is held to the checks above on "
    "the standard problems as they are; one that declares it handles "
    f"{_STATIC_ONLY_TEXT} gets every path check above with the obstacles held still where "
    "they are at the start, and must answer the standard problem, whose obstacles move, "
    "with NoPath whose reason names the moving obstacles, within its time budget",
    kinds=("path_planner",),
    robots=("free-flyer",),
)
def check_obstacle_motion(plugin_class: type[Plugin]) -> None:
    if getattr(plugin_class, "handles_moving_obstacles", True):
        return  # the checks above posed it the moving obstacles
    problem = problems.path_problem()
    start = time.perf_counter()
    result = run_plugin(plugin_class, [problem], "the standard path problem")[0]
    elapsed = time.perf_counter() - start
    if not isinstance(result, NoPath) or "moving" not in result.reason:
        fail(
            f"declares it handles {_STATIC_ONLY_TEXT} but answered {_describe(result)} "
            "for the standard problem, whose obstacles move (a NoPath naming them is expected)"
        )
    if elapsed > 1.2 * problem.time_budget + TIME_SLACK:
        fail(f"took {elapsed:.3f} s with a budget of {problem.time_budget} s to refuse")


def _reach_path(plugin_class: type[Plugin]) -> tuple[Trajectory, PathProblem]:
    return _path(plugin_class, problems.reach_problem(), "the reach problem")


@contract(
    "reaches_the_target",
    "on the reach problem (a manipulator's end effector 0.3 m to a target), the trajectory "
    f"starts at the end effector of the start state (its position and, when the trajectory "
    f"gives attitudes, its attitude, within {_START_TEXT}) and its final "
    "state is inside the goal region (`GoalRegion.contains`) and at rest (within 1e-9 m/s)",
    kinds=("path_planner",),
    robots=("manipulator",),
)
def check_reach_endpoints(plugin_class: type[Plugin]) -> None:
    trajectory, problem = _reach_path(plugin_class)
    start = problem.start
    q = start.configuration
    assert problem.model is not None  # the reach problem carries the manipulator's model
    frame = problem.model.forward_kinematics(q)
    attitude = quaternion_from_matrix(frame.end_effector_rotation)
    end_effector = dataclasses.replace(start, position=frame.end_effector, attitude=attitude)
    _check_start(trajectory, end_effector, "the reach problem")
    final = trajectory.end_state()
    if not problem.goal.contains(final) or np.linalg.norm(final.velocity) > 1e-9:
        fail(
            f"on the reach problem it ends at {final.position} moving at {final.velocity}: "
            f"outside {problem.goal!r}, or not at rest"
        )


@contract(
    "respects_end_effector_limits",
    "on the reach problem the end effector's speed never exceeds max_speed and the "
    "acceleration between consecutive samples never exceeds max_acceleration by more than "
    f"{100 * ACCELERATION_TOLERANCE:g} %",
    kinds=("path_planner",),
    robots=("manipulator",),
)
def check_reach_limits(plugin_class: type[Plugin]) -> None:
    trajectory, problem = _reach_path(plugin_class)
    speeds = np.linalg.norm(trajectory.velocities, axis=1)
    if speeds.max() > problem.max_speed * (1 + 1e-6):
        fail(f"the end effector moves at {speeds.max():.4g} m/s, above {problem.max_speed} m/s")
    rates = np.linalg.norm(np.diff(trajectory.velocities, axis=0), axis=1)
    rates = rates / np.diff(trajectory.times)
    if rates.max() > problem.max_acceleration * (1 + ACCELERATION_TOLERANCE):
        fail(
            f"the end effector accelerates at {rates.max():.4g} m/s², above "
            f"{problem.max_acceleration} m/s²"
        )


@contract(
    "refuses_an_unreachable_target",
    "a target beyond the arm's reach from its shoulder is answered with NoPath and a "
    "reason, within the time budget",
    kinds=("path_planner",),
    robots=("manipulator",),
)
def check_unreachable_target(plugin_class: type[Plugin]) -> None:
    problem = problems.reach_problem(target=(6.0, 0.0, 0.0))
    start = time.perf_counter()
    result = run_plugin(plugin_class, [problem], "a target beyond the arm's reach")[0]
    elapsed = time.perf_counter() - start
    if not isinstance(result, NoPath) or not result.reason.strip():
        fail(f"answered {_describe(result)} for a target beyond the arm's reach")
    if elapsed > 1.2 * problem.time_budget + TIME_SLACK:
        fail(f"took {elapsed:.3f} s with a budget of {problem.time_budget} s to refuse")


# --------------------------------------------------------------------- controller


@contract(
    "commands_within_limits",
    "force and torque magnitudes never exceed max_force and max_torque (and, for a "
    "manipulator, each joint torque its joint_torque_limits)",
    kinds=("controller",),
)
def check_command_limits(plugin_class: type[Plugin]) -> None:
    inputs = standard_inputs("controller", plugin_class=plugin_class)
    robot = inputs[0]
    for index, command in enumerate(run_plugin(plugin_class, inputs, "the standard ticks")):
        force, torque = np.linalg.norm(command.force), np.linalg.norm(command.torque)
        if force > robot.max_force * (1 + 1e-9) or torque > robot.max_torque * (1 + 1e-9):
            fail(
                f"command {index} asks {force:.3f} N and {torque:.3f} N*m; the limits are "
                f"{robot.max_force} N and {robot.max_torque} N*m"
            )
        excess = np.abs(command.joint_torques) > robot.joint_torque_limits * (1 + 1e-9)
        if command.joint_torques.shape != robot.joint_torque_limits.shape or excess.any():
            fail(
                f"command {index} asks joint torques {command.joint_torques.tolist()} N*m; "
                f"the limits are {robot.joint_torque_limits.tolist()} N*m"
            )


@contract(
    "rests_at_the_reference",
    "at the reference, with zero velocity and zero reference velocity, the command is (near) zero",
    kinds=("controller",),
)
def check_rest(plugin_class: type[Plugin]) -> None:
    if problem_robot(plugin_class) == "manipulator":
        robot = problems.manipulator_robot()
        joints = problems.MANIPULATOR_JOINTS
        estimate = StateEstimate(
            time=0.0,
            position=np.array([3.0, -4.0, 5.0]),
            attitude=np.array([0.0, 0.6, 0.0, 0.8]),
            joint_positions=joints,
            joint_velocities=np.zeros_like(joints),
            converged=True,
        )
        reference = Reference(
            time=0.0,
            position=np.array([3.0, -4.0, 5.0]),
            attitude=np.array([0.0, 0.6, 0.0, 0.8]),
            joint_positions=joints,
        )
        what = "a manipulator at rest on its reference"
    else:
        robot = problems.ROBOT
        estimate = StateEstimate(time=0.0, position=np.array([3.0, -4.0, 5.0]), converged=True)
        reference = Reference(time=0.0, position=np.array([3.0, -4.0, 5.0]))
        what = "a collector at rest on its reference"
    inputs = [robot, [(0.0, estimate, reference, Surroundings())]]
    command = run_plugin(plugin_class, inputs, what)[0]
    if (
        np.linalg.norm(command.force) > 1e-6 * robot.max_force
        or np.linalg.norm(command.torque) > 1e-6 * robot.max_torque
        or np.any(np.abs(command.joint_torques) > 1e-6 * robot.joint_torque_limits)
    ):
        fail(f"commands {command!r} while at rest on the reference")


@contract(
    "stabilises_a_double_integrator",
    "from 11.6 m off, a 100 kg double integrator reaches the reference within 0.1 m and "
    "0.01 m/s in 1000 s (free-flyer controllers)",
    kinds=("controller",),
    robots=("free-flyer",),
)
def check_double_integrator(plugin_class: type[Plugin]) -> None:
    robot, dt = problems.ROBOT, 0.1
    if not issubclass(plugin_class, Controller):
        not_derived(plugin_class, Controller)
    plugin = make(plugin_class)
    plugin.reset(robot)
    position, velocity = np.array([10.0, -5.0, 3.0]), np.zeros(3)
    reference = Reference(time=0.0, position=np.zeros(3))
    for k in range(10_000):
        estimate = StateEstimate(time=k * dt, position=position, velocity=velocity, converged=True)
        command = checked_answer(
            "controller",
            plugin.command(k * dt, estimate, reference, Surroundings()),
            f"the double integrator at t = {k * dt:g} s",
        )
        velocity = velocity + command.force / robot.mass * dt
        position = position + velocity * dt
    error, speed = float(np.linalg.norm(position)), float(np.linalg.norm(velocity))
    if error > 0.1 or speed > 0.01:
        fail(f"after 1000 s it is {error:.3f} m from the reference moving at {speed:.4f} m/s")


HARDWARE_TIME = 300.0
"""Time the check on thrusters and wheels gives a controller, s."""


@contract(
    "flies_on_thrusters_and_wheels",
    "a free flyer with 12 thrusters (minimum impulse bits) and 4 reaction wheels, 5 m off "
    f"its reference and 20 deg off its attitude, flown in a real world for {HARDWARE_TIME:g} s: "
    "every command gives none or one value per thruster and per wheel (body force and "
    "torque are allocated to them, on-times and wheel torques are flown as given), and the "
    "robot ends within 0.1 m of the reference (free-flyer controllers)",
    kinds=("controller",),
    robots=("free-flyer",),
)
def check_hardware(plugin_class: type[Plugin]) -> None:
    from dcsim.scenario import read_scenario  # imported here: the world is heavy
    from dcsim.world import World, WorldInputs

    if not issubclass(plugin_class, Controller):
        not_derived(plugin_class, Controller)
    tilt = quaternion_from_rotation_vector(np.radians([20.0, 0.0, 0.0]))
    scenario = read_scenario(
        problems.hardware_scenario(HARDWARE_TIME, (4.0, -3.0, 0.0), tilt.tolist())
    )
    reference = Reference(time=0.0, position=np.zeros(3), attitude=np.array([0.0, 0.0, 0.0, 1.0]))
    actuators = ActuatorCounts(thrusters=12, wheels=4)
    with World(scenario, np.random.default_rng(0)) as world:
        plugin = make(plugin_class)
        plugin.reset(world.robot_spec())
        while world.time < HARDWARE_TIME - 1e-9:
            position, velocity, attitude, rate = world.base_state()
            estimate = StateEstimate(
                time=world.time,
                position=position,
                attitude=attitude,
                velocity=velocity,
                angular_velocity=rate,
                converged=True,
            )
            what = f"thrusters and wheels at t = {world.time:g} s"
            command = checked_answer(
                "controller",
                plugin.command(world.time, estimate, reference, Surroundings()),
                what,
                actuators,
            )
            world.step(
                WorldInputs(
                    force=command.force,
                    torque=command.torque,
                    thruster_on_times=command.thruster_on_times,
                    wheel_torques=command.wheel_torques,
                )
            )
        error = float(np.linalg.norm(world.base_state()[0]))
    if error > 0.1:
        fail(f"after {HARDWARE_TIME:g} s on thrusters and wheels it is {error:.3f} m off")


CONVERGENCE_TIME = 15.0
"""Time the manipulator convergence check gives a controller, s."""


@contract(
    "converges_on_a_manipulator",
    "the thesis's manipulator at rest, its joints 0.05 rad and its base attitude 0.03 rad "
    f"off a constant reference, comes within a third of both errors in {CONVERGENCE_TIME:g} s "
    "(100 Hz control, the model's own dynamics) and never strays beyond 1.5 times them "
    "(manipulator controllers; the base position is not required to follow)",
    kinds=("controller",),
    robots=("manipulator",),
)
def check_manipulator_convergence(plugin_class: type[Plugin]) -> None:
    robot = problems.manipulator_robot()
    if not issubclass(plugin_class, Controller):
        not_derived(plugin_class, Controller)
    plugin = make(plugin_class)
    plugin.reset(robot)
    joints = problems.MANIPULATOR_JOINTS
    reference = Reference(
        time=0.0,
        position=np.zeros(3),
        attitude=np.array([0.0, 0.0, 0.0, 1.0]),
        joint_positions=joints,
    )
    offset = np.array([0.05, -0.05, 0.05, -0.05, 0.05, -0.05])
    tilt = quaternion_from_rotation_vector([0.03, 0.0, 0.0])
    q0 = np.concatenate([[0.02, 0.0, 0.0], tilt, joints + offset])
    try:
        loop = simulate(
            plugin,
            robot,
            lambda t: reference,
            q0,
            np.zeros(q0.size - 1),
            CONVERGENCE_TIME,
            0.01,
            integrator="euler",
        )
    except Exception as error:  # a plugin's own failure: name it, with the problem posed
        fail(f"raised {type(error).__name__}: {error} on a manipulator near its reference")
    for t, command in zip(loop.times, loop.commands, strict=False):
        checked_answer(
            "controller",
            command,
            f"a manipulator near its reference at t = {t:g} s",
            ActuatorCounts(joints=joints.size),
        )
    joint_error = np.abs(loop.q[:, 7:] - joints).max(axis=1) / np.abs(offset).max()
    attitude_error = np.linalg.norm(rotation_vector(loop.q[:, 3:7]), axis=1) / 0.03
    worst = float(np.nanmax(np.maximum(joint_error, attitude_error)))
    final = float(max(joint_error[-1], attitude_error[-1]))
    if not np.isfinite(final) or final > 1 / 3 or worst > 1.5:
        fail(
            f"after {CONVERGENCE_TIME:g} s its joint and attitude errors are {joint_error[-1]:.3g} "
            f"and {attitude_error[-1]:.3g} of their initial sizes (at most 1/3 expected), at "
            f"worst {worst:.3g} of them (at most 1.5)"
        )
