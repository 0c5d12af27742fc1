"""The rotation of one tracked object: a multiplicative extended Kalman filter.

A sensor that estimates an object's pose (a camera matching the object's model) gives
its attitude with a covariance. :class:`RotationFilter` estimates from these the
object's attitude ``q`` (body to world) and angular velocity ``ω`` (world frame).

State and error
    The mean is ``(q, ω)``; the error state is ``[δθ, δω]`` (6), the small rotation
    about the world axes that takes the estimate to the truth, ``q = exp(δθ / 2) ⊗ q̂``,
    and the rate's error, rad and rad/s, with covariance ``P`` (6, 6).
Prediction
    The mean follows the torque-free motion of a body of the detection's catalogue
    inertia (:class:`~dcsim.api.TorqueFreeRotation`), or a constant ``ω`` when the
    inertia is unknown. The error follows ``d(δθ)/dt = ω̂ × δθ + δω``, ``d(δω)/dt = 0``
    (a world-frame error turns with the body), whose transition over ``dt`` is taken to
    second order in ``ω̂ dt`` (``Φθθ = I + dt W + dt² W² / 2``, ``Φθω = dt I + dt² W / 2``,
    ``W = [ω̂ ×]``), plus white angular acceleration noise of spectral density ``s²`` per
    axis for what this leaves out (the rate error's own gyroscopic dynamics, the
    inertia's error): ``Q = s² [[dt³/3, dt²/2], [dt²/2, dt]] ⊗ I``.
Update
    The residual is the rotation vector of ``q_m ⊗ q̂⁻¹``, measured as ``δθ`` with the
    detection's covariance; the correction turns ``q̂`` by its first three components
    and adds the last three to ``ω̂`` (Joseph form for ``P``).
Start
    At the first measured attitude: ``q̂ = q_m`` with its covariance, ``ω̂ = 0`` with
    ``initial_rate_sigma`` on each axis.
"""

from __future__ import annotations

import numpy as np

from dcsim.api import (
    TorqueFreeRotation,
    quaternion_conjugate,
    quaternion_from_rotation_vector,
    quaternion_multiply,
    rotation_vector,
)

_H = np.hstack([np.eye(3), np.zeros((3, 3))])
"""The measurement matrix: the rotation part of the error state."""


class RotationFilter:
    """Attitude and angular velocity of one object from measured attitudes.

    Parameters
    ----------
    attitude : ndarray (4,)
        The first measured body-to-world attitude ``[x, y, z, w]``.
    covariance : ndarray (3, 3)
        Its error covariance about the world axes, rad².
    inertia : ndarray (3, 3) or None
        The object's inertia about its centre of mass, body axes, kg·m² (its catalogue
        value); None to predict with a constant angular velocity.
    rate_sigma : float
        Standard deviation of the initial angular velocity on each axis, rad/s.
    acceleration_noise : float
        Square root of the white angular acceleration noise's spectral density per axis,
        rad/s^1.5.

    Attributes
    ----------
    attitude : ndarray (4,)
        Estimated body-to-world attitude ``[x, y, z, w]``.
    angular_velocity : ndarray (3,)
        Estimated angular velocity, world frame, rad/s.
    covariance : ndarray (6, 6)
        Covariance of ``[δθ, δω]``, rad², rad²/s, rad²/s².
    inertia : ndarray (3, 3) or None
        The inertia it predicts with.
    """

    def __init__(
        self,
        attitude: np.ndarray,
        covariance: np.ndarray,
        inertia: np.ndarray | None,
        rate_sigma: float,
        acceleration_noise: float,
    ) -> None:
        self.attitude = np.array(attitude, dtype=float)
        self.angular_velocity = np.zeros(3)
        self.covariance = np.zeros((6, 6))
        self.covariance[:3, :3] = covariance
        self.covariance[3:, 3:] = rate_sigma**2 * np.eye(3)
        self.inertia = inertia
        self._spectral_density = acceleration_noise**2
        self._noise: tuple[float, np.ndarray] | None = None
        self._rotation = (
            None if inertia is None else TorqueFreeRotation(inertia, self.attitude, np.zeros(3))
        )

    def predict(self, dt: float) -> None:
        """Move the estimate ``dt`` seconds on (nothing for ``dt <= 0``)."""
        if dt <= 0.0:
            return
        if self._rotation is None:
            turn = quaternion_from_rotation_vector(self.angular_velocity * dt)
            self.attitude = quaternion_multiply(turn, self.attitude)
        else:
            self._rotation.set_state(self.attitude, self.angular_velocity)
            self._rotation.advance(dt)
            self.attitude = np.array(self._rotation.attitude)
            self.angular_velocity = np.array(self._rotation.angular_velocity)
        transition = _transition(self.angular_velocity, dt)
        noise = self._process_noise(dt)
        self.covariance = symmetric(transition @ self.covariance @ transition.T + noise)

    def _process_noise(self, dt: float) -> np.ndarray:
        """The process noise (6, 6) over ``dt`` (s); the last one is kept and serves the
        same ``dt`` again (every control period)."""
        if self._noise is None or self._noise[0] != dt:
            s = self._spectral_density
            blocks = s * np.array([[dt**3 / 3.0, dt**2 / 2.0], [dt**2 / 2.0, dt]])
            self._noise = (dt, np.kron(blocks, np.eye(3)))
        return self._noise[1]

    def correct(self, attitude: np.ndarray, covariance: np.ndarray) -> None:
        """Fold in a measured ``attitude`` ``[x, y, z, w]`` of error covariance
        ``covariance`` (3, 3) about the world axes, rad²."""
        residual = rotation_vector(
            quaternion_multiply(attitude, quaternion_conjugate(self.attitude))
        )
        gain = self.covariance[:, :3] @ np.linalg.inv(self.covariance[:3, :3] + covariance)
        correction = gain @ residual
        turned = quaternion_multiply(quaternion_from_rotation_vector(correction[:3]), self.attitude)
        self.attitude = turned / np.linalg.norm(turned)
        self.angular_velocity = self.angular_velocity + correction[3:]
        reduction = np.eye(6) - gain @ _H
        self.covariance = symmetric(
            reduction @ self.covariance @ reduction.T + gain @ covariance @ gain.T
        )


def _transition(rate: np.ndarray, dt: float) -> np.ndarray:
    """The error state's transition (6, 6) over ``dt`` (s) at the estimated rate ``rate``
    (world frame, rad/s), to second order in ``|rate| dt``."""
    x, y, z = rate.tolist()
    turn = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    transition = np.eye(6)
    transition[:3, :3] += dt * turn + 0.5 * dt**2 * (turn @ turn)
    transition[:3, 3:] = dt * np.eye(3) + 0.5 * dt**2 * turn
    return transition


def symmetric(matrices: np.ndarray) -> np.ndarray:
    """``matrices`` (..., k, k) made exactly symmetric (their mean with their transposes)."""
    return 0.5 * (matrices + np.swapaxes(matrices, -1, -2))
