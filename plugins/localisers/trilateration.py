"""``trilateration`` localiser: least-squares fixes on beacon ranges, smoothed by an α-β filter.

Each update solves ``min_p Σ_i (|p − b_i| − ρ_i)²`` with scipy's ``least_squares``,
started from the predicted position, so that of the two mirror solutions three beacons
allow, the one nearer the current belief is chosen. The first fix is taken as it is;
later fixes correct the dead-reckoned prediction (commanded acceleration included) by
fixed gains: ``p += α r`` and ``v += β r / Δt`` with ``r`` the fix minus the prediction
(an α-β tracker). The reported covariance is the filter's steady-state covariance for
the fix's own covariance. This is the yardstick the filters are compared with.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

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


class TrilaterationParams(PluginParams):
    """Parameters of :class:`TrilaterationLocaliser`."""

    min_beacons: int = quantity(3, ge=3, description="Fewest ranges a fix is computed from.")
    position_gain: float = quantity(
        0.2, gt=0, le=1, description="Fraction α of the fix-minus-prediction added to the position."
    )
    velocity_gain: float = quantity(
        0.02,
        gt=0,
        lt=1,
        description="Fraction β of the fix-minus-prediction rate added to the velocity.",
    )
    max_residual: float = quantity(
        5.0, unit="m", gt=0, description="RMS range residual above which a fix is rejected."
    )


class TrilaterationLocaliser(Localiser):
    """Position fixes from beacon ranges by nonlinear least squares (scipy), α-β smoothed."""

    name = "trilateration"
    summary = "Least-squares position fixes on beacon ranges, alpha-beta smoothed (baseline)"
    Params = TrilaterationParams
    params: TrilaterationParams

    def reset(self, prior: Prior, time: float) -> None:
        """Start at the prior mean, not yet converged."""
        self._time = time
        self._position = np.array(prior.position, dtype=float)
        self._velocity = np.array(prior.velocity, dtype=float)
        self._variance = np.concatenate(
            [np.full(3, prior.position_sigma**2), np.full(3, prior.velocity_sigma**2)]
        )
        self._last_fix_time: float | None = None

    def predict(self, motion: MotionInput, dt: float) -> None:
        """Dead-reckon with the commanded acceleration over ``dt`` seconds."""
        a = np.asarray(motion.acceleration)
        self._position = self._position + self._velocity * dt + 0.5 * a * dt**2
        self._velocity = self._velocity + a * dt
        if self._last_fix_time is None:
            self._variance[:3] += self._variance[3:] * dt**2
        self._time += dt

    def update(self, ranges: Sequence[BeaconRange]) -> None:
        """Correct with a fix when at least ``min_beacons`` ranges are in view."""
        fix = self._fix(ranges)
        if fix is None:
            return
        position, fix_variance = fix
        if self._last_fix_time is None:
            self._position = position
            self._variance[:3] = fix_variance
        elif self._time > self._last_fix_time:
            elapsed = self._time - self._last_fix_time
            residual = position - self._position
            alpha, beta = self.params.position_gain, self.params.velocity_gain
            self._position = self._position + alpha * residual
            self._velocity = self._velocity + beta * residual / elapsed
            self._variance = _steady_state_variance(fix_variance, alpha, beta, elapsed)
        self._last_fix_time = self._time

    def _fix(self, ranges: Sequence[BeaconRange]) -> tuple[np.ndarray, np.ndarray] | None:
        """Least-squares position and its per-axis variance, or None if not trustworthy."""
        if len(ranges) < self.params.min_beacons:
            return None
        beacons = np.array([r.beacon_position for r in ranges])
        measured = np.array([r.range for r in ranges])
        sigma = max(max(r.sigma for r in ranges), 1e-6)
        from scipy.optimize import least_squares  # imported on use: it is slow to load

        fit = least_squares(
            lambda p: np.linalg.norm(beacons - p, axis=1) - measured,
            self._position,
            jac=lambda p: (p - beacons) / np.linalg.norm(beacons - p, axis=1)[:, None],
            method="lm",
        )
        rms = float(np.sqrt(np.mean(fit.fun**2)))
        if not fit.success or rms > self.params.max_residual:
            return None
        try:
            variance = np.diag(np.linalg.inv(fit.jac.T @ fit.jac)) * sigma**2
        except np.linalg.LinAlgError:
            return None
        return fit.x, variance

    def estimate(self) -> StateEstimate:
        """The filtered position and velocity with a diagonal covariance."""
        return StateEstimate(
            time=self._time,
            position=self._position,
            velocity=self._velocity,
            covariance=np.diag(np.minimum(self._variance, 1e12)),
            converged=self._last_fix_time is not None,
        )


def _steady_state_variance(
    fix_variance: np.ndarray, alpha: float, beta: float, dt: float
) -> np.ndarray:
    """Steady-state position and velocity variances of an α-β tracker on noisy fixes."""
    denominator = alpha * (4.0 - 2.0 * alpha - beta)
    position = fix_variance * (2.0 * alpha**2 + beta * (2.0 - 3.0 * alpha)) / denominator
    velocity = fix_variance * 2.0 * beta**2 / (denominator * dt**2)
    return np.concatenate([position, velocity])


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the trilateration localiser."""
    return [TrilaterationLocaliser]
