"""The manipulator in the PyBullet world: the multibody matches the model, inputs are
clipped, nothing damps it, and momentum drifts only to first order in the physics step."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from dcsim.errors import ScenarioError
from dcsim.robots.manipulator import ManipulatorModel
from dcsim.scenario import read_scenario
from dcsim.world import World, WorldInputs
from dcsim.world.pybullet_client import pb
from tests.conftest import REPO

FIXTURE = REPO / "tests" / "world" / "data" / "thesis_manipulator.yaml"


def scenario(tmp_path, **changes):
    """The fixture scenario with ``changes`` (``section.key`` → value; None takes the
    key out) applied."""
    data = yaml.safe_load(FIXTURE.read_text())
    for dotted, value in changes.items():
        node = data
        *parents, last = dotted.split(".")
        for key in parents:
            node = node[int(key)] if isinstance(node, list) else node[key]
        if value is None:
            node.pop(last)
        else:
            node[last] = value
    path = tmp_path / "arm.yaml"
    path.write_text(yaml.safe_dump(data))
    return read_scenario(path)


def world(tmp_path, **changes) -> World:
    return World(scenario(tmp_path, **changes), np.random.default_rng(0))


def q_qd(w: World) -> tuple[np.ndarray, np.ndarray]:
    s = w.robot_state()
    return (
        np.r_[s.position, s.attitude, s.joint_positions],
        np.r_[s.velocity, s.angular_velocity, s.joint_velocities],
    )


def momentum(w: World) -> np.ndarray:
    """Linear and angular momentum about the world origin (the conserved ones), (6,)."""
    q, qd = q_qd(w)
    about_base = w.robot_spec().model.momentum(q, qd)
    return np.r_[about_base[:3], about_base[3:] + np.cross(q[:3], about_base[:3])]


def test_spec_carries_the_model_and_joint_limits(tmp_path):
    w = world(tmp_path, **{"robot.links.0.torque_limit": 5.0})
    spec = w.robot_spec()
    assert isinstance(spec.model, ManipulatorModel) and spec.model.n_joints == 6
    assert spec.mass == pytest.approx(1000.0 + 100.0)
    assert spec.joint_torque_limits[0] == 5.0 and np.isinf(spec.joint_torque_limits[1:]).all()
    assert spec.joint_position_limits.shape == (6, 2)
    assert np.isinf(spec.joint_position_limits).all()
    np.testing.assert_allclose(spec.inertia, np.diag([166.67] * 3))


def test_end_effector_of_the_world_is_the_models(tmp_path):
    w = world(
        tmp_path,
        **{
            "robot.initial.attitude": [0.2, -0.3, 0.1, 0.9],
            "robot.initial.angular_velocity": [0.05, -0.02, 0.03],
            "robot.initial.joint_rates_deg_s": [5, -3, 8, 2, -6, 4],
        },
    )
    w.step(WorldInputs(force=np.array([5.0, 0, 0]), joint_torques=np.full(6, 3.0)))
    q, _ = q_qd(w)
    end = pb.getNumJoints(w.robot_id, physicsClientId=w.client) - 1
    link = pb.getLinkState(w.robot_id, end, computeForwardKinematics=1, physicsClientId=w.client)
    model = w.robot_spec().model
    np.testing.assert_allclose(link[4], model.forward_kinematics(q).end_effector, atol=1e-12)
    np.testing.assert_array_equal(w.end_effector(), model.forward_kinematics(q).end_effector)
    # PyBullet's link orientation comes back to ~4e-8 (its quaternion conversion).
    rotation = np.array(pb.getMatrixFromQuaternion(link[5])).reshape(3, 3)
    np.testing.assert_allclose(rotation, model.forward_kinematics(q).rotations[-1], atol=1e-7)


def test_mass_matrix_of_the_world_is_the_models(tmp_path):
    """PyBullet's M at the world's joint angles, ordered [ω_b, v_b, θ̇] in the base frame,
    against the model's at an identity base attitude (base frame = world frame)."""
    w = world(tmp_path)
    q, _ = q_qd(w)
    joints = q[7:].tolist()
    ours = w.robot_spec().model.mass_matrix(np.r_[np.zeros(3), 0, 0, 0, 1, q[7:]])
    theirs = np.array(pb.calculateMassMatrix(w.robot_id, joints, physicsClientId=w.client))
    order = [3, 4, 5, 0, 1, 2, *range(6, 12)]  # ours [v, ω, θ̇] → PyBullet's [ω, v, θ̇]
    np.testing.assert_allclose(ours[np.ix_(order, order)], theirs, rtol=0, atol=1e-9 * 1100)


def test_thrust_torque_and_joint_torques_are_clipped(tmp_path):
    limits = {
        "robot.max_force": 10.0,
        "robot.max_torque": 2.0,
        **{f"robot.links.{i}.torque_limit": 4.0 for i in range(6)},
    }
    big, exact = world(tmp_path, **limits), world(tmp_path, **limits)
    direction = np.array([0.6, 0.8, 0.0])
    big.step(
        WorldInputs(
            force=1e4 * direction,
            torque=1e3 * direction,
            joint_torques=np.array([1e3, -1e3, 50, -50, 1e5, -4.0]),
        )
    )
    exact.step(
        WorldInputs(
            force=10 * direction,
            torque=2 * direction,
            joint_torques=np.array([4.0, -4.0, 4.0, -4.0, 4.0, -4.0]),
        )
    )
    for ours, theirs in zip(q_qd(big), q_qd(exact), strict=True):
        np.testing.assert_array_equal(ours, theirs)
    assert np.abs(big.robot_state().joint_velocities).max() > 0
    with pytest.raises(ValueError, match="3 joint torques for 6 joints"):
        big.step(WorldInputs(joint_torques=np.ones(3)))


def test_a_free_arm_keeps_its_momentum(tmp_path):
    """Nothing damps the base or the links: a coasting, turning arm keeps its momentum."""
    w = world(
        tmp_path,
        **{
            "robot.initial.velocity": [0.1, -0.05, 0.02],
            "robot.initial.angular_velocity": [0.0, 0.0, 0.05],
            "robot.initial.joint_rates_deg_s": [10, -10, 10, -10, 10, -10],
        },
    )
    start = momentum(w)
    for _ in range(50):  # 0.5 s
        w.step()
    end = momentum(w)
    # Damping of PyBullet's default (0.04 1/s) would lose ~2 % in 0.5 s.
    np.testing.assert_allclose(end[:3], start[:3], rtol=1e-4)
    np.testing.assert_allclose(end[3:], start[3:], atol=1e-4 * np.abs(start[3:]).max())


def momentum_drift(tmp_path, step: float) -> float:
    """Largest change of total momentum over 0.5 s of joint torques only."""
    w = world(tmp_path, **{"world.physics_step": step, "world.duration": 0.5})
    start = momentum(w)
    torques = np.array([20.0, -20.0, 20.0, -20.0, 20.0, -20.0])
    drift = 0.0
    for _ in range(50):
        w.step(WorldInputs(joint_torques=torques))
        drift = max(drift, float(np.abs(momentum(w) - start).max()))
    return drift


def test_momentum_drift_falls_with_the_physics_step_to_first_order(tmp_path):
    coarse, fine = momentum_drift(tmp_path, 2e-3), momentum_drift(tmp_path, 5e-4)
    order = np.log(coarse / fine) / np.log(4.0)
    print(f"momentum drift: {coarse:.3g} at 2e-3 s, {fine:.3g} at 5e-4 s, order {order:.2f}")
    assert 0.7 < order < 1.5


# ---------------------------------------------------------------- reaction wheels
PYRAMID_WHEELS = [
    {"axis": axis, "inertia": 0.5, "max_torque": 5.0, "max_momentum": 50.0}
    for axis in ([1, 1, 1], [-1, 1, 1], [-1, -1, 1], [1, -1, 1])
]
"""Four wheels in a pyramid about base +z."""


def test_a_manipulator_s_base_takes_the_free_flyer_s_wheels_and_their_limits(tmp_path):
    """``robot.actuators`` on a manipulator: its torque limit is the wheels' (as a free
    flyer's with the same wheels), and a larger ``max_torque`` given is refused."""
    wheels = {"robot.actuators": {"reaction_wheels": PYRAMID_WHEELS}, "robot.max_torque": None}
    arm = scenario(tmp_path, **wheels)
    flyer = read_scenario(
        {"world": {"frame": "geocentric"}, "robot": {"actuators": arm.robot.actuators.model_dump()}}
    )
    assert arm.robot.max_torque == flyer.robot.max_torque < 10.0
    with pytest.raises(ScenarioError, match="robot.max_torque.*exceeds the reaction wheels'"):
        scenario(
            tmp_path,
            **{"robot.actuators": {"reaction_wheels": PYRAMID_WHEELS}, "robot.max_torque": 100.0},
        )


def wheel_run(tmp_path, wheels: bool) -> tuple[float, float, float]:
    """Fly the arm for 1 s on joint torques with the base's rate damped (by the wheels,
    or not at all); the largest change of total angular momentum (base and arm from
    their states, plus the wheels' own, N·m·s), the largest wheel momentum (N·m·s) and
    the largest base rate (rad/s)."""
    hardware = {"robot.actuators": {"reaction_wheels": PYRAMID_WHEELS}, "robot.max_torque": None}
    changes = hardware if wheels else {}
    w = world(tmp_path, **changes)
    start = momentum(w)[3:]
    torques = np.array([2.0, -2.0, 2.0, -2.0, 2.0, -2.0])
    drift = peak_h = peak_rate = 0.0
    for _ in range(100):
        state = w.robot_state()
        total = momentum(w)[3:]
        if wheels:
            rotation = np.reshape(pb.getMatrixFromQuaternion(state.attitude.tolist()), (3, 3))
            h = rotation @ w.wheels.axes @ w.wheels.momentum
            total, peak_h = total + h, max(peak_h, float(np.linalg.norm(h)))
        drift = max(drift, float(np.linalg.norm(total - start)))
        peak_rate = max(peak_rate, float(np.linalg.norm(state.angular_velocity)))
        damping = -200.0 * state.angular_velocity if wheels else np.zeros(3)
        w.step(WorldInputs(joint_torques=torques, torque=damping))
    return drift, peak_h, peak_rate


def test_wheels_on_a_manipulator_s_base_keep_the_total_angular_momentum(tmp_path):
    """The wheels take up several N·m·s holding the base against the arm, and base, arm
    and wheels together keep their angular momentum as well as base and arm alone do
    without wheels (PyBullet's first-order drift, 0.044 N·m·s here, either way): a
    wheel reaction of the wrong sign or size would add about twice the wheels'
    momentum."""
    bare, _, bare_rate = wheel_run(tmp_path, wheels=False)
    held, peak_h, held_rate = wheel_run(tmp_path, wheels=True)
    assert peak_h > 3.0
    assert held_rate < 0.8 * bare_rate
    assert held <= 1.1 * bare
