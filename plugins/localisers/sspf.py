"""``sspf`` localiser: the source thesis's Simplified Scattered Particle Filter.

Each particle is a position and a velocity (its heading and speed). Every step:

1. **Move**: the commanded acceleration is applied to every particle (with optional
   motion noise ``motion_sigma``).
2. **Weigh**: a particle's error is the sum over beacons of ``| |p − b| − ρ |``, the
   difference between its distance to each beacon and the measured range. Its weight is
   the thesis's piecewise-linear probability of that error (``max_error``,
   ``min_probability``, ``big_error``, ``be_probability``, ``small_error``,
   ``se_probability``; appendix A.3), or, with ``likelihood: gaussian``, the Gaussian
   likelihood of the range residuals under range noise plus motion noise (the
   improvement the thesis asks for in §6.3.2).
3. **Resample** with replacement: multinomial as in the thesis, or systematic; every
   step as in the thesis, or (``resample_below`` < 1) only when the effective sample size
   falls below that fraction of the particles, the weights carried over otherwise.
4. **Scatter**: each copied particle is scattered with probability ``scatter_prob``:
   its position and velocity jitter (by ``roughening`` times the cloud's extent per
   axis, shrinking as the cloud converges), and if its error grew since the last step
   (it is heading the wrong way) its heading is drawn again at random, its speed kept.

The estimate is the particles' mean (the direction of travel is the mean velocity's,
the second improvement of §6.3.2). As in the thesis it is published as converged only once the mean
particle error is at most ``max_error``. Particles start from the prior (Gaussian) or,
as in the thesis, on concentric shells (``shell_radii`` around ``shell_centre``). Every
step is vectorised over the particles.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Literal

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


class SSPFParams(PluginParams):
    """Parameters of :class:`ScatteredParticleLocaliser` (thesis names in lower case)."""

    particles: int = quantity(2000, ge=10, description="Number of particles (LIST_SIZE).")
    max_error: float = quantity(
        20.0,
        unit="m",
        gt=0,
        description="Mean error at or below which the estimate is published; "
        "errors above it get min_probability (MAX_ERROR).",
    )
    min_probability: float = quantity(
        0.001, ge=0, le=1, description="Probability of errors above max_error."
    )
    big_error: float = quantity(
        2.0, unit="m", gt=0, description="Error of the second knot (BIG_ERROR)."
    )
    be_probability: float = quantity(
        0.05, ge=0, le=1, description="Probability at big_error (BE_PROBABILITY)."
    )
    small_error: float = quantity(
        0.3, unit="m", gt=0, description="Error of the third knot (SMALL_ERROR)."
    )
    se_probability: float = quantity(
        0.5, ge=0, le=1, description="Probability at small_error (SE_PROBABILITY)."
    )
    scatter_prob: float = quantity(
        0.3, ge=0, le=1, description="Probability that a copied particle scatters."
    )
    roughening: float = quantity(
        0.2,
        ge=0,
        description="Position and velocity jitter of a scattered particle, per axis, as a fraction "
        "of the cloud's extent times particles^(-1/3).",
    )
    resample_below: float = quantity(
        1.0,
        gt=0,
        le=1,
        description="Resample when the effective sample size falls below this fraction of "
        "the particles (1: every step, as in the thesis).",
    )
    resampling: Literal["multinomial", "systematic"] = quantity(
        "multinomial", description="Resampling scheme."
    )
    likelihood: Literal["thesis", "gaussian"] = quantity(
        "thesis",
        description="Weights from the thesis's piecewise-linear function or a Gaussian likelihood.",
    )
    motion_sigma: float = quantity(
        0.005, unit="m/s^2", ge=0, description="Acceleration noise added to each particle's motion."
    )
    initial: Literal["prior", "shells"] = quantity(
        "prior", description="Draw particles from the prior, or on the thesis's concentric shells."
    )
    shell_radii: tuple[float, ...] = quantity(
        (100_000.0, 150_000.0, 200_000.0), unit="m", description="Radii of the initial shells."
    )
    shell_centre: Literal["origin", "prior"] = quantity(
        "origin", description="Centre of the shells: the frame's origin (thesis) or the prior mean."
    )


def thesis_probability(error: np.ndarray, p: SSPFParams) -> np.ndarray:
    """The thesis's piecewise-linear probability of a particle's error (appendix A.3)."""
    knots_x = [0.0, p.small_error, p.big_error, p.max_error]
    knots_y = [1.0, p.se_probability, p.be_probability, p.min_probability]
    return np.interp(error, knots_x, knots_y, right=p.min_probability)


class ScatteredParticleLocaliser(Localiser):
    """Simplified Scattered Particle Filter with the thesis's improvements as options."""

    name = "sspf"
    summary = "The thesis's Simplified Scattered Particle Filter on beacon ranges, vectorised"
    Params = SSPFParams
    params: SSPFParams

    def reset(self, prior: Prior, time: float) -> None:
        """Spread the particles from the prior or on the shells."""
        n, p = self.params.particles, self.params
        if p.initial == "shells":
            centre = np.zeros(3) if p.shell_centre == "origin" else np.asarray(prior.position)
            directions = self.rng.normal(size=(n, 3))
            directions /= np.linalg.norm(directions, axis=1, keepdims=True)
            radii = np.asarray(p.shell_radii)[np.arange(n) % len(p.shell_radii)]
            self.positions = centre + directions * radii[:, None]
        else:
            self.positions = self.rng.normal(prior.position, prior.position_sigma, size=(n, 3))
        self.velocities = self.rng.normal(prior.velocity, prior.velocity_sigma, size=(n, 3))
        self.weights = np.full(n, 1.0 / n)
        self.errors = np.full(n, np.inf)
        self.mean_error = np.inf
        self.time = time

    def predict(self, motion: MotionInput, dt: float) -> None:
        """Apply the commanded motion to every particle."""
        acceleration = np.asarray(motion.acceleration)
        if self.params.motion_sigma > 0:
            noise = self.rng.standard_normal(self.velocities.shape, dtype=np.float32)
            acceleration = acceleration + self.params.motion_sigma * noise
        self.positions = self.positions + self.velocities * dt + 0.5 * acceleration * dt**2
        self.velocities = self.velocities + acceleration * dt
        self.time += dt

    def update(self, ranges: Sequence[BeaconRange]) -> None:
        """Weigh, resample and scatter (no ranges: the particles only move)."""
        if not ranges:
            return
        beacons = np.array([r.beacon_position for r in ranges])
        measured = np.array([r.range for r in ranges])
        residuals = (
            np.linalg.norm(self.positions[:, None, :] - beacons[None, :, :], axis=2) - measured
        )
        errors = np.abs(residuals).sum(axis=1)
        weights = self.weights * self._weights(errors, residuals, ranges)
        total = weights.sum()
        weights = weights / total if total > 0 else np.full(len(weights), 1.0 / len(weights))
        self.mean_error = float(errors.mean())
        if 1.0 / np.sum(weights**2) > self.params.resample_below * len(weights):
            self.weights, self.errors = weights, errors
            return
        chosen = self._resample(weights)
        previous = self.errors[chosen]
        self.positions, self.velocities = self.positions[chosen], self.velocities[chosen]
        self.errors = errors[chosen]
        self.weights = np.full(len(chosen), 1.0 / len(chosen))
        self._scatter(grew=self.errors > previous)

    def _weights(
        self, errors: np.ndarray, residuals: np.ndarray, ranges: Sequence[BeaconRange]
    ) -> np.ndarray:
        if self.params.likelihood == "thesis":
            weights = thesis_probability(errors, self.params)
        else:
            motion = float(np.mean(self._jitter_scale() ** 2))
            variance = np.array([r.sigma**2 for r in ranges]) + motion + 1e-12
            log_w = -0.5 * (residuals**2 / variance).sum(axis=1)
            weights = np.exp(log_w - log_w.max())
        total = weights.sum()
        return weights / total if total > 0 else np.full(len(weights), 1.0 / len(weights))

    def _resample(self, weights: np.ndarray) -> np.ndarray:
        n = len(weights)
        if self.params.resampling == "multinomial":
            draws = np.sort(self.rng.random(n))  # sorted: same draw, faster lookup
        else:
            draws = (self.rng.random() + np.arange(n)) / n
        return np.minimum(np.searchsorted(np.cumsum(weights), draws), n - 1)

    def _jitter_scale(self, values: np.ndarray | None = None) -> np.ndarray:
        """Roughening per axis: a fraction of the cloud's extent times particles^(-1/3)."""
        values = self.positions if values is None else values
        extent = values.max(axis=0) - values.min(axis=0)
        return self.params.roughening * extent * len(values) ** (-1.0 / 3.0)

    def _scatter(self, grew: np.ndarray) -> None:
        n = len(self.positions)
        scattered = np.flatnonzero(self.rng.random(n) < self.params.scatter_prob)
        scale = np.concatenate(
            [self._jitter_scale(self.positions), self._jitter_scale(self.velocities)]
        )
        jitter = self.rng.standard_normal((len(scattered), 6), dtype=np.float32) * scale
        self.positions[scattered] += jitter[:, :3]
        self.velocities[scattered] += jitter[:, 3:]
        turn = scattered[grew[scattered]]
        if turn.size:
            directions = self.rng.normal(size=(turn.size, 3))
            directions /= np.linalg.norm(directions, axis=1, keepdims=True)
            speeds = np.linalg.norm(self.velocities[turn], axis=1, keepdims=True)
            self.velocities[turn] = directions * speeds

    def _covariance(self, weights: np.ndarray) -> np.ndarray:
        states = np.hstack([self.positions, self.velocities])
        centred = states - weights @ states
        return (centred * weights[:, None]).T @ centred

    def estimate(self) -> StateEstimate:
        """The particles' weighted mean and covariance."""
        weights = self.weights
        position, velocity = weights @ self.positions, weights @ self.velocities
        covariance = self._covariance(weights)
        return StateEstimate(
            time=self.time,
            position=position,
            velocity=velocity,
            covariance=0.5 * (covariance + covariance.T),
            converged=self.mean_error <= self.params.max_error,
        )


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the SSPF localiser."""
    return [ScatteredParticleLocaliser]
