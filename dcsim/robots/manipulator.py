"""The space manipulator's model: kinematics, Jacobians, inverse kinematics, M and C.

Conventions (DESIGN.md, the source thesis's eq. 4.4), world frame throughout:

- ``q = [r_b (3), quaternion x, y, z, w (4), θ (n)]``: the base's centre of mass (m), its
  attitude (base to world) and the joint angles (rad);
- ``qd = [v_b (3), ω_b (3), θ̇ (n)]``: the base centre of mass's velocity (m/s), the
  base's angular velocity (rad/s) and the joint rates (rad/s);
- generalised forces in the same order: base force (N) at the centre of mass, base
  torque (N·m), joint torques (N·m).

The robot's geometry follows :mod:`dcsim.robots.dh`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from dcsim.geometry import quaternion_from_rotation_vector, quaternion_multiply
from dcsim.robots.dh import DHRobot
from dcsim.robots.kinematics import (
    Array,
    DHArrays,
    Kinematics,
    compiled,
    kinematics,
    state_vector,
)
from dcsim.robots.urdf import urdf_text

IKStatus = Literal["converged", "unreachable", "singular", "not-converged"]


@dataclass(frozen=True)
class ForwardKinematics:
    """Every frame of one configuration, world frame.

    ``numpy.asarray(fk)`` is the end-effector position, so the result can stand where a
    position is expected.

    Attributes
    ----------
    rotations : ndarray (n + 1, 3, 3)
        DH frames 0 … n, frame to world; ``rotations[n]`` is the end effector's attitude.
    origins : ndarray (n + 1, 3)
        Origins of DH frames 0 … n, m; ``origins[i − 1]`` lies on joint i's axis.
    joint_axes : ndarray (n, 3)
        Unit rotation axis of each joint.
    link_coms : ndarray (n, 3)
        Centre of mass of each link, m.
    end_effector : ndarray (3,)
        End-effector position (origin of frame n), m.
    """

    rotations: Array
    origins: Array
    joint_axes: Array
    link_coms: Array
    end_effector: Array

    def __array__(self, dtype=None, copy=None) -> Array:
        return np.asarray(self.end_effector, dtype=dtype)

    @property
    def end_effector_rotation(self) -> Array:
        """End-effector attitude (frame n to world), (3, 3)."""
        return self.rotations[-1]


@dataclass(frozen=True)
class InverseKinematicsResult:
    """Outcome of :meth:`ManipulatorModel.inverse_kinematics`.

    Attributes
    ----------
    q : ndarray (7 + n,)
        Last iterate (the seed if nothing was tried).
    status : str
        ``"converged"``, ``"unreachable"`` (the target lies beyond the arm's reach from the
        held base), ``"singular"`` (``det(J Jᵀ)`` fell to the singular tolerance without
        damping) or ``"not-converged"`` (iterations ran out).
    error : float
        End-effector distance to the target at ``q``, m.
    iterations : int
        Newton steps taken.
    """

    q: Array
    status: IKStatus
    error: float
    iterations: int

    @property
    def converged(self) -> bool:
        """Whether the end effector reached the target within the tolerance."""
        return self.status == "converged"


class ManipulatorModel:
    """Kinematic and dynamic model of a DH space manipulator (see the module's conventions).

    Parameters
    ----------
    robot : DHRobot
        The base and the DH table of the arm.
    """

    def __init__(self, robot: DHRobot) -> None:
        self.robot = robot
        self._dh = DHArrays.of(robot)

    @property
    def n_joints(self) -> int:
        """Number of joints ``n``."""
        return self.robot.n_joints

    @property
    def reach(self) -> float:
        """Largest distance from the first joint's axis origin to the end effector, m."""
        return self.robot.reach

    def urdf(self) -> str:
        """URDF text of the robot (:func:`dcsim.robots.urdf.urdf_text`)."""
        return urdf_text(self.robot)

    def kinematics(self, q: ArrayLike) -> Kinematics:
        """Every world-frame kinematic quantity of state ``q`` (7 + n,)."""
        return kinematics(self._dh, q)

    def forward_kinematics(self, q: ArrayLike) -> ForwardKinematics:
        """Every joint frame and the end effector of state ``q`` (eqs 3.1–3.6, 3.10).

        Parameters
        ----------
        q : array_like (7 + n,)
            Base centre of mass (m), base quaternion ``[x, y, z, w]``, joint angles (rad).

        Returns
        -------
        ForwardKinematics
            World frame; ``numpy.asarray`` of it is the end-effector position, m.
        """
        kin = self.kinematics(q)
        return ForwardKinematics(
            rotations=kin.rotations,
            origins=kin.origins,
            joint_axes=kin.axes,
            link_coms=kin.coms,
            end_effector=kin.end_effector,
        )

    def jacobian(self, q: ArrayLike) -> Array:
        """Generalised Jacobian of eq. 3.8: ``[v_ee; ω_ee] = J qd``.

        Parameters
        ----------
        q : array_like (7 + n,)
            State.

        Returns
        -------
        ndarray (6, 6 + n)
            Rows: end-effector linear velocity (m/s), angular velocity (rad/s), world frame;
            columns in the order of ``qd = [v_b, ω_b, θ̇]``.
        """
        return self.kinematics(q).jacobian

    def free_floating_jacobian(self, q: ArrayLike) -> Array:
        """Jacobian of the free-floating robot at zero momentum: ``[v_ee; ω_ee] = J* θ̇``.

        With no external force or torque on the base and zero linear and angular
        momentum, the base moves as ``[v_b; ω_b] = −H_0⁻¹ H_0m θ̇`` (the top rows of
        ``M``), so ``J* = J_m − J_b H_0⁻¹ H_0m``.

        Parameters
        ----------
        q : array_like (7 + n,)
            State.

        Returns
        -------
        ndarray (6, n)
            Rows: end-effector linear (m/s) and angular (rad/s) velocity, world frame.
        """
        jac, m = self.jacobian(q), self.mass_matrix(q)
        return jac[:, 6:] - jac[:, :6] @ np.linalg.solve(m[:6, :6], m[:6, 6:])

    def det_jjt(self, q: ArrayLike, position_only: bool = False) -> float:
        """``det(J Jᵀ)`` of the arm's part of eq. 3.8 (the joint columns): zero at a
        kinematic singularity (eq. 3.14).

        Parameters
        ----------
        q : array_like (7 + n,)
            State.
        position_only : bool
            Use only the linear-velocity rows (3 × n) instead of all six (6 × n).

        Returns
        -------
        float
            m⁶ (position only) or m⁶·(rad)⁶-mixed units of the 6 × n Jacobian.
        """
        arm = self.jacobian(q)[: 3 if position_only else 6, 6:]
        return float(np.linalg.det(arm @ arm.T))

    def mass_matrix(self, q: ArrayLike) -> Array:
        """Generalised mass matrix ``M(q)`` of eqs 4.10–4.21.

        Parameters
        ----------
        q : array_like (7 + n,)
            State.

        Returns
        -------
        ndarray (6 + n, 6 + n)
            Symmetric positive definite, in the order of ``qd``: kg, kg·m, kg·m².
        """
        dh = self._dh
        return compiled().mass_matrix(state_vector(q, self.n_joints), dh.links, dh.bodies, dh.mount)

    def coriolis_matrix(self, q: ArrayLike, qd: ArrayLike) -> Array:
        """Coriolis and centrifugal matrix ``C(q, q̇)`` of eqs 4.23–4.33.

        Parameters
        ----------
        q : array_like (7 + n,)
            State.
        qd : array_like (6 + n,)
            Generalised velocity ``[v_b, ω_b, θ̇]``, world frame.

        Returns
        -------
        ndarray (6 + n, 6 + n)
            ``C`` with ``M q̈ + C q̇ = τ`` and ``Ṁ − 2C`` skew-symmetric.
        """
        return self.dynamics(q, qd)[1]

    def dynamics(self, q: ArrayLike, qd: ArrayLike) -> tuple[Array, Array]:
        """``M(q)`` and ``C(q, q̇)`` from one kinematics pass: the results of
        :meth:`mass_matrix` and :meth:`coriolis_matrix`, for less than the two calls cost.

        Parameters
        ----------
        q : array_like (7 + n,)
            State.
        qd : array_like (6 + n,)
            Generalised velocity ``[v_b, ω_b, θ̇]``, world frame.

        Returns
        -------
        mass : ndarray (6 + n, 6 + n)
            ``M(q)``: kg, kg·m, kg·m².
        coriolis : ndarray (6 + n, 6 + n)
            ``C(q, q̇)``: kg/s, kg·m/s, kg·m²/s.
        """
        dh, q = self._dh, state_vector(q, self.n_joints)
        return compiled().mass_and_coriolis(q, self._velocity(qd), dh.links, dh.bodies, dh.mount)

    def bias(self, q: ArrayLike, qd: ArrayLike) -> Array:
        """Velocity-dependent generalised force ``C(q, q̇) q̇`` (6 + n,): N, N·m, N·m."""
        qd = self._velocity(qd)
        return self.coriolis_matrix(q, qd) @ qd

    def centre_of_mass(self, q: ArrayLike) -> Array:
        """Centre of mass of the whole robot (base and links), world frame, m (3,)."""
        return self._centre(self.kinematics(q))

    def momentum(self, q: ArrayLike, qd: ArrayLike) -> Array:
        """Linear momentum (kg·m/s) and angular momentum about the base's centre of mass
        (kg·m²/s) of the whole robot, world frame: the top rows of ``M q̇`` (6,)."""
        qd = self._velocity(qd)
        return self.mass_matrix(q)[:6] @ qd

    def _velocity(self, qd: ArrayLike) -> Array:
        qd = np.ascontiguousarray(qd, dtype=float)
        if qd.shape != (6 + self.n_joints,):
            raise ValueError(f"qd must have 6 + {self.n_joints} entries, got shape {qd.shape}")
        return qd

    def inverse_kinematics(
        self,
        target: ArrayLike,
        q0: ArrayLike,
        base: Literal["held", "floating", "centre-of-mass"] = "held",
        damping: float = 0.0,
        tolerance: float = 1e-10,
        max_iterations: int = 100,
        singular_tolerance: float = 1e-12,
    ) -> InverseKinematicsResult:
        """State that puts the end effector at ``target``, by the thesis's Newton iteration
        ``q_{k+1} = q_k + J* e`` (eqs 3.12–3.15), never raising on failure.

        Parameters
        ----------
        target : array_like (3,)
            End-effector position, world frame, m.
        q0 : array_like (7 + n,)
            Seed state.
        base : {"held", "floating", "centre-of-mass"}
            ``"held"``: only the joints move (the position rows of eq. 3.8's joint
            columns). ``"floating"``: base position and attitude are unknowns too (all
            columns of eq. 3.8; attitude steps are world rotation vectors).
            ``"centre-of-mass"``: the joints move, the base's attitude is held and its
            position follows so that the robot's centre of mass stays where it is (the
            base's translation free, as under partial base control at zero momentum):
            the Jacobian is ``J_θ − J_v M_vθ / m_total`` (position rows), and after each
            step the base is placed to restore the centre of mass exactly.
        damping : float
            ``λ`` of the damped variant ``J* = Jᵀ (J Jᵀ + λ² 1)⁻¹``, m; 0 is eq. 3.12.
        tolerance : float
            Distance to the target that counts as reached, m.
        max_iterations : int
            Most Newton steps.
        singular_tolerance : float
            Undamped steps stop as ``"singular"`` when ``det(J Jᵀ)`` is at most this, m⁶.

        Returns
        -------
        InverseKinematicsResult
        """
        target = np.asarray(target, dtype=float)
        q = np.array(q0, dtype=float)
        kin = self.kinematics(q)
        centre = self._centre(kin)
        if base != "floating" and np.linalg.norm(target - kin.origins[0]) > self.robot.reach:
            return self._ik_result(q, target, "unreachable", 0)
        for iteration in range(max_iterations):
            error = target - kin.end_effector
            if np.linalg.norm(error) <= tolerance:
                return self._ik_result(q, target, "converged", iteration)
            jac = self._ik_jacobian(kin, base)
            jjt = jac @ jac.T
            if damping == 0.0 and np.linalg.det(jjt) <= singular_tolerance:
                return self._ik_result(q, target, "singular", iteration)
            step = jac.T @ np.linalg.solve(jjt + damping**2 * np.eye(3), error)
            q = self._advance(q, step, base)
            kin = self.kinematics(q)
            if base == "centre-of-mass":  # a pure translation of the whole robot
                q[:3] += centre - self._centre(kin)
                kin = self.kinematics(q)
        distance = np.linalg.norm(target - kin.end_effector)
        status: IKStatus = "converged" if distance <= tolerance else "not-converged"
        return self._ik_result(q, target, status, max_iterations)

    def _centre(self, kin: Kinematics) -> Array:
        """The whole robot's centre of mass in ``kin``, m."""
        masses = self._dh.bodies[:, 0]
        return masses @ kin.body_coms / masses.sum()

    def _ik_jacobian(self, kin: Kinematics, base: str) -> Array:
        """The end-effector position's Jacobian over the unknowns of ``base``'s mode."""
        jac = kin.jacobian[:3]
        if base == "held":
            return jac[:, 6:]
        if base == "floating":
            return jac
        masses = self._dh.bodies[:, 0]
        # the centre of mass's velocity per joint rate, base still: Σ m_i J_v,i / m_total
        centre_rates = np.einsum("b,bij->ij", masses, kin.body_jacobians[:, :3, 6:]) / masses.sum()
        return jac[:, 6:] - jac[:, :3] @ centre_rates

    def _advance(self, q: Array, step: Array, base: str) -> Array:
        q = q.copy()
        q[7:] += step[-self.n_joints :]
        if base == "floating":
            q[:3] += step[:3]
            turned = quaternion_multiply(quaternion_from_rotation_vector(step[3:6]), q[3:7])
            q[3:7] = turned / np.linalg.norm(turned)
        return q

    def _ik_result(
        self, q: Array, target: Array, status: IKStatus, iterations: int
    ) -> InverseKinematicsResult:
        error = float(np.linalg.norm(target - self.kinematics(q).end_effector))
        return InverseKinematicsResult(q=q, status=status, error=error, iterations=iterations)


def manipulator_model(robot: DHRobot) -> ManipulatorModel:
    """The model of a manipulator given by its DH description.

    Parameters
    ----------
    robot : DHRobot
        Base and DH table (e.g. :func:`dcsim.robots.dh.thesis_manipulator`).

    Returns
    -------
    ManipulatorModel
    """
    return ManipulatorModel(robot)
