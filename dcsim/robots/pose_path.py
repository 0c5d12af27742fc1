"""Joint references that carry a manipulator's end effector along a pose trajectory.

Where :class:`~dcsim.robots.joint_path.JointPath` follows an end-effector position, a
:class:`PosePath` follows a full pose: position and attitude of DH frame n, as a
grasp needs. The end-effector twist ``ν_d = [ẋ_d; ω_d]`` of the trajectory becomes joint
rates by closed-loop inverse kinematics at the rate level, the base held at its start
pose:

    θ̇ = J⁺(θ) (ν_d(t) + K e(t, θ)),    e = [x_d − x(θ); φ(R_d Rᵀ)]

with ``J`` the 6 × n joint columns of the generalised Jacobian (eq. 3.8 of the space
manipulator thesis), ``φ`` the rotation vector of the attitude error, ``K`` a gain
(1/s) and ``J⁺ = Jᵀ (J Jᵀ + λ² 1)⁻¹`` the damped pseudo-inverse, whose small ``λ``
keeps the rates bounded near a singularity without changing them elsewhere. The
equation is integrated by classical Runge–Kutta at a fixed step; the path reports how
close it came to a singularity (the least ``det(J Jᵀ)``) and to the joint limits, so
that a planner can judge a trajectory before the arm flies it.

The trajectory's positions and velocities are a cubic Hermite curve; its attitudes are
slerped and its angular velocities linear between samples (sample it densely).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicHermiteSpline

from dcsim.geometry import quaternion_from_matrix, rotation_vector
from dcsim.messages import Trajectory
from dcsim.robots.joint_path import JointSample
from dcsim.robots.kinematics import Array, rotation_matrix
from dcsim.robots.manipulator import ManipulatorModel


@dataclass(frozen=True)
class PoseTracking:
    """How well a pose path's joints can follow it.

    Attributes
    ----------
    min_det_jjt : float
        Least ``det(J Jᵀ)`` of the 6 × n arm Jacobian along the path.
    min_limit_margin : float
        Least distance of any joint from its nearer limit along the path, rad
        (``inf`` for unlimited joints; negative when a limit is passed).
    max_error : float
        Largest end-effector position error of the integrated joints from the path, m.
    max_rate : float
        Largest joint rate along the path, rad/s.
    """

    min_det_jjt: float
    min_limit_margin: float
    max_error: float
    max_rate: float


class PosePath:
    """Joint references along an end-effector pose trajectory (see the module).

    Parameters
    ----------
    model : ManipulatorModel
        The robot's model.
    start : array_like (7 + n,)
        The state the path starts from; its base pose is held throughout.
    trajectory : Trajectory
        Position, velocity, attitude and angular velocity of DH frame n, world frame.
    gain : float
        ``K``, 1/s.
    damping : float
        ``λ`` of the damped pseudo-inverse (m, and rad for the attitude rows).
    step : float
        Integration step, s.

    Attributes
    ----------
    tracking : PoseTracking
        The path's figures.

    Raises
    ------
    ValueError
        If the trajectory has no attitudes, fewer than two samples or times that do not
        increase.
    """

    def __init__(
        self,
        model: ManipulatorModel,
        start: Array,
        trajectory: Trajectory,
        gain: float = 10.0,
        damping: float = 1e-3,
        step: float = 0.01,
    ) -> None:
        times = np.asarray(trajectory.times, dtype=float)
        if trajectory.attitudes is None:
            raise ValueError("a pose path needs the trajectory's attitudes")
        if len(times) < 2 or np.any(np.diff(times) <= 0.0):
            raise ValueError("the path needs two samples or more at increasing times")
        self.model, self.gain, self.damping = model, gain, damping
        self._base = np.asarray(start[:7], dtype=float)
        self._trajectory = trajectory
        self._curve = CubicHermiteSpline(times, trajectory.positions, trajectory.velocities)
        self.start_time, self.end_time = float(times[0]), float(times[-1])
        count = max(2, int(np.ceil((self.end_time - self.start_time) / step)) + 1)
        self._times = np.linspace(self.start_time, self.end_time, count)
        angles, rates, figures = self._integrate(np.asarray(start[7:], dtype=float))
        self._angles = CubicHermiteSpline(self._times, angles, rates)
        limits = np.array([link.joint_limits for link in model.robot.links])
        margin = np.minimum(angles - limits[:, 0], limits[:, 1] - angles)
        self.tracking = PoseTracking(
            min_det_jjt=figures[0],
            min_limit_margin=float(margin.min()),
            max_error=figures[1],
            max_rate=float(np.abs(rates).max()),
        )

    def _twist(self, t: float) -> tuple[Array, Array, Array]:
        """Wanted position (m), attitude (3×3) and twist ``[v; ω]`` of frame n at ``t``."""
        inside = min(max(t, self.start_time), self.end_time)
        trajectory = self._trajectory
        twist = np.zeros(6)
        if self.start_time < t < self.end_time:
            twist[:3] = self._curve(t, 1)
            if trajectory.angular_velocities is not None:
                rates = trajectory.angular_velocities
                twist[3:] = [np.interp(t, trajectory.times, rates[:, k]) for k in range(3)]
        return self._curve(inside), rotation_matrix(trajectory.attitude_at(inside)), twist

    def _rates(self, t: float, theta: Array) -> tuple[Array, float, float]:
        """``θ̇`` (rad/s), ``det(J Jᵀ)`` and the position error (m) at ``t``."""
        kin = self.model.kinematics(np.concatenate([self._base, theta]))
        position, attitude, twist = self._twist(t)
        turn = quaternion_from_matrix(attitude @ kin.rotations[-1].T)  # R_d Rᵀ
        error = np.concatenate([position - kin.end_effector, rotation_vector(turn)])
        jac = kin.jacobian[:, 6:]
        jjt = jac @ jac.T
        rates = jac.T @ np.linalg.solve(
            jjt + self.damping**2 * np.eye(6), twist + self.gain * error
        )
        return rates, float(np.linalg.det(jjt)), float(np.linalg.norm(error[:3]))

    def _integrate(self, theta: Array) -> tuple[Array, Array, tuple[float, float]]:
        """Angles and rates at :attr:`_times` by classical Runge–Kutta; the least
        ``det(J Jᵀ)`` and the largest position error on the way."""
        times = self._times
        angles = np.empty((len(times), theta.size))
        rates = np.empty_like(angles)
        least, worst = np.inf, 0.0
        for i, t in enumerate(times):
            angles[i] = theta
            k1, det, error = self._rates(t, theta)
            rates[i] = k1
            least, worst = min(least, det), max(worst, error)
            if i + 1 == len(times):
                break
            h = times[i + 1] - t
            k2 = self._rates(t + h / 2, theta + h / 2 * k1)[0]
            k3 = self._rates(t + h / 2, theta + h / 2 * k2)[0]
            k4 = self._rates(t + h, theta + h * k3)[0]
            theta = theta + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        return angles, rates, (least, worst)

    def at(self, t: float) -> JointSample:
        """The references at time ``t`` (s); before and after the path, at rest at its ends."""
        inside = min(max(t, self.start_time), self.end_time)
        angles = self._angles(inside)
        position = self._curve(inside)
        if not self.start_time < t < self.end_time:
            zero = np.zeros_like(angles)
            return JointSample(angles, zero, zero.copy(), position, np.zeros(3))
        return JointSample(
            angles, self._angles(t, 1), self._angles(t, 2), position, self._curve(t, 1)
        )
