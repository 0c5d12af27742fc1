"""``straight-line`` path planner: the direct segment, if it is safe.

The collector flies the segment from the start to the goal centre at constant velocity:
at the goal's required time if one is given, otherwise at ``speed_fraction`` of the speed
limit. The segment is checked against every obstacle's predicted motion at a spacing of
``check_spacing``; if it passes closer than the two radii plus ``clearance`` the answer is
"no path", naming the obstacle and the time. This is the yardstick the real planners are
compared with.
"""

from __future__ import annotations

import numpy as np

from dcsim.api import (
    NoPath,
    PathPlanner,
    PathProblem,
    PluginParams,
    Trajectory,
    hookimpl,
    quantity,
)

_MIN_DURATION = 1e-3  # s; a zero-length path still spans a positive time


class StraightLineParams(PluginParams):
    """Parameters of :class:`StraightLinePlanner`."""

    speed_fraction: float = quantity(
        0.8,
        gt=0,
        le=1,
        description="Fraction of the speed limit flown when no arrival time is set.",
    )
    clearance: float = quantity(
        0.5, unit="m", ge=0, description="Margin kept beyond the sum of robot and obstacle radii."
    )
    check_spacing: float = quantity(
        0.25, unit="m", gt=0, description="Distance between collision checks along the segment."
    )


class StraightLinePlanner(PathPlanner):
    """Direct constant-velocity segment, rejected if it meets a predicted obstacle."""

    name = "straight-line"
    summary = (
        "Direct segment at a speed limit; no path if it crosses a predicted obstacle (baseline)"
    )
    Params = StraightLineParams
    params: StraightLineParams

    def plan(self, problem: PathProblem) -> Trajectory | NoPath:
        """Return the straight segment to the goal, or why it cannot be flown."""
        start, goal = problem.start, problem.goal
        offset = goal.position - start.position
        distance = float(np.linalg.norm(offset))
        if goal.time is not None:
            duration = goal.time - start.time
            if duration <= 0:
                return NoPath(
                    f"the goal time {goal.time:g} s is not after the start {start.time:g} s"
                )
        else:
            duration = distance / (self.params.speed_fraction * problem.max_speed)
        duration = max(duration, _MIN_DURATION)
        velocity = offset / duration
        speed = distance / duration
        if speed > problem.max_speed * (1 + 1e-9):
            return NoPath(
                f"reaching the goal by t = {goal.time:g} s needs {speed:.3g} m/s, "
                f"above the {problem.max_speed:g} m/s limit"
            )
        if (
            problem.bounds is not None
            and not problem.bounds.contains([start.position, goal.position]).all()
        ):
            return NoPath("the start or the goal lies outside the bounds")
        delta_v = float(
            np.linalg.norm(velocity - start.velocity) + np.linalg.norm(goal.velocity - velocity)
        )
        if delta_v > problem.max_delta_v:
            return NoPath(
                f"the segment needs {delta_v:.3g} m/s of delta-v, above {problem.max_delta_v:g}"
            )
        t1 = start.time + duration
        blocked = self._first_conflict(problem, start.time, t1, start.position, velocity, distance)
        if blocked is not None:
            return blocked
        return Trajectory(
            times=[start.time, t1],
            positions=[start.position, start.position + velocity * duration],
            velocities=[velocity, goal.velocity],
            delta_v=delta_v,
            length=distance,
            duration=duration,
        )

    def _first_conflict(
        self,
        problem: PathProblem,
        t0: float,
        t1: float,
        p0: np.ndarray,
        velocity: np.ndarray,
        distance: float,
    ) -> NoPath | None:
        samples = int(np.ceil(distance / self.params.check_spacing)) + 2
        times = np.linspace(t0, t1, samples)
        path = p0 + velocity * (times - t0)[:, None]
        for obstacle in problem.obstacles:
            gaps = np.linalg.norm(obstacle.predict(times)[0] - path, axis=1)
            needed = problem.robot_radius + obstacle.radius + self.params.clearance
            hits = np.flatnonzero(gaps < needed)
            if hits.size:
                k = int(hits[0])
                return NoPath(
                    f"the straight segment passes {gaps[k]:.2f} m from obstacle {obstacle.id} "
                    f"at t = {times[k]:.1f} s (needs {needed:.2f} m)"
                )
        return None


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the straight-line path planner."""
    return [StraightLinePlanner]
