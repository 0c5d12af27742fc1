"""``straight-line`` path planner: the direct segment, if it is safe.

The collector flies straight at the goal in the frame that moves with the goal's
velocity (for a goal at rest, a straight line in space), with a trapezoidal speed
profile: it accelerates at ``max_acceleration``, cruises, and brakes to arrive at rest
relative to the goal, that is, matching the goal's velocity. It arrives at the goal's
required time if one is given, otherwise as soon as a cruise speed of ``speed_fraction``
of the speed limit allows. The path is checked against every obstacle's predicted motion
every ``check_spacing`` metres; if it passes closer than the two radii plus the
problem's ``safety_margin`` the answer is "no path", naming the obstacle and the time
(unless ``check_obstacles`` is false). An obstacle's radius is its bounding sphere's
(``ObjectTrack.radius``): for a box or a cylinder (``ObjectTrack.shape``) the check is
conservative and may refuse a path that clears the true shape. The attitude is held at
the start's, or, when the goal gives one, turned onto it at a constant rate (slerp) over
the flight. This is the yardstick the real planners are compared with.
"""

from __future__ import annotations

import numpy as np

from dcsim.api import (
    NoPath,
    PathPlanner,
    PathPlannerParams,
    PathProblem,
    Trajectory,
    cruise_speed,
    hookimpl,
    quantity,
    quaternion_conjugate,
    quaternion_multiply,
    rest_to_rest_time,
    rotation_vector,
    slerp,
)

_MIN_DURATION = 1e-3  # s; a zero-length path still spans a positive time
_RAMP_SAMPLES = 12  # trajectory samples per acceleration ramp


class StraightLineParams(PathPlannerParams):
    """Parameters of :class:`StraightLinePlanner`."""

    speed_fraction: float = quantity(
        0.8,
        gt=0,
        le=1,
        description="Fraction of the speed limit flown when no arrival time is set.",
    )
    check_obstacles: bool = quantity(
        True,
        description="Refuse paths that pass too close to an obstacle; false leaves avoidance "
        "to the controller, as the thesis's executer does.",
    )
    check_spacing: float = quantity(
        0.25, unit="m", gt=0, description="Distance between collision checks along the path."
    )


class Profile:
    """Trapezoidal distance ``s(τ)`` over ``[0, T]``: ramps at ``a``, cruise at ``v``.

    Parameters
    ----------
    length : float
        Distance covered, m.
    duration : float
        ``T``, s.
    speed : float
        Cruise speed ``v``, m/s.
    acceleration : float
        Ramp acceleration ``a``, m/s² (``inf``: no ramps).
    """

    def __init__(self, length: float, duration: float, speed: float, acceleration: float) -> None:
        self.length, self.duration, self.speed = length, duration, speed
        self.acceleration = acceleration
        self.ramp = 0.0 if np.isinf(acceleration) else min(speed / acceleration, duration / 2)

    def __call__(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Distance (m) and speed (m/s) along the path at times ``tau`` since the start."""
        if self.ramp == 0.0:
            return self.speed * tau, np.full_like(tau, self.speed)
        a, r, T, v = self.acceleration, self.ramp, self.duration, self.speed
        rising, falling = tau < r, tau > T - r
        distance = np.where(
            rising,
            0.5 * a * tau**2,
            np.where(
                falling, self.length - 0.5 * a * (T - tau) ** 2, 0.5 * a * r**2 + v * (tau - r)
            ),
        )
        speed = np.where(rising, a * tau, np.where(falling, a * (T - tau), v))
        return distance, speed

    def sample_times(self) -> np.ndarray:
        """Times that resolve the ramps, for the trajectory's samples."""
        ramps = [
            np.linspace(0, self.ramp, _RAMP_SAMPLES),
            np.linspace(self.duration - self.ramp, self.duration, _RAMP_SAMPLES),
        ]
        return np.unique(np.concatenate([[0.0, self.duration], *ramps]))


class StraightLinePlanner(PathPlanner):
    """Straight at the goal (in the goal's moving frame), trapezoidal speed, obstacle-checked."""

    name = "straight-line"
    summary = (
        "Direct path with a trapezoidal speed profile; "
        "no path if it meets a predicted obstacle (baseline)"
    )
    Params = StraightLineParams
    params: StraightLineParams

    def plan(self, problem: PathProblem) -> Trajectory | NoPath:
        """Return the straight path to the goal, or why it cannot be flown."""
        start, goal = problem.start, problem.goal
        goal_speed = float(np.linalg.norm(goal.velocity))
        headroom = problem.max_speed - goal_speed
        if headroom <= 0:
            return NoPath(
                f"the goal moves at {goal_speed:.3g} m/s, "
                f"at or above the {problem.max_speed:g} m/s limit"
            )
        profile = self._profile(problem, headroom)
        if isinstance(profile, NoPath):
            return profile
        offset = goal.position - goal.velocity * profile.duration - start.position
        direction = offset / profile.length if profile.length > 0 else np.zeros(3)

        def states(tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            distance, speed = profile(tau)
            positions = (
                start.position + np.outer(tau, goal.velocity) + np.outer(distance, direction)
            )
            return positions, goal.velocity + np.outer(speed, direction)

        spacing = self.params.check_spacing
        count = int(np.ceil((profile.length + goal_speed * profile.duration) / spacing)) + 2
        fine_tau = np.linspace(0.0, profile.duration, count)
        fine_positions, _ = states(fine_tau)
        if problem.bounds is not None and not problem.bounds.contains(fine_positions).all():
            return NoPath("the path leaves the bounds")
        delta_v = float(np.linalg.norm(goal.velocity - start.velocity)) + 2.0 * profile.speed
        if delta_v > problem.max_delta_v:
            return NoPath(
                f"the path needs {delta_v:.3g} m/s of delta-v, above {problem.max_delta_v:g}"
            )
        if self.params.check_obstacles:
            blocked = self._first_conflict(problem, start.time + fine_tau, fine_positions)
            if blocked is not None:
                return blocked
        tau = profile.sample_times()
        positions, velocities = states(tau)
        attitudes, angular_velocities = _attitudes(start.attitude, goal.attitude, tau)
        return Trajectory(
            times=start.time + tau,
            positions=positions,
            velocities=velocities,
            attitudes=attitudes,
            angular_velocities=angular_velocities,
            delta_v=delta_v,
            length=float(np.linalg.norm(np.diff(fine_positions, axis=0), axis=1).sum()),
            duration=profile.duration,
        )

    def _profile(self, problem: PathProblem, headroom: float) -> Profile | NoPath:
        """The speed profile in the goal's frame: length, duration, cruise speed."""
        start, goal = problem.start, problem.goal
        accel = problem.max_acceleration
        if goal.time is not None:
            duration = goal.time - start.time
            if duration <= 0:
                return NoPath(
                    f"the goal time {goal.time:g} s is not after the start {start.time:g} s"
                )
            length = float(
                np.linalg.norm(goal.position - goal.velocity * duration - start.position)
            )
            speed = cruise_speed(length, duration, accel)
            if not speed <= headroom * (1 + 1e-9):
                needed = rest_to_rest_time(length, headroom, accel)
                return NoPath(
                    f"reaching the goal by t = {goal.time:g} s needs {float(needed):.4g} s at the "
                    f"speed and acceleration limits, only {duration:.4g} s are left"
                )
            return Profile(length, max(duration, _MIN_DURATION), speed, accel)
        limit = self.params.speed_fraction * headroom
        duration = 0.0
        for _ in range(50):  # the goal's own motion during the flight moves the aim point
            length = float(
                np.linalg.norm(goal.position - goal.velocity * duration - start.position)
            )
            updated = float(rest_to_rest_time(length, limit, accel))
            converged = abs(updated - duration) < 1e-9
            duration = updated
            if converged:
                break
        speed = limit if np.isinf(accel) else min(limit, float(np.sqrt(accel * length)))
        return Profile(length, max(duration, _MIN_DURATION), speed, accel)

    def _first_conflict(
        self, problem: PathProblem, times: np.ndarray, path: np.ndarray
    ) -> NoPath | None:
        for obstacle in problem.obstacles:
            gaps = np.linalg.norm(obstacle.predict(times)[0] - path, axis=1)
            needed = problem.robot_radius + obstacle.radius + problem.safety_margin
            hits = np.flatnonzero(gaps < needed)
            if hits.size:
                k = int(hits[0])
                return NoPath(
                    f"the straight path passes {gaps[k]:.2f} m from obstacle {obstacle.id} "
                    f"at t = {times[k]:.1f} s (needs {needed:.2f} m)"
                )
        return None


def _attitudes(
    start: np.ndarray, goal: np.ndarray | None, tau: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Attitudes and angular velocities (rad/s) at times ``tau`` since the start: the start
    attitude held, or turned at a constant rate onto the goal's over the flight."""
    if goal is None:
        return np.tile(start, (len(tau), 1)), np.zeros((len(tau), 3))
    fraction = tau / tau[-1]
    turn = rotation_vector(quaternion_multiply(goal, quaternion_conjugate(start)))
    rate = turn / tau[-1]
    return slerp(start, goal, fraction), np.tile(rate, (len(tau), 1))


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the straight-line path planner."""
    return [StraightLinePlanner]
