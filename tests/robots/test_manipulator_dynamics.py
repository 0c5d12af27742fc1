"""The manipulator's mass and Coriolis matrices (thesis ch. 4) against their own
properties and against two independent implementations, PyBullet and Pinocchio, both
loading the URDF dcsim generates."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pybullet
import pytest

from dcsim.geometry import quaternion_from_rotation_vector, quaternion_multiply
from dcsim.robots.dh import DHLink, DHRobot, ManipulatorBase, thesis_manipulator
from dcsim.robots.kinematics import rotation_matrix
from dcsim.robots.manipulator import ManipulatorModel

N = 6
SEEDS = range(4)
#: agreement required with the independent implementations (largest difference over the
#: reference's largest entry)
RELATIVE = 1e-9


@pytest.fixture(scope="module")
def model() -> ManipulatorModel:
    return ManipulatorModel(thesis_manipulator())


def random_state(seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    quaternion = rng.normal(size=4)
    quaternion /= np.linalg.norm(quaternion)
    q = np.concatenate([rng.normal(size=3), quaternion, rng.uniform(-math.pi, math.pi, N)])
    return q, rng.normal(size=6 + N)


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


# --- PyBullet: [ω_b, v_b, θ̇] in the base frame, inverse dynamics returns [F_b, M_b, τ] ---


@pytest.fixture(scope="module")
def bullet(model, tmp_path_factory):
    path = tmp_path_factory.mktemp("urdf") / "manipulator.urdf"
    path.write_text(model.urdf())
    client = pybullet.connect(pybullet.DIRECT)
    body = pybullet.loadURDF(
        str(path), flags=pybullet.URDF_USE_INERTIA_FROM_FILE, physicsClientId=client
    )
    pybullet.setGravity(0, 0, 0, physicsClientId=client)
    yield client, body
    pybullet.disconnect(client)


def bullet_map(q: np.ndarray) -> np.ndarray:
    """``T`` with PyBullet's velocity = ``T`` · ours."""
    rotation_t, n = rotation_matrix(q[3:7]).T, q.size - 7
    t = np.zeros((6 + n, 6 + n))
    t[:3, 3:6], t[3:6, :3], t[6:, 6:] = rotation_t, rotation_t, np.eye(n)
    return t


def test_pybullet_reads_every_mass_from_the_urdf(bullet):
    client, body = bullet
    masses = [
        pybullet.getDynamicsInfo(body, link, physicsClientId=client)[0] for link in range(-1, 7)
    ]
    assert masses == [1000.0, 20.0, 15.0, 15.0, 15.0, 15.0, 20.0, 0.0]


@pytest.mark.parametrize("seed", SEEDS)
def test_mass_matrix_agrees_with_pybullet(model, bullet, seed):
    client, body = bullet
    q, _ = random_state(seed)
    t = bullet_map(q)
    theirs = np.array(pybullet.calculateMassMatrix(body, list(q[7:]), physicsClientId=client))
    assert relative_error(model.mass_matrix(q), t.T @ theirs @ t) <= RELATIVE


@pytest.mark.parametrize("seed", SEEDS)
def test_bias_agrees_with_pybullet_inverse_dynamics(model, bullet, seed):
    client, body = bullet
    q, qd = random_state(seed)
    t = bullet_map(q)
    out = pybullet.calculateInverseDynamics(
        body, list(q), list(t @ qd), [0.0] * (6 + N), physicsClientId=client
    )
    out = np.asarray(out)
    theirs = t.T @ np.concatenate([out[3:6], out[:3], out[6:]])
    assert relative_error(model.bias(q, qd), theirs) <= RELATIVE


# --- Pinocchio: free flyer with [v, ω] of the base frame in the base frame ---


@pytest.fixture(scope="module")
def pinocchio_model(model):
    built = pin.buildModelFromXML(model.urdf(), pin.JointModelFreeFlyer())
    built.gravity.setZero()
    return built, built.createData()


def pinocchio_map(q: np.ndarray) -> np.ndarray:
    """``T`` with Pinocchio's velocity = ``T`` · ours."""
    rotation_t, n = rotation_matrix(q[3:7]).T, q.size - 7
    t = np.zeros((6 + n, 6 + n))
    t[:3, :3], t[3:6, 3:6], t[6:, 6:] = rotation_t, rotation_t, np.eye(n)
    return t


@pytest.mark.parametrize("seed", SEEDS)
def test_mass_matrix_agrees_with_pinocchio(model, pinocchio_model, seed):
    built, data = pinocchio_model
    q, _ = random_state(seed)
    t = pinocchio_map(q)
    theirs = pin.crba(built, data, q)
    theirs = np.triu(theirs) + np.triu(theirs, 1).T
    assert relative_error(model.mass_matrix(q), t.T @ theirs @ t) <= RELATIVE


@pytest.mark.parametrize("seed", SEEDS)
def test_bias_agrees_with_pinocchio(model, pinocchio_model, seed):
    """Pinocchio's base velocity is in the turning base frame: zero world acceleration is
    its acceleration ``[−ω × v, 0, 0]`` (local), so C q̇ is RNEA there."""
    built, data = pinocchio_model
    q, qd = random_state(seed)
    t = pinocchio_map(q)
    v = t @ qd
    acceleration = np.zeros(6 + N)
    acceleration[:3] = -np.cross(v[3:6], v[:3])
    theirs = t.T @ pin.rnea(built, data, q, v, acceleration)
    assert relative_error(model.bias(q, qd), theirs) <= RELATIVE


@pytest.mark.parametrize("seed", SEEDS)
def test_end_effector_jacobian_agrees_with_pinocchio(model, pinocchio_model, seed):
    built, data = pinocchio_model
    q, _ = random_state(seed)
    frame = built.getFrameId("end_effector")
    pin.computeJointJacobians(built, data, q)
    pin.updateFramePlacements(built, data)
    theirs = pin.getFrameJacobian(built, data, frame, pin.LOCAL_WORLD_ALIGNED) @ pinocchio_map(q)
    assert relative_error(model.jacobian(q), theirs) <= RELATIVE
    np.testing.assert_allclose(
        data.oMf[frame].translation, model.forward_kinematics(q).end_effector, atol=1e-12
    )
    np.testing.assert_allclose(
        data.oMf[frame].rotation, model.forward_kinematics(q).end_effector_rotation, atol=1e-12
    )


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


def test_a_robot_with_offsets_and_twists_agrees_with_pinocchio_and_pybullet(tmp_path):
    model = ManipulatorModel(skewed_robot())
    n = model.n_joints
    built = pin.buildModelFromXML(model.urdf(), pin.JointModelFreeFlyer())
    built.gravity.setZero()
    data = built.createData()
    path = tmp_path / "skewed.urdf"
    path.write_text(model.urdf())
    client = pybullet.connect(pybullet.DIRECT)
    try:
        body = pybullet.loadURDF(
            str(path), flags=pybullet.URDF_USE_INERTIA_FROM_FILE, physicsClientId=client
        )
        rng = np.random.default_rng(11)
        for _ in range(3):
            quaternion = rng.normal(size=4)
            q = np.concatenate(
                [rng.normal(size=3), quaternion / np.linalg.norm(quaternion), rng.uniform(-3, 3, n)]
            )
            qd = rng.normal(size=6 + n)
            t_pin, t_bullet = pinocchio_map(q), bullet_map(q)
            m_pin = pin.crba(built, data, q)
            m_pin = np.triu(m_pin) + np.triu(m_pin, 1).T
            assert relative_error(model.mass_matrix(q), t_pin.T @ m_pin @ t_pin) <= RELATIVE
            m_bullet = np.array(
                pybullet.calculateMassMatrix(body, list(q[7:]), physicsClientId=client)
            )
            assert (
                relative_error(model.mass_matrix(q), t_bullet.T @ m_bullet @ t_bullet) <= RELATIVE
            )
            v = t_pin @ qd
            acceleration = np.zeros(6 + n)
            acceleration[:3] = -np.cross(v[3:6], v[:3])
            bias_pin = t_pin.T @ pin.rnea(built, data, q, v, acceleration)
            assert relative_error(model.bias(q, qd), bias_pin) <= RELATIVE
            pin.computeJointJacobians(built, data, q)
            pin.updateFramePlacements(built, data)
            frame = built.getFrameId("end_effector")
            jac = pin.getFrameJacobian(built, data, frame, pin.LOCAL_WORLD_ALIGNED) @ t_pin
            assert relative_error(model.jacobian(q), jac) <= RELATIVE
    finally:
        pybullet.disconnect(client)
