"""``pd`` controller: proportional-derivative tracking with force and speed limits.

The gains come from pole placement on the double integrator ẍ = u (per axis, per unit
mass) with python-control: the closed-loop poles are those of a second-order system of
natural frequency ``bandwidth`` and damping ratio ``damping``, giving ``kp = ω²`` and
``kd = 2ζω``. The law is written in its speed-limited form

    v_cmd = v_ref + (kp / kd) (p_ref − p),   |v_cmd| ≤ max_speed
    F = m (kd (v_cmd − v) + a_ref),          |F| ≤ max_force

which equals ``F = m (kp e + kd ė + a_ref)`` while no limit is active.

When the reference gives an attitude, an attitude loop of the same form acts on the
rotation-vector error ``e_q = rotvec(q_ref ⊗ q⁻¹)`` (world frame), with its own
pole-placed gains:

    ω_cmd = ω_ref + (kp_q / kd_q) e_q,                   |ω_cmd| ≤ max_angular_rate
    τ = I_w (kd_q (ω_cmd − ω) + α_ref) + ω × I_w ω,      |τ| ≤ max_torque

with ``I_w = R I Rᵀ`` the inertia in the world frame. A reference without attitude
leaves the attitude free: no torque is commanded.
"""

from __future__ import annotations

import numpy as np

from dcsim.api import (
    Command,
    Controller,
    PluginParams,
    Reference,
    RobotSpec,
    StateEstimate,
    Surroundings,
    clip_norm,
    cross,
    hookimpl,
    quantity,
    quaternion_conjugate,
    quaternion_multiply,
    rotate,
    rotation_vector,
)


class PDParams(PluginParams):
    """Parameters of :class:`PDController`."""

    bandwidth: float = quantity(
        0.2, unit="rad/s", gt=0, description="Natural frequency ω of the closed position loop."
    )
    damping: float = quantity(0.9, gt=0, le=5, description="Damping ratio ζ of the closed loop.")
    attitude_bandwidth: float = quantity(
        0.5, unit="rad/s", gt=0, description="Natural frequency of the closed attitude loop."
    )
    attitude_damping: float = quantity(
        0.9, gt=0, le=5, description="Damping ratio of the closed attitude loop."
    )


def design_gains(bandwidth: float, damping: float) -> tuple[float, float]:
    """Place the double integrator's poles at those of ``s² + 2ζω s + ω²``.

    Parameters
    ----------
    bandwidth : float
        Natural frequency ω, rad/s.
    damping : float
        Damping ratio ζ.

    Returns
    -------
    kp, kd : float
        Position gain (1/s²) and velocity gain (1/s), per unit mass.
    """
    import control  # imported here: it is slow to import and only needed at reset

    a = np.array([[0.0, 1.0], [0.0, 0.0]])
    b = np.array([[0.0], [1.0]])
    poles = np.roots([1.0, 2.0 * damping * bandwidth, bandwidth**2])
    gains = np.asarray(control.acker(a, b, poles)).ravel()
    return float(gains[0]), float(gains[1])


class PDController(Controller):
    """Speed- and force-limited PD tracking with pole-placed gains."""

    name = "pd"
    summary = "PD tracking with pole-placed gains, force and speed limits (baseline)"
    Params = PDParams
    params: PDParams

    def reset(self, robot: RobotSpec) -> None:
        """Design the gains and remember the robot's limits."""
        self.robot = robot
        self.kp, self.kd = design_gains(self.params.bandwidth, self.params.damping)
        self.kp_attitude, self.kd_attitude = design_gains(
            self.params.attitude_bandwidth, self.params.attitude_damping
        )

    def command(
        self,
        time: float,
        estimate: StateEstimate,
        reference: Reference,
        surroundings: Surroundings,
    ) -> Command:
        """Force towards the reference; torque towards its attitude, if it gives one."""
        error = reference.position - estimate.position
        limit = min(self.robot.max_speed, reference.max_speed)
        v_cmd = clip_norm(reference.velocity + (self.kp / self.kd) * error, limit)
        acceleration = self.kd * (v_cmd - estimate.velocity) + reference.acceleration
        force = clip_norm(self.robot.mass * acceleration, self.robot.max_force)
        if reference.attitude is None:
            return Command(force=force)
        return Command(force=force, torque=self._torque(estimate, reference, reference.attitude))

    def _torque(
        self, estimate: StateEstimate, reference: Reference, attitude: np.ndarray
    ) -> np.ndarray:
        """The attitude loop's torque towards ``attitude`` (the reference's), world frame, N·m."""
        error = rotation_vector(
            quaternion_multiply(attitude, quaternion_conjugate(estimate.attitude))
        )
        limit = min(self.robot.max_angular_rate, reference.max_angular_rate)
        rate = clip_norm(
            reference.angular_velocity + (self.kp_attitude / self.kd_attitude) * error, limit
        )
        inertia = _world_inertia(self.robot.inertia, estimate.attitude)
        omega = estimate.angular_velocity
        wanted = self.kd_attitude * (rate - omega) + reference.angular_acceleration
        torque = inertia @ wanted + cross(omega, inertia @ omega)
        return clip_norm(torque, self.robot.max_torque)


def _world_inertia(inertia: np.ndarray, attitude: np.ndarray) -> np.ndarray:
    """``R I Rᵀ``: a body-frame inertia tensor expressed in the world frame, kg·m²."""
    rotation = np.array([rotate(attitude, axis) for axis in _AXES]).T
    return rotation @ inertia @ rotation.T


_AXES = np.eye(3)


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the PD controller."""
    return [PDController]
