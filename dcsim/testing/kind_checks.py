"""Checks specific to each plugin kind (localiser, task planner, path planner, controller)."""

from __future__ import annotations

import time

import numpy as np

from dcsim.interfaces import Plugin
from dcsim.messages import NoPath, Reference, StateEstimate, Surroundings, Trajectory
from dcsim.testing import problems
from dcsim.testing.contracts import (
    LOCALISER_ERROR_BOUND,
    TIME_SLACK,
    contract,
    fail,
    make,
    run_plugin,
    standard_inputs,
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
    "a request for 15 targets with a 0.3 s budget is answered within the budget "
    f"(plus 20 % and {TIME_SLACK} s)",
    kinds=("task_planner",),
)
def check_task_budget(plugin_class: type[Plugin]) -> None:
    request = problems.task_request(targets=15, time_budget=0.3)
    plugin = make(plugin_class)
    start = time.perf_counter()
    plugin.plan(request)
    elapsed = time.perf_counter() - start
    if elapsed > 1.2 * request.time_budget + TIME_SLACK:
        fail(f"took {elapsed:.3f} s with a budget of {request.time_budget} s")


# --------------------------------------------------------------------- path planner


def _path(plugin_class: type[Plugin]) -> tuple[Trajectory, object]:
    problem = problems.path_problem()
    result = run_plugin(plugin_class, [problem], "the standard path problem")[0]
    if not isinstance(result, Trajectory):
        fail(f"found no path on the standard problem, which has one: {result!r}")
    return result, problem


def _fine_samples(trajectory: Trajectory, problem) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Times, positions and velocities ten times finer than the trajectory's own samples,
    and no farther apart than a quarter of the robot radius."""
    times = [trajectory.times[0]]
    for t0, t1, p0, p1 in zip(
        trajectory.times,
        trajectory.times[1:],
        trajectory.positions,
        trajectory.positions[1:],
        strict=False,
    ):
        pieces = max(10, int(np.ceil(np.linalg.norm(p1 - p0) / (0.25 * problem.robot_radius))))
        times.extend(np.linspace(t0, t1, pieces + 1)[1:])
    times = np.array(times)
    states = [trajectory.sample(t) for t in times]
    return times, np.array([s[0] for s in states]), np.array([s[1] for s in states])


@contract(
    "reaches_the_goal",
    "the trajectory starts at the start state and ends inside the goal region",
    kinds=("path_planner",),
)
def check_endpoints(plugin_class: type[Plugin]) -> None:
    trajectory, problem = _path(plugin_class)
    start_gap = np.linalg.norm(trajectory.positions[0] - problem.start.position)
    if start_gap > 1e-6 or abs(trajectory.times[0] - problem.start.time) > 1e-9:
        fail(
            f"starts {start_gap:.3g} m and {trajectory.times[0] - problem.start.time:.3g} s "
            "away from the start state"
        )
    end_gap = np.linalg.norm(trajectory.positions[-1] - problem.goal.position)
    if end_gap > problem.goal.tolerance:
        fail(
            f"ends {end_gap:.3f} m from the goal; "
            f"the goal region's radius is {problem.goal.tolerance} m"
        )


@contract(
    "stays_in_bounds",
    "the trajectory, sampled finely, stays inside the problem's bounds",
    kinds=("path_planner",),
)
def check_bounds(plugin_class: type[Plugin]) -> None:
    trajectory, problem = _path(plugin_class)
    times, positions, _ = _fine_samples(trajectory, problem)
    outside = ~problem.bounds.contains(positions)
    if outside.any():
        i = int(np.flatnonzero(outside)[0])
        fail(f"at t = {times[i]:.2f} s it is at {positions[i]}, outside {problem.bounds!r}")


@contract(
    "respects_limits",
    "speeds never exceed max_speed and the reported delta-v is within max_delta_v",
    kinds=("path_planner",),
)
def check_limits(plugin_class: type[Plugin]) -> None:
    trajectory, problem = _path(plugin_class)
    times, _, velocities = _fine_samples(trajectory, problem)
    speeds = np.linalg.norm(velocities, axis=1)
    if speeds.max() > problem.max_speed * (1 + 1e-6):
        i = int(np.argmax(speeds))
        fail(f"speed {speeds[i]:.4f} m/s at t = {times[i]:.2f} s exceeds {problem.max_speed} m/s")
    if trajectory.delta_v > problem.max_delta_v:
        fail(
            f"needs {trajectory.delta_v:.3f} m/s of delta-v; the limit is {problem.max_delta_v} m/s"
        )


@contract(
    "collision_free",
    "checked ten times finer than its own samples against the obstacles' predicted motion, "
    "the trajectory keeps the robot and every obstacle apart",
    kinds=("path_planner",),
)
def check_collisions(plugin_class: type[Plugin]) -> None:
    trajectory, problem = _path(plugin_class)
    times, positions, _ = _fine_samples(trajectory, problem)
    for obstacle in problem.obstacles:
        gaps = (
            np.linalg.norm(obstacle.predict(times)[0] - positions, axis=1)
            - obstacle.radius
            - problem.robot_radius
        )
        if gaps.min() < 0:
            i = int(np.argmin(gaps))
            fail(f"overlaps obstacle {obstacle.id} by {-gaps[i]:.3f} m at t = {times[i]:.2f} s")


@contract(
    "answers_no_path",
    "with the goal inside an obstacle it answers NoPath with a reason, within its time budget",
    kinds=("path_planner",),
)
def check_impossible(plugin_class: type[Plugin]) -> None:
    problem = problems.impossible_path_problem(time_budget=1.0)
    start = time.perf_counter()
    result = run_plugin(plugin_class, [problem], "a problem whose goal is inside an obstacle")[0]
    elapsed = time.perf_counter() - start
    if not isinstance(result, NoPath) or not result.reason.strip():
        fail(f"answered {result!r} for a goal inside obstacle 9")
    if elapsed > 1.2 * problem.time_budget + TIME_SLACK:
        fail(f"took {elapsed:.3f} s with a budget of {problem.time_budget} s")


# --------------------------------------------------------------------- controller


@contract(
    "commands_within_limits",
    "force and torque magnitudes never exceed max_force and max_torque",
    kinds=("controller",),
)
def check_command_limits(plugin_class: type[Plugin]) -> None:
    robot = problems.ROBOT
    for index, command in enumerate(
        run_plugin(plugin_class, standard_inputs("controller"), "the standard ticks")
    ):
        force, torque = np.linalg.norm(command.force), np.linalg.norm(command.torque)
        if force > robot.max_force * (1 + 1e-9) or torque > robot.max_torque * (1 + 1e-9):
            fail(
                f"command {index} asks {force:.3f} N and {torque:.3f} N*m; the limits are "
                f"{robot.max_force} N and {robot.max_torque} N*m"
            )


@contract(
    "rests_at_the_reference",
    "at the reference, with zero velocity and zero reference velocity, the command is (near) zero",
    kinds=("controller",),
)
def check_rest(plugin_class: type[Plugin]) -> None:
    robot = problems.ROBOT
    estimate = StateEstimate(time=0.0, position=[3.0, -4.0, 5.0], converged=True)
    reference = Reference(time=0.0, position=[3.0, -4.0, 5.0])
    inputs = [robot, [(0.0, estimate, reference, Surroundings())]]
    command = run_plugin(plugin_class, inputs, "a collector at rest on its reference")[0]
    if (
        np.linalg.norm(command.force) > 1e-6 * robot.max_force
        or np.linalg.norm(command.torque) > 1e-6 * robot.max_torque
    ):
        fail(f"commands {command!r} while at rest on the reference")


@contract(
    "stabilises_a_double_integrator",
    "from 11.6 m off, a 100 kg double integrator reaches the reference within 0.1 m and "
    "0.01 m/s in 1000 s",
    kinds=("controller",),
)
def check_double_integrator(plugin_class: type[Plugin]) -> None:
    robot, dt = problems.ROBOT, 0.1
    plugin = make(plugin_class)
    plugin.reset(robot)
    position, velocity = np.array([10.0, -5.0, 3.0]), np.zeros(3)
    reference = Reference(time=0.0, position=[0.0, 0.0, 0.0])
    for k in range(10_000):
        estimate = StateEstimate(time=k * dt, position=position, velocity=velocity, converged=True)
        force = plugin.command(k * dt, estimate, reference, Surroundings()).force
        velocity = velocity + force / robot.mass * dt
        position = position + velocity * dt
    error, speed = float(np.linalg.norm(position)), float(np.linalg.norm(velocity))
    if error > 0.1 or speed > 0.01:
        fail(f"after 1000 s it is {error:.3f} m from the reference moving at {speed:.4f} m/s")
