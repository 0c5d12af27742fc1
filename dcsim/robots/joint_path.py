"""Joint references that carry a manipulator's end effector along a path, the base held.

The end-effector path ``x_d(t)`` is the cubic Hermite curve through a trajectory's
samples (positions and velocities): its position and velocity are continuous, its
acceleration is linear between samples (it may jump at a sample). It becomes joint
angles by closed-loop inverse kinematics at the rate level (the velocity form of the
the space manipulator thesis's eqs 3.12–3.13):

    θ̇ = J⁺(θ) (ẋ_d(t) + K (x_d(t) − x(θ)))

with ``J`` the position rows of the joint columns of eq. 3.8 (3 × n, the base held at
its start pose), ``J⁺ = Jᵀ (J Jᵀ)⁻¹`` its pseudo-inverse, which resolves the arm's
redundancy by the least joint rates, and ``K`` (1/s) a gain that pulls the integration's
drift back onto the path. The equation is integrated with scipy's DOP853 to tight
tolerances; the joint accelerations are the central difference of ``θ̇`` along the
solution. Angles, rates and accelerations are therefore consistent with one another,
which a computed-torque controller needs to track them to its model's accuracy.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicHermiteSpline

from dcsim.messages import Trajectory
from dcsim.robots.kinematics import Array
from dcsim.robots.manipulator import ManipulatorModel

_DIFFERENCE_STEP = 1e-4
"""Time step of the central difference that gives the joint accelerations, s."""


@dataclass(frozen=True)
class JointSample:
    """The references at one instant.

    Attributes
    ----------
    angles, rates, accelerations : ndarray (n,)
        Joint angles (rad), rates (rad/s) and accelerations (rad/s²).
    end_effector, end_effector_velocity : ndarray (3,)
        The end-effector path's position (m) and velocity (m/s), world frame.
    """

    angles: Array
    rates: Array
    accelerations: Array
    end_effector: Array
    end_effector_velocity: Array


class SingularPath(ValueError):
    """The path leads the arm into a singularity (``det(J Jᵀ)`` at its tolerance), or
    starts in one."""


@dataclass(frozen=True)
class _Singularity:
    """scipy's terminal event of a joint path: ``det(J Jᵀ)`` falls to its tolerance.

    Attributes
    ----------
    det_jjt : callable
        ``det(J Jᵀ)`` of the joint angles (rad).
    tolerance : float
        Value of ``det(J Jᵀ)`` at which the integration stops.
    """

    det_jjt: Callable[[Array], float]
    tolerance: float
    terminal: ClassVar[bool] = True

    def __call__(self, t: float, theta: Array) -> float:
        """Zero where the arm meets the tolerance; ``t`` (s) is unused."""
        return self.det_jjt(theta) - self.tolerance


class JointPath:
    """Joint references along an end-effector trajectory (see the module).

    Parameters
    ----------
    model : ManipulatorModel
        The robot's model.
    start : array_like (7 + n,)
        The state the path starts from; its base pose is held throughout.
    trajectory : Trajectory
        The end effector's path, world frame; held at its ends outside its times.
    gain : float
        ``K``, 1/s.
    singular_tolerance : float
        ``det(J Jᵀ)`` (m⁶) at or below which the path is refused.

    Raises
    ------
    SingularPath
        If the arm starts in a singularity (an arm of fewer than three joints always
        does) or meets one on the way.
    ValueError
        If the trajectory cannot be followed (fewer than two samples, times not
        increasing).
    """

    def __init__(
        self,
        model: ManipulatorModel,
        start: np.ndarray,
        trajectory: Trajectory,
        gain: float = 20.0,
        singular_tolerance: float = 1e-9,
    ) -> None:
        self.model = model
        self._base = np.asarray(start[:7], dtype=float)
        self.gain = gain
        self.singular_tolerance = singular_tolerance
        if model.n_joints < 3:
            raise SingularPath(
                f"an arm of {model.n_joints} joint(s) cannot move its end effector freely in "
                "three dimensions: give at least three links"
            )
        if self._det_jjt(np.asarray(start[7:], dtype=float)) <= singular_tolerance:
            raise SingularPath("the arm starts in a singularity (det(J Jᵀ) at its tolerance)")
        if len(trajectory.times) < 2 or np.any(np.diff(trajectory.times) <= 0.0):
            raise ValueError("the path needs two samples or more at increasing times")
        self.start_time, self.end_time = float(trajectory.times[0]), float(trajectory.times[-1])
        self._path = CubicHermiteSpline(
            trajectory.times, trajectory.positions, trajectory.velocities, extrapolate=False
        )
        self._initial = np.asarray(start[7:], dtype=float)
        self._final = self._initial
        self._angles: Callable[[float], Array] | None = None
        if self.end_time > self.start_time:
            self._angles = self._integrate(self._initial)

    def _integrate(self, angles: Array) -> Callable[[float], Array]:
        """Solve the module's equation from ``angles``; keep the final angles and return
        the dense solution."""
        singular = _Singularity(self._det_jjt, self.singular_tolerance)
        try:
            solution = self._solve(angles, singular)
        except np.linalg.LinAlgError:
            raise SingularPath("the arm meets a singularity on the path") from None
        if solution.status == 1:
            raise SingularPath(
                f"the arm meets a singularity at t = {solution.t_events[0][0]:.3f} s on the path"
            )
        if solution.status != 0:
            raise SingularPath(f"the joint path could not be integrated: {solution.message}")
        self._final = solution.y[:, -1]
        return solution.sol

    def _solve(self, angles: Array, singular: _Singularity) -> Any:
        """scipy's DOP853 over the path, to 1e-8 relative, stopping at a singularity."""
        return solve_ivp(
            self._rates,
            (self.start_time, self.end_time),
            angles,
            method="DOP853",
            rtol=1e-8,
            atol=1e-10,
            dense_output=True,
            events=singular,
        )

    def _state(self, theta: Array) -> Array:
        return np.concatenate([self._base, theta])

    def _det_jjt(self, theta: Array) -> float:
        return self.model.det_jjt(self._state(theta), position_only=True)

    def _path_at(self, t: float) -> tuple[Array, Array, Array]:
        """End-effector path position, velocity and acceleration at ``t`` (held at the ends)."""
        inside = min(max(t, self.start_time), self.end_time)
        moving = self.start_time < t < self.end_time
        position = self._path(inside)
        if not moving:
            return position, np.zeros(3), np.zeros(3)
        return position, self._path(t, 1), self._path(t, 2)

    def _rates(self, t: float, theta: Array) -> Array:
        """``θ̇`` of the module's equation."""
        kin = self.model.kinematics(self._state(theta))
        jac = kin.jacobian[:3, 6:]
        position, velocity, _ = self._path_at(t)
        drift = position - kin.end_effector
        wanted = velocity + self.gain * drift
        return jac.T @ np.linalg.solve(jac @ jac.T, wanted)

    def angles_at(self, t: float) -> Array:
        """Joint angles at ``t`` (s), held at the path's ends, rad."""
        if t <= self.start_time:
            return self._initial.copy()
        if t >= self.end_time:
            return self._final.copy()
        assert self._angles is not None  # integrated whenever end_time > start_time
        return self._angles(t)

    def at(self, t: float) -> JointSample:
        """The references at time ``t`` (s); before and after the path, at rest at its ends."""
        angles = self.angles_at(t)
        position, velocity, _ = self._path_at(t)
        if not self.start_time < t < self.end_time:
            zero = np.zeros_like(angles)
            return JointSample(angles, zero, zero.copy(), position, velocity)
        h = min(_DIFFERENCE_STEP, t - self.start_time, self.end_time - t)
        before = self._rates(t - h, self.angles_at(t - h))
        after = self._rates(t + h, self.angles_at(t + h))
        rates = self._rates(t, angles)
        return JointSample(angles, rates, (after - before) / (2 * h), position, velocity)
