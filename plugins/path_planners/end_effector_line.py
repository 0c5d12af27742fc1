"""``end-effector-line`` path planner: a manipulator's end effector straight to its target.

The end effector moves on the segment from where it is (the forward kinematics of the
problem's start state) to the goal region's centre, at rest at both ends, with the
minimum-jerk (quintic) time law of :mod:`minimum_jerk`, whose velocity and acceleration
are continuous: what a model-based controller needs to track the joint references
derived from it. The move's duration is the shortest that keeps its peak speed and
acceleration within the problem's limits (or the goal's time, when it sets one). The
answer is "no path" when the target lies beyond the arm's reach from the shoulder (the
base held where it is), when no model is given (a free flyer), or when the goal's time
is too soon. This is the task-space straight line of the space manipulator thesis's reach
experiment, and the baseline of the learned planner.
"""

from __future__ import annotations

import numpy as np

from dcsim.api import (
    NoPath,
    PathPlanner,
    PathPlannerParams,
    PathProblem,
    Trajectory,
    hookimpl,
    minimum_jerk_move,
    quantity,
    shortest_duration,
)


class EndEffectorLineParams(PathPlannerParams):
    """Parameters of :class:`EndEffectorLinePlanner`."""

    samples: int = quantity(
        201, ge=2, le=100_000, description="Trajectory samples from start to target."
    )
    min_duration: float = quantity(
        0.1, unit="s", gt=0, description="Shortest motion, also for a target already reached."
    )


class EndEffectorLinePlanner(PathPlanner):
    """Straight-line end-effector path with a minimum-jerk time law."""

    name = "end-effector-line"
    summary = "A manipulator's end effector straight to the target, minimum-jerk time law"
    Params = EndEffectorLineParams
    params: EndEffectorLineParams
    robots = ("manipulator",)

    def plan(self, problem: PathProblem) -> Trajectory | NoPath:
        """The end effector's straight path to the goal's centre, or why there is none."""
        refusal = unreachable(problem)
        if refusal is not None:
            return refusal
        assert problem.model is not None  # unreachable() refuses a problem without one
        origin = problem.model.forward_kinematics(problem.start.configuration).end_effector
        target = problem.goal.position
        length = float(np.linalg.norm(target - origin))
        duration = self._duration(problem, length)
        if isinstance(duration, NoPath):
            return duration
        times, positions, velocities = minimum_jerk_move(
            origin, target, duration, self.params.samples
        )
        return Trajectory(
            times=problem.start.time + times,
            positions=positions,
            velocities=velocities,
            length=length,
            duration=duration,
        )

    def _duration(self, problem: PathProblem, length: float) -> float | NoPath:
        """``T``: the goal's time if set, else the least within the speed and acceleration
        limits (never below ``min_duration``)."""
        shortest = shortest_duration(
            length, problem.max_speed, problem.max_acceleration, self.params.min_duration
        )
        if problem.goal.time is None:
            return shortest
        available = problem.goal.time - problem.start.time
        if available < shortest * (1 - 1e-9):
            return NoPath(
                f"the target is {length:.3g} m away: reaching it needs {shortest:.3g} s within "
                f"the speed and acceleration limits, the goal's time leaves {available:.3g} s"
            )
        return available


def unreachable(problem: PathProblem) -> NoPath | None:
    """Why no end-effector path can be planned at all: no manipulator model, or a target
    beyond the arm's reach from its shoulder (the base where it is); None otherwise."""
    model = problem.model
    if model is None:
        return NoPath("the problem carries no manipulator model: this planner moves an arm")
    shoulder = model.forward_kinematics(problem.start.configuration).origins[0]
    distance = float(np.linalg.norm(problem.goal.position - shoulder))
    if distance > model.reach:
        return NoPath(
            f"the target is {distance:.3f} m from the shoulder, beyond the arm's reach of "
            f"{model.reach:.3f} m"
        )
    return None


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the end-effector line planner."""
    return [EndEffectorLinePlanner]
