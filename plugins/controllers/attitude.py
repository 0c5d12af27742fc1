"""The attitude loop the free-flyer controllers share: pole-placed PD on the rotation
vector, with the gyroscopic term.

An attitude loop of the same form as the ``pd`` controller's position loop acts on the
rotation-vector error ``e_q = rotvec(q_ref ⊗ q⁻¹)`` (world frame):

    ω_cmd = ω_ref + (kp_q / kd_q) e_q,                   |ω_cmd| ≤ max_angular_rate
    τ = I_w (kd_q (ω_cmd − ω) + α_ref) + ω × I_w ω,      |τ| ≤ max_torque

with ``I_w = R I Rᵀ`` the inertia in the world frame and the gains placed by
:func:`design_gains` at the poles of ``s² + 2ζω s + ω²``. A reference without attitude
leaves the attitude free: no torque is commanded.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from dcsim.api import (
    Reference,
    RobotSpec,
    StateEstimate,
    clip_norm,
    cross,
    quantity,
    quaternion_conjugate,
    quaternion_multiply,
    rotate,
    rotation_vector,
)


def attitude_bandwidth() -> Any:
    """The ``attitude_bandwidth`` parameter of a controller that holds attitude (rad/s)."""
    return quantity(
        0.5, unit="rad/s", gt=0, description="Natural frequency of the closed attitude loop."
    )


def attitude_damping() -> Any:
    """The ``attitude_damping`` parameter of a controller that holds attitude."""
    return quantity(0.9, gt=0, le=5, description="Damping ratio of the closed attitude loop.")


def design_gains(bandwidth: float, damping: float) -> tuple[float, float]:
    """Place the double integrator's poles at those of ``s² + 2ζω s + ω²``.

    Ackermann's formula for ``ẍ = u`` (``A = [[0, 1], [0, 0]]``, ``B = [0, 1]ᵀ``) gives
    the gains ``[kp, kd] = [a₀, a₁]``, the coefficients of the characteristic polynomial
    ``s² + a₁ s + a₀`` of the placed poles. The poles are found and the polynomial is
    rebuilt from them, as python-control's ``acker`` does, so that the gains are its to
    the bit (``tests/plugins/test_pd.py``).

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
    poles = np.roots([1.0, 2.0 * damping * bandwidth, bandwidth**2])
    characteristic = np.real(np.poly(poles))  # [1, a₁, a₀]
    return float(characteristic[2]), float(characteristic[1])


class AttitudeLoop:
    """Torque towards a reference's attitude.

    Parameters
    ----------
    bandwidth : float
        Natural frequency of the closed loop, rad/s.
    damping : float
        Its damping ratio.
    """

    def __init__(self, bandwidth: float, damping: float) -> None:
        self.kp, self.kd = design_gains(bandwidth, damping)

    def torque(self, robot: RobotSpec, estimate: StateEstimate, reference: Reference) -> np.ndarray:
        """The torque towards ``reference.attitude``, world frame, N·m (zero when the
        reference leaves the attitude free)."""
        if reference.attitude is None:
            return np.zeros(3)
        error = rotation_vector(
            quaternion_multiply(reference.attitude, quaternion_conjugate(estimate.attitude))
        )
        limit = min(robot.max_angular_rate, reference.max_angular_rate)
        rate = clip_norm(reference.angular_velocity + (self.kp / self.kd) * error, limit)
        inertia = world_inertia(robot.inertia, estimate.attitude)
        omega = estimate.angular_velocity
        wanted = self.kd * (rate - omega) + reference.angular_acceleration
        torque = inertia @ wanted + cross(omega, inertia @ omega)
        return clip_norm(torque, robot.max_torque)


def world_inertia(inertia: np.ndarray, attitude: np.ndarray) -> np.ndarray:
    """``R I Rᵀ``: a body-frame inertia tensor expressed in the world frame, kg·m²."""
    rotation = np.array([rotate(attitude, axis) for axis in np.eye(3)]).T
    return rotation @ inertia @ rotation.T
