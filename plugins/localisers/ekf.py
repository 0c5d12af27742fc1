"""``ekf`` localiser: an extended Kalman filter on beacon ranges (filterpy).

State ``[position, velocity]`` with a constant-velocity model driven by the commanded
acceleration; thrust uncertainty is white acceleration noise ``acceleration_sigma``.
Each update uses however many ranges are in view (none skips the update), linearised
at the current estimate. The filter starts from the first least-squares fix once three
or more beacons are in view (``initialise: fix``), or straight from the prior
(``initialise: prior``). It reports converged once the position's largest standard
deviation is below ``convergence_sigma``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Literal

import numpy as np
from dcsim_plugins.localisers.range_models import (
    beacon_arrays,
    least_squares_fix,
    predicted_ranges,
    process_noise,
    range_jacobian,
    transition,
)

from dcsim.api import (
    BeaconRange,
    Localiser,
    MotionInput,
    PluginParams,
    Prior,
    StateEstimate,
    hookimpl,
    quantity,
)

if TYPE_CHECKING:
    from filterpy.kalman import ExtendedKalmanFilter


class EKFParams(PluginParams):
    """Parameters of :class:`EKFLocaliser`."""

    acceleration_sigma: float = quantity(
        0.005, unit="m/s^2", gt=0, description="Thrust uncertainty as white acceleration noise."
    )
    initialise: Literal["fix", "prior"] = quantity(
        "fix", description="Start from the first least-squares fix, or from the prior."
    )
    convergence_sigma: float = quantity(
        1.0, unit="m", gt=0, description="Position standard deviation below which it is converged."
    )


class EKFLocaliser(Localiser):
    """Extended Kalman filter, constant velocity, range measurements."""

    name = "ekf"
    summary = "Extended Kalman filter on beacon ranges, constant-velocity model (filterpy)"
    Params = EKFParams
    params: EKFParams

    def reset(self, prior: Prior, time: float) -> None:
        """Start from the prior: its mean, and its standard deviations as a diagonal covariance."""
        self.filter = self._new_filter()
        mean = np.concatenate([prior.position, prior.velocity])
        self.filter.x = mean.reshape(self.filter.x.shape)
        self.filter.P = np.diag([prior.position_sigma**2] * 3 + [prior.velocity_sigma**2] * 3)
        self.time = time
        self.started = self.params.initialise == "prior"

    def predict(self, motion: MotionInput, dt: float) -> None:
        """Propagate with the commanded acceleration over ``dt`` s."""
        self.filter.F, self.filter.B = transition(dt)
        self.filter.Q = process_noise(dt, self.params.acceleration_sigma)
        self.filter.predict(u=np.asarray(motion.acceleration).reshape(3, 1))
        self.time += dt

    def update(self, ranges: Sequence[BeaconRange]) -> None:
        """Correct with the ranges in view (none: nothing to do)."""
        if not ranges:
            return
        beacons, measured, variances = beacon_arrays(ranges)
        if not self.started:
            if len(ranges) < 3:
                return
            fix = least_squares_fix(self.filter.x.ravel()[:3], beacons, measured, variances)
            self._start_at_fix(*fix)
        self._correct(beacons, measured, variances)

    def _new_filter(self) -> ExtendedKalmanFilter:
        from filterpy.kalman import ExtendedKalmanFilter  # imported on use: it loads scipy.stats

        return ExtendedKalmanFilter(dim_x=6, dim_z=1, dim_u=3)

    def _correct(self, beacons: np.ndarray, measured: np.ndarray, variances: np.ndarray) -> None:
        """The filter's own measurement update with these ranges."""
        self.filter.update(
            measured.reshape(-1, 1),
            HJacobian=lambda x: range_jacobian(x.ravel(), beacons),
            Hx=lambda x: predicted_ranges(x.ravel()[:3], beacons).reshape(-1, 1),
            R=np.diag(variances),
        )

    def _start_at_fix(self, position: np.ndarray, covariance: np.ndarray) -> None:
        """Replace the prior's position belief by a least-squares fix and its covariance."""
        self.filter.x[:3] = position.reshape(self.filter.x[:3].shape)
        self.filter.P[:3, :] = 0.0
        self.filter.P[:, :3] = 0.0
        self.filter.P[:3, :3] = covariance
        self.started = True

    def estimate(self) -> StateEstimate:
        """The filter's mean and covariance."""
        state = self.filter.x.ravel()
        covariance = 0.5 * (self.filter.P + self.filter.P.T)
        return StateEstimate(
            time=self.time,
            position=state[:3],
            velocity=state[3:],
            covariance=covariance,
            converged=self.started and self._position_settled(covariance[:3, :3]),
        )

    def _position_settled(self, covariance: np.ndarray) -> bool:
        """Whether the largest position standard deviation is within ``convergence_sigma``.

        The largest eigenvalue of a covariance (m²) lies between its largest diagonal
        entry and its trace; the eigenvalues are computed only when those bounds, with a
        margin for rounding, leave the answer open.
        """
        sigma = self.params.convergence_sigma
        if np.trace(covariance) < 0.999 * sigma**2:
            return True
        if covariance.diagonal().max() > 1.001 * sigma**2:
            return False
        return float(np.sqrt(np.linalg.eigvalsh(covariance).max())) <= sigma


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the EKF localiser."""
    return [EKFLocaliser]
