"""The trilateration baseline localiser."""

from __future__ import annotations

import numpy as np
import pytest
from dcsim_plugins.localisers.trilateration import TrilaterationLocaliser

from dcsim.api import BeaconRange, MotionInput, Prior

BEACONS = np.array([[100.0, 0, 0], [0, 100.0, 0], [0, 0, 100.0], [-100.0, -100.0, -100.0]])


def ranges(position, beacons=BEACONS, sigma=0.0, rng=None):
    true = np.linalg.norm(beacons - position, axis=1)
    noisy = true + (rng.normal(0, sigma, len(true)) if sigma else 0.0)
    return [
        BeaconRange(i, b, r, max(sigma, 1e-3))
        for i, (b, r) in enumerate(zip(beacons, noisy, strict=True))
    ]


def localiser(prior_position=(0, 0, 0), **params):
    loc = TrilaterationLocaliser(params)
    loc.reset(Prior(position=prior_position, position_sigma=50.0), time=0.0)
    return loc


def test_noiseless_fix_is_exact_from_a_distant_prior():
    truth = np.array([12.0, -7.0, 3.0])
    loc = localiser(prior_position=(-40, 40, 30))
    assert not loc.estimate().converged
    loc.update(ranges(truth))
    estimate = loc.estimate()
    assert estimate.converged
    np.testing.assert_allclose(estimate.position, truth, atol=1e-6)


def test_three_beacons_pick_the_mirror_solution_nearer_the_belief():
    beacons = BEACONS[:3]
    truth = np.array([10.0, 20.0, 30.0])
    normal = np.ones(3) / np.sqrt(3)  # beacon plane x + y + z = 100
    mirror = truth + 2 * (100 / np.sqrt(3) - truth @ normal) * normal
    near_truth = localiser(prior_position=truth + 5)
    near_truth.update(ranges(truth, beacons))
    near_mirror = localiser(prior_position=mirror + 5)
    near_mirror.update(ranges(truth, beacons))
    np.testing.assert_allclose(near_truth.estimate().position, truth, atol=1e-5)
    np.testing.assert_allclose(near_mirror.estimate().position, mirror, atol=1e-5)


def test_too_few_beacons_dead_reckon_with_the_commanded_acceleration():
    loc = localiser()
    loc.update(ranges(np.zeros(3))[:2])
    assert not loc.estimate().converged
    for _ in range(10):
        loc.predict(MotionInput(acceleration=[0.1, 0, 0]), dt=1.0)
    estimate = loc.estimate()
    np.testing.assert_allclose(estimate.position, [0.5 * 0.1 * 10**2, 0, 0], atol=1e-12)
    np.testing.assert_allclose(estimate.velocity, [1.0, 0, 0], atol=1e-12)
    assert estimate.time == pytest.approx(10.0)


def test_reported_variance_matches_the_scatter_of_noisy_fixes():
    rng = np.random.default_rng(4)
    truth = np.array([5.0, 5.0, 5.0])
    errors, predicted = [], []
    for _ in range(300):
        loc = localiser(prior_position=truth)
        loc.update(ranges(truth, sigma=0.5, rng=rng))
        estimate = loc.estimate()
        errors.append(estimate.position - truth)
        predicted.append(np.diag(estimate.covariance)[:3])
    ratio = np.var(errors, axis=0) / np.mean(predicted, axis=0)
    assert np.all((ratio > 0.7) & (ratio < 1.4)), ratio


def test_velocity_follows_a_coasting_collector():
    loc = localiser()
    velocity = np.array([0.3, -0.2, 0.1])
    for k in range(400):
        loc.predict(MotionInput(), dt=1.0)
        loc.update(ranges(velocity * (k + 1)))
    np.testing.assert_allclose(loc.estimate().velocity, velocity, atol=1e-6)
