"""Motion models against their own equations."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from dcsim.api import (
    ClohessyWiltshireMotion,
    LinearMotion,
    SphericalMotion,
    StaticMotion,
    mean_motion,
    spherical_to_cartesian,
)

N = mean_motion(6_778_137.0)


def test_mean_motion_of_a_400_km_orbit():
    period = 2 * np.pi / N
    assert period == pytest.approx(5553.6, abs=1.0)  # s, the ISS-like 92.6 min orbit


def test_cw_closed_form_matches_numerical_integration_of_the_cw_equations():
    motion = ClohessyWiltshireMotion((12.0, -30.0, 4.0), (0.02, -0.01, 0.005), N, epoch=10.0)

    def rhs(_, s):
        x, y, z, vx, vy, vz = s
        return [vx, vy, vz, 3 * N**2 * x + 2 * N * vy, -2 * N * vx, -(N**2) * z]

    times = np.linspace(10.0, 6000.0, 50)
    numeric = solve_ivp(
        rhs, (10.0, 6000.0), [12, -30, 4, 0.02, -0.01, 0.005], t_eval=times, rtol=1e-11, atol=1e-11
    )
    position, velocity = motion.state_at(times)
    np.testing.assert_allclose(position, numeric.y[:3].T, atol=1e-6)
    np.testing.assert_allclose(velocity, numeric.y[3:].T, atol=1e-9)


def test_cw_without_along_track_drift_is_periodic():
    motion = ClohessyWiltshireMotion((15.0, 30.0, 5.0), (0.0, -2 * N * 15.0, 0.0), N)
    period = 2 * np.pi / N
    np.testing.assert_allclose(motion.position_at(period), motion.position_at(0.0), atol=1e-9)


def test_spherical_model_follows_eq_2_1():
    motion = SphericalMotion(
        150_000.0, 45.0, 10.0, v=2.0, alpha_deg_s=0.003, beta_deg_s=-0.002, epoch=5.0
    )
    t = 305.0
    expected = spherical_to_cartesian(150_000.0 + 2.0 * 300.0, 45.0 + 0.9, 10.0 - 0.6)
    np.testing.assert_allclose(motion.position_at(t), expected, rtol=1e-14)


def test_spherical_velocity_is_the_derivative_of_position():
    motion = SphericalMotion(150_000.0, 80.0, 330.0, v=-1.0, alpha_deg_s=0.004, beta_deg_s=0.003)
    t, h = 100.0, 1e-3
    numeric = (motion.position_at(t + h) - motion.position_at(t - h)) / (2 * h)
    np.testing.assert_allclose(motion.state_at(t)[1], numeric, rtol=1e-7)


def test_linear_and_static_models_vectorise_over_time():
    times = np.array([0.0, 1.0, 2.5])
    position, velocity = LinearMotion((1.0, 2.0, 3.0), (0.5, 0.0, -1.0), epoch=1.0).state_at(times)
    np.testing.assert_allclose(position[2], [1.75, 2.0, 1.5])
    assert velocity.shape == (3, 3)
    position, velocity = StaticMotion((4.0, 5.0, 6.0)).state_at(times)
    assert position.shape == (3, 3) and not velocity.any()


def test_batch_evaluation_matches_one_by_one():
    from dcsim.motion import batch_states

    models = [
        ClohessyWiltshireMotion((1.0, 2.0, 3.0), (0.01, 0.0, -0.02), N),
        SphericalMotion(150_000.0, 45.0, 0.0, v=1.0, alpha_deg_s=0.002, beta_deg_s=0.001),
        StaticMotion((7.0, 8.0, 9.0)),
        ClohessyWiltshireMotion((-4.0, 0.0, 1.0), (0.0, 0.03, 0.0), N, epoch=5.0),
        LinearMotion((0.0, 0.0, 0.0), (1.0, 1.0, 0.0), epoch=2.0),
        SphericalMotion(149_000.0, 44.0, 359.0, beta_deg_s=-0.003, epoch=1.0),
    ]
    positions, velocities = batch_states(models, 123.4)
    for model, position, velocity in zip(models, positions, velocities, strict=True):
        expected_position, expected_velocity = model.state_at(123.4)
        np.testing.assert_allclose(position, expected_position, rtol=1e-13, atol=1e-12)
        np.testing.assert_allclose(velocity, expected_velocity, rtol=1e-13, atol=1e-12)


def test_one_cw_model_at_one_time_equals_its_array_evaluation_to_the_bit():
    rng = np.random.default_rng(5)
    for _ in range(200):
        model = ClohessyWiltshireMotion(
            tuple(rng.normal(0, 1e4, 3)), tuple(rng.normal(0, 5, 3)), N, epoch=rng.uniform(-50, 50)
        )
        t = float(rng.uniform(-1e4, 1e4))
        position, velocity = model.state_at(t)
        positions, velocities = model.state_at(np.array([t]))
        assert position.tolist() == positions[0].tolist()
        assert velocity.tolist() == velocities[0].tolist()


def test_a_field_on_one_orbit_equals_its_models_one_by_one_to_the_bit():
    """Shared mean motion and epoch take the batch's scalar path; mixed ones its array
    path. Both give each model's own numbers exactly (telemetry depends on it)."""
    from dcsim.motion import MotionSet

    rng = np.random.default_rng(7)

    def field(epochs):
        # every third object in the orbit plane: its z terms are zeros of either sign
        planar = np.array([1.0, 1.0, 0.0])
        return [
            ClohessyWiltshireMotion(
                tuple(rng.normal(0, 50, 3) * (planar if i % 3 == 0 else 1.0)),
                tuple(rng.normal(0, 0.05, 3) * (planar if i % 3 == 0 else 1.0)),
                N,
                e,
            )
            for i, e in enumerate(epochs)
        ]

    for models in (field([0.0] * 9), field(rng.uniform(-50, 50, 9))):
        batch = MotionSet(models)
        for t in rng.uniform(0, 5000, 50):
            positions, velocities = batch.state_at(float(t))
            for model, position, velocity in zip(models, positions, velocities, strict=True):
                expected_position, expected_velocity = model.state_at(float(t))
                assert position.tobytes() == expected_position.tobytes()  # zeros' signs too
                assert velocity.tobytes() == expected_velocity.tobytes()


def test_row_lengths_are_numpys_norms_to_the_bit():
    from dcsim.geometry import row_lengths

    vectors = np.random.default_rng(6).normal(0, 1e3, (500, 3))
    assert row_lengths(vectors).tolist() == np.linalg.norm(vectors, axis=1).tolist()


@pytest.mark.parametrize(
    ("a_shape", "b_shape"), [((3,), (3,)), ((40, 3), (40, 3)), ((40, 3), (3,)), ((2, 5, 3), (5, 3))]
)
def test_cross_products_are_numpys_to_the_bit(a_shape, b_shape):
    from dcsim.api import cross

    rng = np.random.default_rng(8)
    for scale in (1e-9, 1.0, 1e9):
        a, b = rng.normal(0, scale, a_shape), rng.normal(0, 1.0, b_shape)
        assert cross(a, b).tobytes() == np.cross(a, b).tobytes()
    zeros = np.zeros(a_shape)  # signed zeros as numpy gives them
    assert cross(zeros, -np.ones(b_shape)).tobytes() == np.cross(zeros, -np.ones(b_shape)).tobytes()


def test_a_vector_s_length_is_numpys_norm_to_the_bit():
    from dcsim.api import length

    for vector in np.random.default_rng(9).normal(0, 1e3, (200, 3)):
        assert length(vector) == np.linalg.norm(vector)
