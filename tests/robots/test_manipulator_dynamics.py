"""The manipulator's mass and Coriolis matrices (thesis ch. 4) against their own
properties and against two independent implementations, PyBullet and Pinocchio, both
loading the URDF dcsim generates."""

from __future__ import annotations

import numpy as np
import pytest

from dcsim.bench.reference_models import BulletModel, PinocchioModel
from dcsim.bench.reference_models import random_state as reference_state
from dcsim.geometry import quaternion_from_rotation_vector, quaternion_multiply
from dcsim.robots.dh import DHLink, DHRobot, ManipulatorBase, thesis_manipulator
from dcsim.robots.manipulator import ManipulatorModel
from dcsim.world.pybullet_client import pb

N = 6
SEEDS = range(4)
#: agreement required with the independent implementations (largest difference over the
#: reference's largest entry)
RELATIVE = 1e-9


@pytest.fixture(scope="module")
def model() -> ManipulatorModel:
    return ManipulatorModel(thesis_manipulator())


def random_state(seed: int) -> tuple[np.ndarray, np.ndarray]:
    return reference_state(np.random.default_rng(seed), N)


def advance(q: np.ndarray, qd: np.ndarray, dt: float) -> np.ndarray:
    turned = quaternion_multiply(quaternion_from_rotation_vector(qd[3:6] * dt), q[3:7])
    return np.concatenate([q[:3] + qd[:3] * dt, turned, q[7:] + qd[6:] * dt])


def relative_error(ours: np.ndarray, reference: np.ndarray) -> float:
    return float(np.abs(ours - reference).max() / np.abs(reference).max())


@pytest.mark.parametrize("seed", SEEDS)
def test_mass_matrix_is_symmetric_positive_definite(model, seed):
    q, _ = random_state(seed)
    m = model.mass_matrix(q)
    np.testing.assert_array_equal(m, m.T)
    assert np.linalg.eigvalsh(m).min() > 0.0


def test_mass_matrix_top_left_is_the_total_mass(model):
    q, _ = random_state(0)
    np.testing.assert_allclose(model.mass_matrix(q)[:3, :3], 1100.0 * np.eye(3), rtol=1e-15)


@pytest.mark.parametrize("seed", SEEDS)
def test_mass_matrix_rate_minus_twice_coriolis_is_skew_symmetric(model, seed):
    q, qd = random_state(seed)
    h = 1e-6
    m_rate = (model.mass_matrix(advance(q, qd, h)) - model.mass_matrix(advance(q, qd, -h))) / (
        2 * h
    )
    s = m_rate - 2.0 * model.coriolis_matrix(q, qd)
    assert np.abs(s + s.T).max() <= 1e-6 * np.abs(s).max()
    assert np.abs(s).max() > 1.0  # not trivially zero


def test_coriolis_vanishes_at_rest(model):
    q, _ = random_state(1)
    np.testing.assert_array_equal(model.bias(q, np.zeros(6 + N)), 0.0)


# --- PyBullet and Pinocchio (dcsim.bench.reference_models maps their orders to ours) ---


@pytest.fixture(scope="module")
def bullet(model):
    with BulletModel(model) as built:
        yield built


@pytest.fixture(scope="module")
def pinocchio_model(model):
    return PinocchioModel(model)


def test_pybullet_reads_every_mass_from_the_urdf(bullet):
    masses = [
        pb.getDynamicsInfo(bullet.body, link, physicsClientId=bullet.client)[0]
        for link in range(-1, 7)
    ]
    assert masses == [1000.0, 20.0, 15.0, 15.0, 15.0, 15.0, 20.0, 0.0]


@pytest.mark.parametrize("seed", SEEDS)
def test_mass_matrix_agrees_with_pybullet(model, bullet, seed):
    q, _ = random_state(seed)
    assert relative_error(model.mass_matrix(q), bullet.mass_matrix(q)) <= RELATIVE


@pytest.mark.parametrize("seed", SEEDS)
def test_bias_agrees_with_pybullet_inverse_dynamics(model, bullet, seed):
    q, qd = random_state(seed)
    assert relative_error(model.bias(q, qd), bullet.bias(q, qd)) <= RELATIVE


@pytest.mark.parametrize("seed", SEEDS)
def test_end_effector_jacobian_agrees_with_pybullet(model, bullet, seed):
    q, _ = random_state(seed)
    assert relative_error(model.jacobian(q), bullet.jacobian(q)) <= RELATIVE


@pytest.mark.parametrize("seed", SEEDS)
def test_mass_matrix_agrees_with_pinocchio(model, pinocchio_model, seed):
    q, _ = random_state(seed)
    assert relative_error(model.mass_matrix(q), pinocchio_model.mass_matrix(q)) <= RELATIVE


@pytest.mark.parametrize("seed", SEEDS)
def test_bias_agrees_with_pinocchio(model, pinocchio_model, seed):
    q, qd = random_state(seed)
    assert relative_error(model.bias(q, qd), pinocchio_model.bias(q, qd)) <= RELATIVE


@pytest.mark.parametrize("seed", SEEDS)
def test_end_effector_jacobian_agrees_with_pinocchio(model, pinocchio_model, seed):
    q, _ = random_state(seed)
    assert relative_error(model.jacobian(q), pinocchio_model.jacobian(q)) <= RELATIVE
    position, rotation = pinocchio_model.end_effector_pose(q)
    fk = model.forward_kinematics(q)
    np.testing.assert_allclose(position, fk.end_effector, atol=1e-12)
    np.testing.assert_allclose(rotation, fk.end_effector_rotation, atol=1e-12)


def skewed_robot() -> DHRobot:
    """Offsets, link offsets d and twists the thesis's robot does not have."""
    rows = [
        (0.3, -0.4, 0.2, 0.3),
        (0.5, 1.1, -0.15, -0.7),
        (0.25, -2.0, 0.1, 1.2),
        (0.0, 0.6, 0.35, 0.0),
    ]
    links = tuple(
        DHLink(
            a=a,
            alpha=alpha,
            d=d,
            theta_offset=offset,
            mass=5.0 + i,
            inertia=(0.1 + 0.01 * i, 0.2, 0.25),
        )
        for i, (a, alpha, d, offset) in enumerate(rows)
    )
    base = ManipulatorBase(
        mass=200.0, inertia=(20.0, 30.0, 25.0), size=(1.0, 0.8, 0.6), mount=(0.4, 0.1, -0.2)
    )
    return DHRobot(base=base, links=links, name="skewed")


def test_a_robot_with_offsets_and_twists_agrees_with_pinocchio_and_pybullet():
    model = ManipulatorModel(skewed_robot())
    pinocchio_model = PinocchioModel(model)
    rng = np.random.default_rng(11)
    with BulletModel(model) as bullet:
        for _ in range(3):
            q, qd = reference_state(rng, model.n_joints)
            for reference in (pinocchio_model, bullet):
                assert relative_error(model.mass_matrix(q), reference.mass_matrix(q)) <= RELATIVE
                assert relative_error(model.bias(q, qd), reference.bias(q, qd)) <= RELATIVE
                assert relative_error(model.jacobian(q), reference.jacobian(q)) <= RELATIVE
