"""The computed-torque controller, flown on the manipulator's own model (no world)."""

from __future__ import annotations

import copy

import numpy as np
import pytest
from dcsim_plugins.controllers.computed_torque import ComputedTorqueController

from dcsim.api import PluginError, Reference, RobotSpec, Surroundings
from dcsim.testing.manipulator import estimate_of, simulate, thesis_robot
from tests.plugins.manipulator_reach import (
    DURATION,
    MODEL,
    PERIOD,
    ROBOT,
    START,
    reference,
    reference_states,
)


def controller(robot: RobotSpec = ROBOT, **params) -> ComputedTorqueController:
    plugin = ComputedTorqueController(params)
    plugin.reset(robot)
    return plugin


@pytest.fixture(scope="module")
def reach():
    return simulate(
        controller(), ROBOT, reference, START, np.zeros(12), DURATION, PERIOD, rtol=1e-7
    )


def test_tracks_the_thesis_reach_within_its_end_effector_error(reach):
    reached = np.array([MODEL.forward_kinematics(q).end_effector for q in reach.q])
    wanted = np.array(
        [MODEL.forward_kinematics(q).end_effector for q in reference_states(reach.times)]
    )
    error = np.linalg.norm(reached - wanted, axis=1).max()
    assert error <= 1e-4  # the thesis's ≈1e-4 m at k_P = 1, k_D = 10
    assert np.linalg.norm(reached[-1] - [1.5, 0.7, -1.0]) <= 1e-4
    assert np.linalg.norm(reach.q[:, :3], axis=1).max() <= 1e-5  # the base is held


def test_the_law_makes_every_coordinate_a_double_integrator():
    rng = np.random.default_rng(1)
    q = START + np.concatenate([rng.normal(0, 0.1, 3), np.zeros(4), rng.normal(0, 0.2, 6)])
    qd = rng.normal(0, 0.05, 12)
    wanted = reference(1.3)
    plugin = controller(kp=3.0, kd=2.0)
    command = plugin.command(0.0, estimate_of(0.0, q, qd), wanted, Surroundings())
    tau = np.concatenate([command.force, command.torque, command.joint_torques])
    acceleration = np.linalg.solve(MODEL.mass_matrix(q), tau - MODEL.bias(q, qd))
    attitude_error = -q[3:6] / np.linalg.norm(q[3:6]) * 2 * np.arccos(q[6]) if q[3:6].any() else 0
    error = np.concatenate([-q[:3], np.zeros(3) + attitude_error, wanted.joint_positions - q[7:]])
    rate_error = np.concatenate([-qd[:6], wanted.joint_velocities - qd[6:]])
    u = np.concatenate([np.zeros(6), wanted.joint_accelerations]) + 2.0 * rate_error + 3.0 * error
    np.testing.assert_allclose(acceleration, u, atol=1e-9)


def test_attitude_error_drives_the_angular_acceleration_as_a_rotation_vector():
    turned = START.copy()
    turned[3:7] = [0.0, 0.0, np.sin(0.05), np.cos(0.05)]  # 0.1 rad about z
    plugin = controller()
    command = plugin.command(
        0.0, estimate_of(0.0, turned, np.zeros(12)), reference(0.0), Surroundings()
    )
    tau = np.concatenate([command.force, command.torque, command.joint_torques])
    acceleration = np.linalg.solve(MODEL.mass_matrix(turned), tau)
    np.testing.assert_allclose(acceleration[3:6], [0.0, 0.0, -0.1], atol=1e-12)


def test_commands_stay_within_the_robots_limits():
    robot = thesis_robot(max_force=3.0, max_torque=1.0, joint_torque=0.5)
    far = START.copy()
    far[7:] += 0.5
    loop = simulate(controller(robot), robot, reference, far, np.zeros(12), 1.0, 0.05)
    force = max(np.linalg.norm(c.force) for c in loop.commands)
    torque = max(np.linalg.norm(c.torque) for c in loop.commands)
    joints = max(np.abs(c.joint_torques).max() for c in loop.commands)
    assert force == pytest.approx(3.0) and torque <= 1.0 + 1e-12 and joints == pytest.approx(0.5)


def test_designed_gains_place_the_poles():
    plugin = controller(bandwidth=2.0, damping=0.7)
    assert (plugin.kp, plugin.kd) == pytest.approx((4.0, 2.8))
    assert (controller().kp, controller().kd) == (1.0, 10.0)


def test_is_deterministic_and_leaves_its_inputs_alone():
    rng = np.random.default_rng(4)
    estimate = estimate_of(
        0.5, START + np.r_[np.zeros(7), rng.normal(0, 0.1, 6)], rng.normal(0, 0.1, 12)
    )
    kept = copy.deepcopy(estimate), copy.deepcopy(reference(0.5))
    first = controller().command(0.5, estimate, reference(0.5), Surroundings())
    second = controller().command(0.5, estimate, reference(0.5), Surroundings())
    np.testing.assert_array_equal(
        np.concatenate([first.force, first.torque, first.joint_torques]),
        np.concatenate([second.force, second.torque, second.joint_torques]),
    )
    for given, pristine in zip((estimate, reference(0.5)), kept, strict=True):
        for name in ("position", "attitude", "velocity", "joint_positions"):
            np.testing.assert_array_equal(getattr(given, name), getattr(pristine, name))


def test_a_free_flyer_is_refused_at_reset_with_a_reason():
    free_flyer = RobotSpec(mass=100.0, inertia=np.eye(3), max_force=5.0, max_torque=1.0)
    with pytest.raises(PluginError, match="manipulator"):
        ComputedTorqueController().reset(free_flyer)


def test_a_reference_with_the_wrong_number_of_joints_is_refused():
    wrong = Reference(time=0.0, position=np.zeros(3), joint_positions=np.zeros(4))
    with pytest.raises(ValueError, match="6 joints"):
        controller().command(0.0, estimate_of(0.0, START, np.zeros(12)), wrong, Surroundings())
