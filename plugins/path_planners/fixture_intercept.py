"""``fixture-intercept`` path planner: a manipulator's end effector onto a tumbling body's
grapple fixture, moving with it.

The problem's :class:`~dcsim.api.GraspGoal` carries the body's track (pose, velocities,
inertia) and the fixture; a problem without one (a reach) is met as a fixture that does
not move, at the goal region's centre, with the end effector's attitude at the start,
reached by the transfer alone (no insertion, no follow).
The body's motion is predicted by its torque-free tumble
(:class:`~dcsim.api.TorqueFreeRotation`) and a straight line for its centre of mass. The
grasp pose of DH frame n at any time is then rigidly attached to the body: x_n along
``-approach_axis``, z_n along ``bar_axis`` (or against it: a bar is held either way
round, and the way nearer the end effector's z axis at the start is taken), the grasp
point ``tool_offset`` ahead of the frame on the bar's centre. The end effector's
trajectory has three phases:

1. **transfer** — from the start (at rest) onto the *pre-grasp* pose, the grasp pose
   moved ``approach_distance`` out along the approach axis, flown in joint space: the
   joints of the pre-grasp pose are found by damped Newton iteration from the start's,
   and each joint follows a quintic from rest to them, arriving with the rates that move
   the end effector exactly as the pre-grasp pose moves (matched velocity). A straight
   Cartesian blend would carry this arm (its joints 5 and 6 are parallel: it has no
   wrist roll) through singularities that a joint-space move does not meet;
2. **insertion** — in along the approach axis onto the grasp pose, the offset falling
   from ``approach_distance`` to 0 by the minimum-jerk law while the pose turns and
   moves with the body;
3. **follow** — on the grasp pose, moving with the fixture, for ``follow_time`` (the
   gripper closes and its grip is judged meanwhile).

Grasp times are tried every ``candidate_step``, from the earliest the transfer's length
allows up to ``horizon``. A candidate whose fixture, over insertion and follow, stays
within the arm's reach from the shoulder and faces it, and whose pre-grasp pose has a
joint solution, is flown by the framework's closed-loop inverse kinematics
(:class:`~dcsim.api.PosePath`, the base held); it is accepted when the joints stay
``limit_margin_deg`` from their limits, ``det(J Jᵀ)`` of the 6 × n arm Jacobian stays
above ``min_det_jjt`` (away from singularities; an arm that starts nearer one must not
come to half its value at the start) and the joints follow the path within the goal's
tolerance. The first accepted candidate is the answer; none by the deadline is a "no
path" that counts the refusals of each kind.
"""

from __future__ import annotations

import time as wallclock
from dataclasses import dataclass

import numpy as np

from dcsim.api import (
    ForwardKinematics,
    GraspGoal,
    ManipulatorModel,
    NoPath,
    ObjectKind,
    ObjectTrack,
    PathPlanner,
    PathPlannerParams,
    PathProblem,
    PosePath,
    TorqueFreeRotation,
    Trajectory,
    hookimpl,
    minimum_jerk_profile,
    quantity,
    quaternion_from_matrix,
    rotation_matrix,
    rotation_vector,
    shortest_duration,
)


class FixtureInterceptParams(PathPlannerParams):
    """Parameters of :class:`FixtureInterceptPlanner`."""

    approach_distance: float = quantity(
        0.15,
        unit="m",
        gt=0,
        description="Distance out along the fixture's approach axis at which the end "
        "effector lines up before moving in.",
    )
    min_transfer_time: float = quantity(
        1.0, unit="s", gt=0, description="Shortest transfer onto the pre-grasp pose."
    )
    insertion_time: float = quantity(
        3.0, unit="s", gt=0, description="Duration of the move in along the approach axis."
    )
    follow_time: float = quantity(
        4.0,
        unit="s",
        gt=0,
        description="Time the end effector follows the fixture after reaching it.",
    )
    candidate_step: float = quantity(
        1.0, unit="s", gt=0, description="Spacing of the grasp times tried."
    )
    horizon: float = quantity(
        120.0, unit="s", gt=0, description="Latest grasp time tried, after the start."
    )
    limit_margin_deg: float = quantity(
        5.0, unit="deg", ge=0, description="Least distance kept from every joint limit."
    )
    min_det_jjt: float = quantity(
        1e-4,
        gt=0,
        description="Least det(J Jᵀ) of the 6 × n arm Jacobian along the path (away from "
        "singularities).",
    )
    sample_step: float = quantity(
        0.05, unit="s", gt=0, description="Spacing of the trajectory's samples."
    )
    ik_damping: float = quantity(
        0.02,
        gt=0,
        description="Damping λ of the checking inverse kinematics' pseudo-inverse "
        "(bounds the joint rates near a singularity).",
    )
    ik_gain: float = quantity(
        10.0, unit="1/s", gt=0, description="Gain of the inverse kinematics that checks a path."
    )


@dataclass(frozen=True)
class BodyPrediction:
    """A tumbling body's predicted motion at sample times (world frame).

    Attributes
    ----------
    centres : ndarray (N, 3)
        Centre of mass, m.
    velocity : ndarray (3,)
        Velocity of the centre of mass, m/s.
    rotations : ndarray (N, 3, 3)
        Body-to-world rotations.
    angular_velocities : ndarray (N, 3)
        rad/s.
    """

    centres: np.ndarray
    velocity: np.ndarray
    rotations: np.ndarray
    angular_velocities: np.ndarray

    def points(self, body_point: np.ndarray) -> np.ndarray:
        """World positions (N, 3) of a point fixed in the body (body frame, m)."""
        return self.centres + self.rotations @ body_point

    def point_velocities(self, body_point: np.ndarray) -> np.ndarray:
        """World velocities (N, 3) of a point fixed in the body, m/s."""
        return self.velocity + np.cross(self.angular_velocities, self.rotations @ body_point)

    def axes(self, body_axis: np.ndarray) -> np.ndarray:
        """World directions (N, 3) of a body-fixed direction."""
        return self.rotations @ body_axis

    def head(self, count: int) -> BodyPrediction:
        """The prediction at its first ``count`` samples."""
        return BodyPrediction(
            self.centres[:count],
            self.velocity,
            self.rotations[:count],
            self.angular_velocities[:count],
        )


def predict_body(grasp: GraspGoal, times: np.ndarray) -> BodyPrediction:
    """The body's torque-free motion at ``times`` (s, increasing, not before its track)."""
    track = grasp.target
    assert track.attitude is not None and track.angular_velocity is not None
    assert track.inertia is not None  # GraspGoal refuses a track without them
    rotation = TorqueFreeRotation(track.inertia, track.attitude, track.angular_velocity)
    rotations = np.empty((len(times), 3, 3))
    rates = np.empty((len(times), 3))
    now = track.time
    for i, t in enumerate(times):
        rotation.advance(max(t - now, 0.0))
        now = max(t, now)
        rotations[i] = rotation_matrix(rotation.attitude)
        rates[i] = rotation.angular_velocity
    centres = track.position + np.outer(times - track.time, track.velocity)
    return BodyPrediction(centres, np.asarray(track.velocity), rotations, rates)


class FixtureInterceptPlanner(PathPlanner):
    """End-effector pose trajectory onto a tumbling body's grapple fixture."""

    name = "fixture-intercept"
    summary = "A manipulator's end effector onto a tumbling body's fixture, velocity matched"
    Params = FixtureInterceptParams
    params: FixtureInterceptParams
    robots = ("manipulator",)

    def plan(self, problem: PathProblem) -> Trajectory | NoPath:
        """The earliest feasible intercept of the fixture, or why there is none."""
        due = problem.due()
        model = problem.model
        if not isinstance(model, ManipulatorModel):
            return NoPath("the problem carries no manipulator model: this planner moves an arm")
        start = problem.start
        frame = model.forward_kinematics(start.configuration)
        grasp = problem.grasp or _still_goal(problem, frame)
        shoulder = frame.origins[0]
        p = self.params
        if problem.grasp is None:  # a still goal: the transfer ends on it, at rest
            p = p.model_copy(
                update={"approach_distance": 0.0, "insertion_time": 1e-9, "follow_time": 0.0}
            )
        # the body's motion over every candidate's samples, predicted once
        samples = start.time + p.sample_step * np.arange(
            _sample_count(p.horizon + p.follow_time, p)
        )
        predicted = predict_body(grasp, samples)
        candidates = self._grasp_times(problem, frame, grasp, predicted, p)
        if len(candidates) == 0:
            return NoPath(
                f"the fixture is too far to reach by the horizon of {p.horizon:g} s at the "
                "problem's speed and acceleration limits"
            )
        refusals: dict[str, tuple[int, str]] = {}
        for grasp_time in candidates:
            count = _sample_count(grasp_time + p.follow_time - start.time, p)
            times, body = samples[:count], predicted.head(count)
            judged = times >= grasp_time - p.insertion_time
            refusal = _out_of_reach(
                body, grasp, shoulder, model.reach, judged, problem.grasp is not None
            )
            if refusal is None:
                trajectory = self._trajectory(problem, frame, times, grasp_time, body, grasp, p)
                if isinstance(trajectory, Trajectory):
                    refusal = self._check(problem, trajectory)
                    if refusal is None:
                        return trajectory
                else:
                    refusal = trajectory
            kind, detail = refusal
            refusals[kind] = (refusals.get(kind, (0, ""))[0] + 1, detail)
            if problem.grasp is None and kind != _TOO_FAST:
                break  # a still goal: a later start of the same move is no better
            if wallclock.monotonic() > due:
                refusals["the planning budget ran out"] = (1, f"{problem.time_budget:g} s")
                break
        return NoPath(_summary(refusals))

    def _grasp_times(
        self,
        problem: PathProblem,
        frame: ForwardKinematics,
        grasp: GraspGoal,
        predicted: BodyPrediction,
        p: FixtureInterceptParams,
    ) -> np.ndarray:
        """Candidate grasp times, s: every ``candidate_step`` from the earliest the
        transfer's straight length allows within the speed and acceleration limits, up to
        ``horizon`` (``predicted``: the body's motion from the start on)."""
        start = problem.start.time
        fixture = predicted.head(1).points(np.asarray(grasp.fixture))
        distance = float(np.linalg.norm(fixture[0] - frame.end_effector))
        transfer = shortest_duration(
            distance, problem.max_speed, problem.max_acceleration, p.min_transfer_time
        )
        return np.arange(start + transfer + p.insertion_time, start + p.horizon, p.candidate_step)

    def _trajectory(
        self,
        problem: PathProblem,
        frame: ForwardKinematics,
        times: np.ndarray,
        grasp_time: float,
        body: BodyPrediction,
        grasp: GraspGoal,
        p: FixtureInterceptParams,
    ) -> Trajectory | tuple[str, str]:
        """The three phases as a trajectory of DH frame n, or why the arm has no joint
        solution at the pre-grasp pose (``frame``: the arm's at the start)."""
        assert isinstance(problem.model, ManipulatorModel)  # plan() refuses other models
        model, start = problem.model, problem.start.configuration
        lined_up = grasp_time - p.insertion_time
        moving = _GraspPoses.along(body, grasp, times, lined_up, p, frame)
        first = int(np.searchsorted(times, lined_up))
        joints = _pose_solution(model, start, moving.positions[first], moving.rotations[first])
        if joints is None:
            return "no joint solution at the pre-grasp pose", f"t = {lined_up:.1f} s"
        try:
            transfer = _JointTransfer(
                model, start, joints, moving.twist(first), (float(times[0]), lined_up)
            )
        except np.linalg.LinAlgError:
            return "a singular arm at the pre-grasp pose", f"t = {lined_up:.1f} s"
        positions, velocities = moving.positions.copy(), moving.velocities.copy()
        rotations, angular = moving.rotations.copy(), moving.angular.copy()
        for i, t in enumerate(times[:first]):
            positions[i], rotations[i], velocities[i], angular[i] = transfer.at(t)
        too_fast = _beyond_limits(problem, times[: first + 1], velocities[: first + 1])
        if too_fast is not None:
            return _TOO_FAST, too_fast
        attitudes = np.array([quaternion_from_matrix(r) for r in rotations])
        for i in range(1, len(attitudes)):  # one sign along the way, for slerp between samples
            attitudes[i] = _near(attitudes[i], attitudes[i - 1])
        return Trajectory(
            times=times,
            positions=positions,
            velocities=velocities,
            attitudes=attitudes,
            angular_velocities=angular,
            length=float(np.linalg.norm(np.diff(positions, axis=0), axis=1).sum()),
            duration=float(times[-1] - times[0]),
            statistics={"grasp_time": grasp_time},
        )

    def _check(self, problem: PathProblem, trajectory: Trajectory) -> tuple[str, str] | None:
        """Why the arm cannot fly ``trajectory`` (None when it can)."""
        assert isinstance(problem.model, ManipulatorModel)  # plan() refuses other models
        path = PosePath(
            problem.model,
            problem.start.configuration,
            trajectory,
            gain=self.params.ik_gain,
            damping=self.params.ik_damping,
            step=self.params.sample_step,
        )
        figures = path.tracking
        margin = np.radians(self.params.limit_margin_deg)
        if figures.min_limit_margin < margin:
            return "a joint near its limit", f"{np.degrees(figures.min_limit_margin):.1f} deg"
        start_det = problem.model.det_jjt(problem.start.configuration)
        if figures.min_det_jjt < min(self.params.min_det_jjt, 0.5 * start_det):
            return "near a singularity", f"det(J Jᵀ) {figures.min_det_jjt:.2e}"
        if figures.max_error > problem.goal.tolerance:
            return "the joints fall behind the path", f"{figures.max_error:.3g} m"
        return None


@dataclass(frozen=True)
class _GraspPoses:
    """The pose of DH frame n that holds the bar, moved out along the approach axis by
    the insertion's offset, at sample times: insertion and follow, and the pre-grasp
    pose before (world frame).

    Attributes
    ----------
    positions, velocities : ndarray (N, 3)
        Origin of frame n, m and m/s.
    rotations : ndarray (N, 3, 3)
        Frame n to world.
    angular : ndarray (N, 3)
        Angular velocity, rad/s (the body's).
    """

    positions: np.ndarray
    velocities: np.ndarray
    rotations: np.ndarray
    angular: np.ndarray

    @classmethod
    def along(
        cls,
        body: BodyPrediction,
        grasp: GraspGoal,
        times: np.ndarray,
        lined_up: float,
        params: FixtureInterceptParams,
        frame: ForwardKinematics,
    ) -> _GraspPoses:
        """The poses at ``times`` for an insertion from ``lined_up`` (s)."""
        approach = np.asarray(grasp.approach_axis)
        inserted, insert_rate, _ = minimum_jerk_profile(
            (times - lined_up) / params.insertion_time, params.insertion_time
        )
        offset = params.approach_distance * (1.0 - inserted)
        grasp_point = np.asarray(grasp.fixture) + grasp.tool_offset * approach
        out = body.axes(approach)
        spin = body.angular_velocities
        velocities = (
            body.point_velocities(grasp_point)
            - params.approach_distance * insert_rate[:, None] * out
            + offset[:, None] * np.cross(spin, out)
        )
        z_axis = body.axes(np.asarray(grasp.bar_axis))
        # a bar is held either way round: the way nearer the end effector's z at the start
        if z_axis[-1] @ frame.end_effector_rotation[:, 2] < 0.0:
            z_axis = -z_axis
        rotations = np.stack([-out, np.cross(z_axis, -out), z_axis], axis=-1)
        positions = body.points(grasp_point) + offset[:, None] * out
        return cls(positions, velocities, rotations, spin)

    def twist(self, row: int) -> np.ndarray:
        """``[v; ω]`` (6,) of the pose at sample ``row``."""
        return np.concatenate([self.velocities[row], self.angular[row]])


class _JointTransfer:
    """The transfer in joint space: from the start, at rest, to the pre-grasp joints,
    arriving with the joint rates that move the end effector as the pre-grasp pose
    moves (a quintic per joint: zero acceleration at both ends), so the arm meets no
    singularity a straight Cartesian move might cross."""

    def __init__(
        self,
        model: ManipulatorModel,
        start: np.ndarray,
        joints: np.ndarray,
        twist: np.ndarray,
        times: tuple[float, float],
    ) -> None:
        self.model, self.base = model, np.asarray(start[:7])
        self.origin = np.asarray(start[7:], dtype=float)
        self.goal = joints
        full = np.concatenate([self.base, joints])
        arm = model.jacobian(full)[:, 6:]
        square = arm.shape[0] == arm.shape[1]
        self.end_rates = (
            np.linalg.solve(arm, twist) if square else np.linalg.lstsq(arm, twist, rcond=None)[0]
        )
        self.start_time, self.duration = times[0], times[1] - times[0]

    def at(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Frame n's position, rotation, velocity and angular velocity at ``t`` (s)."""
        duration = self.duration
        tau = (t - self.start_time) / duration
        shape = tau**3 * (10 - 15 * tau + 6 * tau**2)
        shape_rate = 30 * tau**2 * (1 - tau) ** 2
        end = tau**3 * (-4 + 7 * tau - 3 * tau**2)
        end_rate = tau**2 * (-12 + 28 * tau - 15 * tau**2)
        step = self.goal - self.origin
        angles = self.origin + shape * step + duration * end * self.end_rates
        rates = (shape_rate * step) / duration + end_rate * self.end_rates
        kin = self.model.kinematics(np.concatenate([self.base, angles]))
        twist = kin.jacobian[:, 6:] @ rates
        return kin.end_effector, kin.rotations[-1], twist[:3], twist[3:]


_TOO_FAST = "the transfer is too fast for the limits"


def _beyond_limits(problem: PathProblem, times: np.ndarray, velocities: np.ndarray) -> str | None:
    """Which of the problem's speed and acceleration limits the samples pass (between
    consecutive samples for the acceleration); None within both."""
    speed = float(np.linalg.norm(velocities, axis=1).max())
    if speed > problem.max_speed * (1 + 1e-9):
        return f"{speed:.3g} m/s of {problem.max_speed:g}"
    if len(times) > 1:
        changes = np.linalg.norm(np.diff(velocities, axis=0), axis=1) / np.diff(times)
        if changes.max() > problem.max_acceleration * (1 + 1e-9):
            return f"{changes.max():.3g} m/s² of {problem.max_acceleration:g}"
    return None


def _pose_solution(
    model: ManipulatorModel, start: np.ndarray, position: np.ndarray, rotation: np.ndarray
) -> np.ndarray | None:
    """Joint angles near the start's that put frame n at ``position`` (m) turned by
    ``rotation``, the base held (damped Newton on the pose error); None when they do not
    converge to 1e-9 m and 1e-9 rad."""
    q = np.array(start, dtype=float)
    damping = 0.05
    for _ in range(200):
        kin = model.kinematics(q)
        turn = rotation_vector(quaternion_from_matrix(rotation @ kin.rotations[-1].T))
        error = np.concatenate([position - kin.end_effector, turn])
        if np.abs(error).max() < 1e-9:
            return q[7:]
        jac = kin.jacobian[:, 6:]
        q[7:] += jac.T @ np.linalg.solve(jac @ jac.T + damping**2 * np.eye(6), error)
    return None


def _out_of_reach(
    body: BodyPrediction,
    grasp: GraspGoal,
    shoulder: np.ndarray,
    reach: float,
    judged: np.ndarray,
    facing_matters: bool,
) -> tuple[str, str] | None:
    """Why the fixture cannot be held at the times ``judged`` (insertion and follow):
    out of the arm's reach from the shoulder, or (when ``facing_matters``) facing away
    from it."""
    fixture = body.points(np.asarray(grasp.fixture))[judged]
    approach = body.axes(np.asarray(grasp.approach_axis))[judged]
    offset = shoulder - fixture
    distance = np.linalg.norm(offset, axis=1)
    if np.any(distance > 0.95 * reach):
        return "out of the arm's reach", f"{distance.max():.2f} m of {reach:.2f} m"
    facing = np.einsum("ij,ij->i", offset, approach) / distance
    if facing_matters and np.any(facing < 0.5):
        return "the fixture faces away", f"{np.degrees(np.arccos(facing.min())):.0f} deg"
    return None


def _sample_count(span: float, p: FixtureInterceptParams) -> int:
    """Samples every ``sample_step`` from the start that cover ``span`` (s)."""
    return int(np.ceil(span / p.sample_step - 1e-9)) + 1


def _still_goal(problem: PathProblem, frame: ForwardKinematics) -> GraspGoal:
    """A problem without a grasp as one: the goal region's centre a fixture that does not
    move, to be met with the end effector's attitude at the start."""
    rotation = frame.end_effector_rotation
    track = ObjectTrack(
        id=-1,
        kind=ObjectKind.TARGET,
        time=problem.start.time,
        position=problem.goal.position,
        velocity=np.zeros(3),
        radius=problem.goal.tolerance,
        attitude=np.array([0.0, 0.0, 0.0, 1.0]),
        angular_velocity=np.zeros(3),
        inertia=np.eye(3),
    )
    return GraspGoal(
        target=track,
        fixture=np.zeros(3),
        approach_axis=-rotation[:, 0],
        bar_axis=rotation[:, 2],
        tool_offset=0.0,
    )


def _summary(refusals: dict[str, tuple[int, str]]) -> str:
    """Why no grasp time was accepted: each kind of refusal, how many times, and the
    figure of its last case."""
    if not refusals:
        return "no grasp time within the horizon"
    return "; ".join(
        f"{kind} ({count}x, last {detail})" for kind, (count, detail) in refusals.items()
    )


def _near(q: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """``q`` or ``-q``, whichever is nearer ``reference`` (the shorter slerp)."""
    return q if float(q @ reference) >= 0.0 else -q


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the fixture intercept planner."""
    return [FixtureInterceptPlanner]
