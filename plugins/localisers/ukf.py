"""``ukf`` localiser: an unscented Kalman filter on beacon ranges (filterpy).

The same constant-velocity model, noise and initialisation as ``ekf``; the range
measurement is propagated through Van der Merwe's scaled sigma points instead of being
linearised.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from dcsim_plugins.localisers.ekf import EKFLocaliser, EKFParams
from dcsim_plugins.localisers.range_models import (
    predicted_ranges,
    process_noise,
    transition,
)

from dcsim.api import (
    MotionInput,
    hookimpl,
    quantity,
)

if TYPE_CHECKING:
    from filterpy.kalman import UnscentedKalmanFilter


class UKFParams(EKFParams):
    """Parameters of :class:`UKFLocaliser`."""

    alpha: float = quantity(0.5, gt=0, le=1, description="Sigma-point spread α.")


def _propagate(x: np.ndarray, dt: float, acceleration: np.ndarray) -> np.ndarray:
    f, b = transition(dt)
    return f @ x + b @ acceleration


class UKFLocaliser(EKFLocaliser):
    """Unscented Kalman filter, constant velocity, range measurements."""

    name = "ukf"
    summary = "Unscented Kalman filter on beacon ranges, constant-velocity model (filterpy)"
    Params = UKFParams
    params: UKFParams

    def _new_filter(self) -> UnscentedKalmanFilter:
        from filterpy.kalman import MerweScaledSigmaPoints, UnscentedKalmanFilter  # on use

        points = MerweScaledSigmaPoints(6, alpha=self.params.alpha, beta=2.0, kappa=0.0)
        return UnscentedKalmanFilter(6, 1, 1.0, hx=None, fx=_propagate, points=points)

    def predict(self, motion: MotionInput, dt: float) -> None:
        """Propagate the sigma points with the commanded acceleration over ``dt`` s."""
        self.filter.Q = process_noise(dt, self.params.acceleration_sigma)
        self.filter.predict(dt=dt, acceleration=np.asarray(motion.acceleration))
        self.time += dt

    def _start_at_fix(self, position: np.ndarray, covariance: np.ndarray) -> None:
        super()._start_at_fix(position, covariance)
        # the update reuses the predicted sigma points: draw them again around the fix
        self.filter.sigmas_f = self.filter.points_fn.sigma_points(self.filter.x, self.filter.P)

    def _correct(self, beacons: np.ndarray, measured: np.ndarray, variances: np.ndarray) -> None:
        """Unscented update with these ranges."""
        self.filter.update(
            measured, R=np.diag(variances), hx=lambda x: predicted_ranges(x[:3], beacons)
        )


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the UKF localiser."""
    return [UKFLocaliser]
