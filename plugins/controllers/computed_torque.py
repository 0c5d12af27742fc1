"""``computed-torque`` controller: full control of a space manipulator by feedback
linearisation (the space manipulator thesis, eqs 6.1–6.7).

With the robot's own model ``M(q)``, ``C(q, q̇)`` (on ``RobotSpec.model``, a
:class:`~dcsim.api.RobotModel`, both from one call of its ``dynamics(q, q̇)`` per tick)
the generalised force

    τ = M(q) u + C(q, q̇) q̇,      u = q̈_d + K_D ė + K_P e                (6.1, 6.4)

turns the equation of motion ``M q̈ + C q̇ = τ`` into ``q̈ = u``: every generalised
coordinate becomes a double integrator, and the tracking error obeys
``ë + K_D ė + K_P e = 0`` (6.6). ``e = q_d − q`` (eq. 6.5).

Generalised coordinates, in the order of ``q̇ = [v_base, ω_base, θ̇]`` (DESIGN.md, the
thesis's eq. 4.4), world frame, base at its centre of mass:

- base position: ``e_r = r_d − r``, ``ė_r = v_d − v``, feed-forward ``a_d``;
- base attitude: the attitude has four quaternion numbers but three velocity components
  ``ω``, so its error is the world-frame rotation vector that turns the estimated
  attitude onto the reference, ``e_α = rotvec(q_d ⊗ q⁻¹)``; it sits in the ``ω`` slots
  of ``e``, with ``ė_α = ω_d − ω`` and feed-forward ``ω̇_d``. To first order in the error
  ``d e_α / dt = ω_d − ω``, so near the reference the attitude loop is the same double
  integrator as the others. A reference without attitude leaves ``e_α = 0``: the base
  then only follows the reference's angular velocity (zero: it is kept from turning);
- joints: ``e_θ = θ_d − θ``, ``ė_θ = θ̇_d − θ̇``, feed-forward ``θ̈_d``. A reference with
  no joint entries holds the joints still (``θ̇_d = 0``, no angle error).

The generalised force's first three entries are the base force (N), the next three the
base torque (N·m), both world frame, the rest the joint torques (N·m); each is clipped
to the robot's limits (``max_force`` and ``max_torque`` on the vectors' magnitudes,
``joint_torque_limits`` per joint). While no limit binds, the law is exact on the model.

Gains are diagonal, ``K_P = k_P 1`` and ``K_D = k_D 1``: the thesis's ``k_P = 1``,
``k_D = 10`` by default (eqs 7.2–7.3), or, when ``bandwidth`` is set, placed at the poles
of ``s² + 2ζω s + ω²`` by Ackermann's formula (:func:`design_gains` of the ``pd``
controller: ``k_P = ω²``, ``k_D = 2ζω``).
"""

from __future__ import annotations

import numpy as np
from dcsim_plugins.controllers.pd import design_gains

from dcsim.api import (
    Command,
    Controller,
    PluginError,
    PluginParams,
    Reference,
    RobotSpec,
    StateEstimate,
    Surroundings,
    clip_norm,
    hookimpl,
    quantity,
    quaternion_conjugate,
    quaternion_multiply,
    rotation_vector,
)


class ComputedTorqueParams(PluginParams):
    """Parameters of :class:`ComputedTorqueController`."""

    kp: float = quantity(
        1.0,
        unit="1/s^2",
        gt=0,
        description="Proportional gain k_P, every diagonal entry of K_P (thesis eq. 7.2); "
        "ignored when bandwidth is set.",
    )
    kd: float = quantity(
        10.0,
        unit="1/s",
        gt=0,
        description="Derivative gain k_D, every diagonal entry of K_D (thesis eq. 7.3); "
        "ignored when bandwidth is set.",
    )
    bandwidth: float | None = quantity(
        None,
        unit="rad/s",
        gt=0,
        description="Natural frequency ω of each closed loop; when set, k_P and k_D are "
        "placed from it and damping (unset: kp and kd are used as given).",
    )
    damping: float = quantity(
        1.0, gt=0, le=10, description="Damping ratio ζ of each closed loop, used with bandwidth."
    )


class ComputedTorqueController(Controller):
    """Computed-torque (feedback-linearising) full control of a space manipulator."""

    name = "computed-torque"
    summary = "Computed torque: full control of base and joints through the model's M and C"
    Params = ComputedTorqueParams
    params: ComputedTorqueParams
    robots = ("manipulator",)

    def reset(self, robot: RobotSpec) -> None:
        """Take the model and limits of ``robot`` and set the gains.

        Raises
        ------
        PluginError
            If ``robot`` carries no manipulator model (a free flyer), or its joint torque
            limits do not match the model's joints.
        """
        model = robot.model
        if model is None:
            raise PluginError(
                f"controller '{self.name}' needs a manipulator's model (mass and Coriolis "
                "matrices) on RobotSpec.model, got none; use it with robot.type: "
                "manipulator, or choose a free-flyer controller such as 'pd'"
            )
        n = model.n_joints
        if robot.joint_torque_limits.shape != (n,):
            raise PluginError(
                f"controller '{self.name}': the robot has {n} joints but "
                f"{len(robot.joint_torque_limits)} joint torque limits"
            )
        self.robot, self.model, self.n_joints = robot, model, n
        if self.params.bandwidth is None:
            self.kp, self.kd = self.params.kp, self.params.kd
        else:
            self.kp, self.kd = design_gains(self.params.bandwidth, self.params.damping)

    def command(
        self,
        time: float,
        estimate: StateEstimate,
        reference: Reference,
        surroundings: Surroundings,
    ) -> Command:
        """Generalised force of eq. 6.7, split into base force, base torque and joint
        torques and clipped to the robot's limits."""
        q, qd = generalised_state(estimate)
        u = self.outer_loop(estimate, reference)
        mass, coriolis = self.model.dynamics(q, qd)
        tau = mass @ u + coriolis @ qd
        return self.limited(tau[:3], tau[3:6], tau[6:])

    def outer_loop(self, estimate: StateEstimate, reference: Reference) -> np.ndarray:
        """``u = q̈_d + K_D ė + K_P e`` (eq. 6.4) over all 6 + n generalised coordinates."""
        error, rate_error, feed_forward = tracking_errors(estimate, reference, self.n_joints)
        return feed_forward + self.kd * rate_error + self.kp * error

    def limited(self, force: np.ndarray, torque: np.ndarray, joints: np.ndarray) -> Command:
        """A command with each part clipped to the robot's limits."""
        limits = self.robot.joint_torque_limits
        return Command(
            force=clip_norm(force, self.robot.max_force),
            torque=clip_norm(torque, self.robot.max_torque),
            joint_torques=np.clip(joints, -limits, limits),
        )


def generalised_state(estimate: StateEstimate) -> tuple[np.ndarray, np.ndarray]:
    """The model's ``q = [r, quaternion, θ]`` (7 + n,) and ``q̇ = [v, ω, θ̇]`` (6 + n,)."""
    q = estimate.configuration
    return q, estimate.generalised_velocity


def tracking_errors(
    estimate: StateEstimate, reference: Reference, n_joints: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``e``, ``ė`` and ``q̈_d`` (each 6 + n, in the order of ``q̇``), as the module says.

    Raises
    ------
    ValueError
        If the reference gives joint entries but not one per joint.
    """
    if reference.attitude is None:
        attitude_error = np.zeros(3)
    else:
        turn = quaternion_multiply(reference.attitude, quaternion_conjugate(estimate.attitude))
        attitude_error = rotation_vector(turn)
    joints = _joint_reference(reference, estimate.joint_positions, n_joints)
    error = np.concatenate(
        [
            reference.position - estimate.position,
            attitude_error,
            joints[0] - estimate.joint_positions,
        ]
    )
    rate_error = np.concatenate(
        [
            reference.velocity - estimate.velocity,
            reference.angular_velocity - estimate.angular_velocity,
            joints[1] - estimate.joint_velocities,
        ]
    )
    feed_forward = np.concatenate(
        [reference.acceleration, reference.angular_acceleration, joints[2]]
    )
    return error, rate_error, feed_forward


def _joint_reference(
    reference: Reference, angles: np.ndarray, n_joints: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Joint angle, rate and acceleration references (n,) each; where the reference gives
    none, the current ``angles`` and zero rate and acceleration (the joints held still)."""
    out = []
    for name, held in (
        ("joint_positions", angles),
        ("joint_velocities", np.zeros(n_joints)),
        ("joint_accelerations", np.zeros(n_joints)),
    ):
        values = getattr(reference, name)
        if not values.size:
            values = held
        elif values.shape != (n_joints,):
            raise ValueError(
                f"Reference.{name} has {values.size} entries; the manipulator has {n_joints} "
                "joints (give one per joint, or none)"
            )
        out.append(values)
    return out[0], out[1], out[2]


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the computed-torque controller."""
    return [ComputedTorqueController]
