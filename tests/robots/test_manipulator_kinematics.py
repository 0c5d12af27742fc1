"""The manipulator's forward kinematics, Jacobians and inverse kinematics (thesis ch. 3)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from dcsim.geometry import quaternion_from_rotation_vector, quaternion_multiply, rotation_vector
from dcsim.robots.dh import DHLink, thesis_manipulator
from dcsim.robots.kinematics import rotation_matrix
from dcsim.robots.manipulator import ManipulatorModel

N = 6
IDENTITY = np.array([0.0, 0.0, 0.0, 1.0])


@pytest.fixture(scope="module")
def model() -> ManipulatorModel:
    return ManipulatorModel(thesis_manipulator())


def state(joints, position=(0.0, 0.0, 0.0), quaternion=IDENTITY) -> np.ndarray:
    return np.concatenate([position, quaternion, joints])


def random_state(rng: np.random.Generator) -> np.ndarray:
    quaternion = rng.normal(size=4)
    return state(
        rng.uniform(-math.pi, math.pi, N),
        rng.normal(size=3),
        quaternion / np.linalg.norm(quaternion),
    )


def advance(q: np.ndarray, qd: np.ndarray, dt: float) -> np.ndarray:
    """``q`` after moving at constant ``qd`` (world angular velocity) for ``dt``."""
    turned = quaternion_multiply(quaternion_from_rotation_vector(qd[3:6] * dt), q[3:7])
    return np.concatenate([q[:3] + qd[:3] * dt, turned, q[7:] + qd[6:] * dt])


def test_stretched_arm_lies_along_the_base_x_axis(model):
    fk = model.forward_kinematics(state(np.zeros(N)))
    expected = [
        [0.5, 0, 0],
        [1.2, 0, 0],
        [1.6, 0, 0],
        [2.0, 0, 0],
        [2.4, 0, 0],
        [2.8, 0, 0],
        [3.5, 0, 0],
    ]
    np.testing.assert_allclose(fk.origins, expected, atol=1e-15)
    np.testing.assert_allclose(np.asarray(fk), [3.5, 0.0, 0.0], atol=1e-15)
    # the twists α sum to 3π/2 about x
    c, s = math.cos(1.5 * math.pi), math.sin(1.5 * math.pi)
    np.testing.assert_allclose(
        fk.end_effector_rotation, [[1, 0, 0], [0, c, -s], [0, s, c]], atol=1e-15
    )
    np.testing.assert_allclose(fk.link_coms[0], [0.85, 0.0, 0.0])


def test_first_joint_at_90_degrees_swings_the_arm_to_y(model):
    fk = model.forward_kinematics(state([math.pi / 2, 0, 0, 0, 0, 0]))
    np.testing.assert_allclose(fk.end_effector, [0.5, 3.0, 0.0], atol=1e-14)
    np.testing.assert_allclose(fk.joint_axes[0], [0.0, 0.0, 1.0], atol=1e-15)


def test_second_joint_at_90_degrees_lifts_the_arm_about_minus_y(model):
    fk = model.forward_kinematics(state([0, math.pi / 2, 0, 0, 0, 0]))
    np.testing.assert_allclose(fk.joint_axes[1], [0.0, -1.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(fk.end_effector, [1.2, 0.0, 2.3], atol=1e-14)


def test_base_pose_moves_and_turns_the_whole_arm(model):
    quarter_turn_z = np.array([0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4)])
    fk = model.forward_kinematics(state(np.zeros(N), (1.0, 2.0, 3.0), quarter_turn_z))
    np.testing.assert_allclose(fk.end_effector, [1.0, 5.5, 3.0], atol=1e-14)


@pytest.mark.parametrize("seed", range(3))
def test_jacobian_matches_finite_differences_with_base_motion(model, seed):
    rng = np.random.default_rng(seed)
    q, qd = random_state(rng), rng.normal(size=6 + N)
    h = 1e-6
    after, before = (
        model.forward_kinematics(advance(q, qd, h)),
        model.forward_kinematics(advance(q, qd, -h)),
    )
    linear = (after.end_effector - before.end_effector) / (2 * h)
    relative = after.end_effector_rotation @ before.end_effector_rotation.T
    turn = rotation_matrix_to_vector(relative) / (2 * h)
    np.testing.assert_allclose(model.jacobian(q) @ qd, np.concatenate([linear, turn]), atol=1e-7)


def rotation_matrix_to_vector(rotation: np.ndarray) -> np.ndarray:
    return rotation_vector(Rotation.from_matrix(rotation).as_quat())


def test_rotation_matrix_matches_scipy():
    quaternion = np.array([0.1, -0.4, 0.3, 0.8])
    expected = Rotation.from_quat(quaternion).as_matrix()
    np.testing.assert_allclose(rotation_matrix(quaternion), expected, atol=1e-15)


def test_free_floating_jacobian_is_the_jacobian_at_zero_momentum(model):
    rng = np.random.default_rng(7)
    q, rates = random_state(rng), rng.normal(size=N)
    m = model.mass_matrix(q)
    base = -np.linalg.solve(m[:6, :6], m[:6, 6:] @ rates)
    qd = np.concatenate([base, rates])
    np.testing.assert_allclose(model.momentum(q, qd), 0.0, atol=1e-10)
    np.testing.assert_allclose(
        model.free_floating_jacobian(q) @ rates, model.jacobian(q) @ qd, atol=1e-12
    )


@pytest.mark.parametrize("base", ["held", "floating", "centre-of-mass"])
@pytest.mark.parametrize("seed", range(3))
def test_inverse_kinematics_converges_from_nearby_seeds(model, base, seed):
    rng = np.random.default_rng(seed)
    solution = random_state(rng)
    target = model.forward_kinematics(solution).end_effector
    seed_q = solution.copy()
    seed_q[7:] += rng.uniform(-0.1, 0.1, N)
    result = model.inverse_kinematics(target, seed_q, base=base)
    assert result.converged, result
    assert result.error <= 1e-10
    assert np.linalg.norm(model.forward_kinematics(result.q).end_effector - target) <= 1e-10
    if base == "held":
        np.testing.assert_array_equal(result.q[:7], seed_q[:7])
    if base == "centre-of-mass":  # the base's attitude held, the whole robot's centre kept
        np.testing.assert_array_equal(result.q[3:7], seed_q[3:7])
        np.testing.assert_allclose(
            model.centre_of_mass(result.q), model.centre_of_mass(seed_q), atol=1e-12
        )


def test_centre_of_mass_weighs_the_base_and_every_link(model):
    q = state(np.full(N, 0.3))
    frames = model.forward_kinematics(q)
    masses = np.array([20.0, 15.0, 15.0, 15.0, 15.0, 20.0])
    expected = (1000.0 * q[:3] + masses @ frames.link_coms) / 1100.0
    np.testing.assert_allclose(model.centre_of_mass(q), expected, atol=1e-15)


def test_inverse_kinematics_reports_an_unreachable_target(model):
    result = model.inverse_kinematics([5.0, 0.0, 0.0], state(np.full(N, 0.3)))
    assert result.status == "unreachable"
    assert not result.converged
    assert result.error == pytest.approx(
        np.linalg.norm(np.subtract([5.0, 0, 0], model.forward_kinematics(result.q).end_effector))
    )


def test_inverse_kinematics_reports_a_singular_seed(model):
    stretched = state(np.zeros(N))
    assert model.det_jjt(stretched, position_only=True) == pytest.approx(0.0, abs=1e-20)
    result = model.inverse_kinematics([2.0, 1.0, 0.5], stretched)
    assert result.status == "singular"
    assert result.iterations == 0


def test_damped_inverse_kinematics_leaves_a_singular_seed(model):
    result = model.inverse_kinematics(
        [2.0, 1.0, 0.5], state(np.zeros(N)), damping=1e-2, max_iterations=200
    )
    assert result.converged, result


def test_det_jjt_is_positive_away_from_singularities(model):
    q = state([0.3, 0.5, -0.7, 0.4, 0.9, -0.2])
    assert model.det_jjt(q) > 1e-6
    assert model.det_jjt(q, position_only=True) > 1e-6


def test_a_link_inertia_no_body_can_have_is_refused():
    with pytest.raises(ValueError, match="at most the sum of the other two"):
        DHLink(a=0.5, alpha=0.0, d=0.0, mass=1.0, inertia=(0.05, 0.2, 0.3))
