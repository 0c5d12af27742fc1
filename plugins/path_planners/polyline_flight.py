"""A polyline flown as a timed, checked trajectory: corner blends or rest to rest.

Not a plugin itself; ``ant-colony`` flies its simplified path with it (:func:`fly_polyline`),
and ``ompl-geometric`` shares its rest-to-rest segments (:func:`rest_to_rest_segment`),
the joining of pieces (:func:`chain`), the arrival at rest (:func:`arrival_refusal`) and
the delta-v limit (:func:`trajectory_of`).

Corner blends (:func:`blended`)
    The polyline is flown at one cruise speed with parabolic corner blends: at each
    vertex the velocity turns from ``v u_j`` to ``v u_(j+1)`` at the acceleration limit
    over ``v |u_(j+1) − u_j| / a`` seconds centred on the vertex (the path cuts the
    corner by ``v² |Δu|² / 8a``; speed never exceeds v), and it accelerates from rest at
    the first vertex and brakes to rest at the last on the first and last pieces. The
    duration is ``L/v + v/a``.
Rest to rest (:func:`rest_to_rest`)
    Every piece is flown from rest to rest with the trapezoid of the ``straight-line``
    planner, so the polyline is followed exactly.
Timing and checks (:func:`fly_polyline`)
    v is ``speed_fraction`` of the speed limit, lowered until every piece holds its
    ramps and half-blends (:func:`blend_speed_limit`), or chosen to arrive exactly at
    the goal's time when it sets one (no path if even the fastest admissible v is late).
    A start that moves first brakes to rest along its velocity (:func:`departure`). The
    timed trajectory must stay in the bounds and within the delta-v limit, and is
    checked with dcsim's swept clearance (``path_clearance``) against the obstacles'
    predicted motion: it must keep half of the problem's ``safety_margin``. If the
    blends cut too close it is flown again with half the cruise speed (when there is no
    goal time), then rest to rest at every vertex (the polyline exactly; waiting at the
    goal for its time), and "no path" if none passes. The goal is arrived at at rest (a
    goal velocity beyond its tolerance is "no path"); the attitude is left free (the
    transfer mission holds the goal's or the start's). The frame's free motion is not
    used: straight pieces are flown with thrust.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from dcsim_plugins.path_planners.straight_line import Profile

from dcsim.api import (
    NoPath,
    PathProblem,
    Trajectory,
    cruise_speed,
    path_clearance,
    rest_to_rest_time,
)

SHORTEST = 1e-6
"""m: shorter polyline pieces are dropped."""
_BLEND_SAMPLES = 8  # trajectory samples per corner blend or ramp

Samples = tuple[np.ndarray, np.ndarray, np.ndarray]
"""Times (s), positions (m) and velocities (m/s) of a piece of trajectory."""


@dataclass(frozen=True)
class Departure:
    """Braking to rest along the start's velocity at the acceleration limit, flown before
    the polyline.

    Attributes
    ----------
    samples : Samples
        Times since the start, positions and velocities; one sample when the start is
        at rest.
    time : float
        When the robot is at rest, s.
    """

    samples: Samples
    time: float

    @property
    def position(self) -> np.ndarray:
        """Where the robot is at rest, m."""
        return self.samples[1][-1]


def departure(problem: PathProblem) -> Departure:
    """The braking piece before the polyline of ``problem``."""
    samples = _braking(problem.start.position, problem.start.velocity, problem.max_acceleration)
    return Departure(samples, problem.start.time + float(samples[0][-1]))


def _braking(position: np.ndarray, velocity: np.ndarray, acceleration: float) -> Samples:
    """Times since the start (s), positions (m) and velocities (m/s) of braking to rest
    along ``velocity`` at ``acceleration``; one sample when at rest."""
    position, velocity = np.asarray(position, float), np.asarray(velocity, float)
    speed = float(np.linalg.norm(velocity))
    if speed == 0.0 or math.isinf(acceleration):
        return np.zeros(1), position[None], np.zeros((1, 3))
    return _constant_acceleration(
        position, velocity, -velocity / speed * acceleration, speed / acceleration
    )


def _constant_acceleration(
    position: np.ndarray, velocity: np.ndarray, acceleration: np.ndarray, duration: float
) -> Samples:
    """Samples of a piece flown at a constant acceleration, from its start."""
    tau = np.linspace(0.0, duration, _BLEND_SAMPLES + 1)
    positions = position + np.outer(tau, velocity) + 0.5 * np.outer(tau**2, acceleration)
    return tau, positions, velocity + np.outer(tau, acceleration)


def blend_speed_limit(vertices: np.ndarray, acceleration: float) -> float:
    """Largest cruise speed at which every piece of the polyline holds its ramps and
    half-blends, m/s (``inf`` for impulsive acceleration)."""
    if math.isinf(acceleration):
        return math.inf
    pieces = np.diff(vertices, axis=0)
    lengths = np.linalg.norm(pieces, axis=1)
    directions = pieces / lengths[:, None]
    turns = np.linalg.norm(np.diff(directions, axis=0), axis=1)
    ends = np.concatenate([[1.0], turns, [1.0]]) / (2.0 * acceleration)  # × v² = length used
    demand = ends[:-1] + ends[1:]
    return float(np.sqrt(np.min(lengths / demand)))


def blended(vertices: np.ndarray, speed: float, acceleration: float) -> Samples:
    """A polyline flown at cruise ``speed`` (m/s) with parabolic corner blends at
    ``acceleration`` (m/s²), from rest to rest; times from the start. With impulsive
    acceleration (``inf``) the polyline is flown rest to rest instead."""
    if math.isinf(acceleration):
        return rest_to_rest(vertices, speed, acceleration)
    pieces = np.diff(vertices, axis=0)
    directions = pieces / np.linalg.norm(pieces, axis=1)[:, None]
    ramp = speed / acceleration
    parts = [_constant_acceleration(vertices[0], np.zeros(3), acceleration * directions[0], ramp)]
    last = len(directions) - 1
    for j, direction in enumerate(directions):
        position, velocity = parts[-1][1][-1], parts[-1][2][-1]
        if j < last:
            turn = speed * (directions[j + 1] - direction)
            duration = float(np.linalg.norm(turn)) / acceleration
            change = turn / duration if duration > 0 else np.zeros(3)
        else:
            duration, change = ramp, -acceleration * direction
        entry = vertices[j + 1] - direction * (0.5 * speed * duration)  # half-blend or ramp
        cruise = float(np.dot(entry - position, direction)) / speed
        if cruise > 0:
            parts.append(
                (
                    np.array([0.0, cruise]),
                    np.vstack([position, entry]),
                    np.vstack([velocity, velocity]),
                )
            )
            position = entry
        if duration > 0:
            parts.append(_constant_acceleration(position, velocity, change, duration))
        else:
            parts.append((np.zeros(1), position[None], velocity[None]))
    times, positions, velocities = chain(parts, 0.0)
    positions[-1], velocities[-1] = vertices[-1], 0.0
    return times, positions, velocities


def rest_to_rest(vertices: np.ndarray, speed: float, acceleration: float) -> Samples:
    """A polyline flown rest to rest on every piece (:func:`rest_to_rest_segment`);
    times from the start."""
    parts = [
        rest_to_rest_segment(a, b, speed, acceleration)
        for a, b in zip(vertices[:-1], vertices[1:], strict=True)
    ]
    return chain(parts, 0.0)


def rest_to_rest_segment(
    a: np.ndarray, b: np.ndarray, speed: float, acceleration: float
) -> Samples:
    """Times since the segment's start (s), positions (m) and velocities (m/s) of the
    flight from rest at ``a`` to rest at ``b`` with the trapezoid of cruise ``speed``
    (m/s) and ``acceleration`` (m/s², ``inf``: impulsive)."""
    length = float(np.linalg.norm(b - a))
    duration = float(rest_to_rest_time(length, speed, acceleration))
    cruise = speed if math.isinf(acceleration) else min(speed, math.sqrt(acceleration * length))
    profile = Profile(length, duration, cruise, acceleration)
    tau = profile.sample_times()
    distance, velocity = profile(tau)
    direction = (b - a) / length
    return tau, a + np.outer(distance, direction), np.outer(velocity, direction)


def chain(parts: list[Samples], t0: float) -> Samples:
    """Consecutive pieces joined end to start, from time ``t0``; samples closer than a
    microsecond merged."""
    times, positions, velocities = [np.array([t0])], [parts[0][1][:1]], [parts[0][2][:1]]
    clock = t0
    for tau, p, v in parts:
        times.append(clock + tau[1:])
        positions.append(p[1:])
        velocities.append(v[1:])
        clock += float(tau[-1])
    t, p, v = np.concatenate(times), np.vstack(positions), np.vstack(velocities)
    keep = np.append(True, np.diff(t) > 1e-6)
    return t[keep], p[keep], v[keep]


def arrival_refusal(problem: PathProblem) -> NoPath | None:
    """ "No path" when the goal asks for a velocity beyond its tolerance: a polyline is
    arrived at at rest; None otherwise."""
    goal = problem.goal
    if np.linalg.norm(goal.velocity) > goal.velocity_tolerance:
        return NoPath(
            f"the goal asks to arrive at {goal.velocity} m/s; this planner arrives at rest"
        )
    return None


def trajectory_of(
    problem: PathProblem, samples: Samples, statistics: dict[str, float]
) -> Trajectory | NoPath:
    """The trajectory of ``samples`` (times from the problem's clock), or "no path" when
    its velocity changes, from the start's velocity on, add up to more than the delta-v
    limit."""
    times, positions, velocities = samples
    changes = np.diff(np.vstack([problem.start.velocity, velocities]), axis=0)
    delta_v = float(np.linalg.norm(changes, axis=1).sum())
    if delta_v > problem.max_delta_v:
        return NoPath(f"the path needs {delta_v:.3g} m/s of delta-v, above {problem.max_delta_v:g}")
    return Trajectory(
        times=times,
        positions=positions,
        velocities=velocities,
        delta_v=delta_v,
        length=float(np.linalg.norm(np.diff(positions, axis=0), axis=1).sum()),
        duration=float(times[-1] - times[0]),
        statistics=statistics,
    )


def fly_polyline(
    problem: PathProblem,
    start: Departure,
    vertices: np.ndarray,
    speed_fraction: float,
    statistics: dict[str, float],
) -> Trajectory | NoPath:
    """The polyline ``vertices`` (k, 3) m, from where ``start`` comes to rest, flown with
    blends (or rest to rest) and checked to keep half of the problem's ``safety_margin``
    (m); see the module docstring."""
    keep = np.append(True, np.linalg.norm(np.diff(vertices, axis=0), axis=1) > SHORTEST)
    vertices = vertices[keep]
    goal = problem.goal
    available = None if goal.time is None else goal.time - start.time
    if len(vertices) < 2:  # already there: hold, until the goal's time if it sets one
        hold = max(available or 0.0, 1e-3)
        samples = (np.array([0.0, hold]), np.vstack([vertices, vertices]), np.zeros((2, 3)))
        return _checked(problem, start, samples, statistics)
    attempts, reason = _attempts(problem, vertices, speed_fraction, available)
    for samples in attempts:
        if available is not None:
            late = samples[0][-1] - available
            if late > goal.time_tolerance:
                reason = reason or (
                    f"the path arrives {late:.3g} s after the goal's time {goal.time:g} s"
                )
                continue
            if late < 0:
                samples = _waiting(samples, available)
        answer = _checked(problem, start, samples, statistics)
        if isinstance(answer, Trajectory):
            return answer
        reason = answer.reason
    return NoPath(reason)


def _attempts(
    problem: PathProblem, vertices: np.ndarray, speed_fraction: float, available: float | None
) -> tuple[list[Samples], str]:
    """The flights of the polyline to try in turn (times from the start of the polyline),
    and why the blended one is left out when the goal's time cannot be met with it."""
    accel = problem.max_acceleration
    cruise = speed_fraction * problem.max_speed
    length = float(np.linalg.norm(np.diff(vertices, axis=0), axis=1).sum())
    fastest = min(problem.max_speed, blend_speed_limit(vertices, accel))
    attempts: list[Samples] = []
    reason = ""
    if available is None:
        speed = min(cruise, fastest)
        attempts += [blended(vertices, speed, accel), blended(vertices, speed / 2, accel)]
    else:
        needed = cruise_speed(length, max(available, 1e-9), accel)
        if needed <= fastest * (1 + 1e-9) and available > 0:
            attempts.append(blended(vertices, min(needed, fastest), accel))
        else:
            best = length / fastest + (0.0 if math.isinf(accel) else fastest / accel)
            reason = (
                f"the {length:.3g} m path needs {best:.4g} s at the speed and acceleration "
                f"limits; the goal's time leaves {available:.4g} s"
            )
    attempts.append(rest_to_rest(vertices, min(cruise, problem.max_speed), accel))
    return attempts, reason


def _waiting(samples: Samples, until: float) -> Samples:
    """``samples`` followed by waiting at rest at their end until ``until`` (s)."""
    t, p, v = samples
    return np.append(t, until), np.vstack([p, p[-1]]), np.vstack([v, 0 * v[-1]])


def _checked(
    problem: PathProblem,
    start: Departure,
    samples: Samples,
    statistics: dict[str, float],
) -> Trajectory | NoPath:
    """The trajectory of the braking piece and ``samples``, if it keeps half of the
    problem's ``safety_margin`` from every obstacle, stays in bounds and within the
    delta-v limit."""
    braking = start.samples
    parts = [braking, samples] if len(braking[0]) > 1 else [samples]
    joined = chain(parts, problem.start.time)
    if problem.bounds is not None and not problem.bounds.contains(joined[1]).all():
        return NoPath("the timed path leaves the bounds")
    trajectory = trajectory_of(problem, joined, statistics)
    if isinstance(trajectory, NoPath) or not problem.obstacles:
        return trajectory
    closest = path_clearance(trajectory, problem)
    needed = 0.5 * problem.safety_margin
    if closest.distance < needed:
        return NoPath(
            f"the timed path passes {closest.distance:.3g} m from obstacle "
            f"{closest.obstacle_id} at t = {closest.time:.1f} s (needs {needed:.3g} m)"
        )
    return trajectory
