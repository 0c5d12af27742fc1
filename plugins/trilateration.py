"""``trilateration`` localiser: a nonlinear least-squares fix on beacon ranges.

Each update solves ``min_p Σ_i (|p − b_i| − ρ_i)²`` with scipy's ``least_squares``,
started from the predicted position, so that of the two mirror solutions three beacons
allow, the one nearer the current belief is chosen. Between fixes the estimate is
dead-reckoned with the commanded acceleration. The velocity is smoothed from
successive fixes. This is the yardstick the filters are compared with.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.optimize import least_squares

from dcsim.api import (
    BeaconRange,
    Localiser,
    LocationEstimate,
    MotionInput,
    PluginParams,
    Prior,
    hookimpl,
    quantity,
    unit,
)


class TrilaterationParams(PluginParams):
    """Parameters of :class:`TrilaterationLocaliser`."""

    min_beacons: int = quantity(3, ge=3, description="Fewest ranges a fix is computed from.")
    velocity_gain: float = quantity(
        0.5, gt=0, le=1, description="Weight of a new fix-to-fix velocity against the prediction."
    )
    max_residual: float = quantity(
        5.0, unit="m", gt=0, description="RMS range residual above which a fix is rejected."
    )


class TrilaterationLocaliser(Localiser):
    """Position fixes from beacon ranges by nonlinear least squares (scipy)."""

    name = "trilateration"
    summary = "Nonlinear least-squares position fix on beacon ranges (baseline)"
    Params = TrilaterationParams
    params: TrilaterationParams

    def reset(self, prior: Prior, time: float) -> None:
        """Start at the prior mean, not yet converged."""
        self._time = time
        self._position = np.array(prior.position, dtype=float)
        self._velocity = np.array(prior.velocity, dtype=float)
        self._position_var = np.full(3, prior.position_sigma**2)
        self._velocity_var = np.full(3, prior.velocity_sigma**2)
        self._heading = unit(self._velocity)
        self._converged = False
        self._last_fix: tuple[float, np.ndarray] | None = None

    def predict(self, motion: MotionInput, dt: float) -> None:
        """Dead-reckon with the commanded acceleration over ``dt`` seconds."""
        a = np.asarray(motion.acceleration)
        self._position = self._position + self._velocity * dt + 0.5 * a * dt**2
        self._velocity = self._velocity + a * dt
        self._position_var = self._position_var + self._velocity_var * dt**2
        self._time += dt

    def update(self, ranges: Sequence[BeaconRange]) -> None:
        """Fix the position when at least ``min_beacons`` ranges are in view."""
        if len(ranges) < self.params.min_beacons:
            return
        beacons = np.array([r.beacon_position for r in ranges])
        measured = np.array([r.range for r in ranges])
        sigma = max(max(r.sigma for r in ranges), 1e-6)
        fit = least_squares(
            lambda p: np.linalg.norm(beacons - p, axis=1) - measured, self._position, method="lm"
        )
        rms = float(np.sqrt(np.mean(fit.fun**2)))
        if not fit.success or rms > self.params.max_residual:
            return
        fix = fit.x
        if self._last_fix is not None and self._time > self._last_fix[0]:
            fix_velocity = (fix - self._last_fix[1]) / (self._time - self._last_fix[0])
            g = self.params.velocity_gain
            self._velocity = (1 - g) * self._velocity + g * fix_velocity
        self._last_fix = (self._time, fix)
        self._position = fix
        self._position_var = self._fix_variance(fit.jac, sigma)
        self._heading = unit(self._velocity, fallback=self._heading)
        self._converged = True

    @staticmethod
    def _fix_variance(jacobian: np.ndarray, sigma: float) -> np.ndarray:
        information = jacobian.T @ jacobian
        try:
            return np.diag(np.linalg.inv(information)) * sigma**2
        except np.linalg.LinAlgError:
            return np.full(3, np.inf)

    def estimate(self) -> LocationEstimate:
        """The latest fix (or dead-reckoned position) with a diagonal covariance."""
        variances = np.concatenate([self._position_var, self._velocity_var])
        covariance = np.diag(np.minimum(variances, 1e12))
        return LocationEstimate(
            time=self._time,
            position=self._position,
            velocity=self._velocity,
            heading=self._heading,
            covariance=covariance,
            converged=self._converged,
        )


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the trilateration localiser."""
    return [TrilaterationLocaliser]
