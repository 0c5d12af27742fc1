"""The underactuated (partial base) controller, flown on the manipulator's own model."""

from __future__ import annotations

import numpy as np
import pytest
from dcsim_plugins.controllers.underactuated import UnderactuatedController, reduced_dynamics

from dcsim.api import PluginError, RobotSpec, Surroundings
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


def controller(robot: RobotSpec = ROBOT, **params) -> UnderactuatedController:
    plugin = UnderactuatedController(params)
    plugin.reset(robot)
    return plugin


@pytest.fixture(scope="module")
def reach():
    # twice the computed-torque test's period (k_D dt = 2 at the thesis's k_D = 100): the
    # run is half as long, and the law still holds the joints within the thesis's error
    period = 2 * PERIOD
    return simulate(
        controller(), ROBOT, reference, START, np.zeros(12), DURATION, period, rtol=1e-7
    )


def test_tracks_the_joints_within_the_thesis_error_without_thrust(reach):
    wanted = reference_states(reach.times)
    error = np.degrees(np.abs(reach.q[:, 7:] - wanted[:, 7:]).max())
    assert error <= 1e-3  # the thesis's ≈1e-3 deg at k_P = 10, k_D = 100
    assert all(not c.force.any() for c in reach.commands)
    attitude = np.abs(reach.q[:, 3:6]).max()
    assert attitude <= 1e-6


def test_the_base_drifts_as_zero_linear_momentum_dictates(reach):
    momentum = np.array(
        [MODEL.momentum(q, qd)[:3] for q, qd in zip(reach.q, reach.qd, strict=True)]
    )
    assert np.abs(momentum).max() <= 1e-9  # kg·m/s, against a 1100 kg robot moving at cm/s
    drift = np.linalg.norm(reach.q[-1, :3])
    assert drift > 1e-3  # the base moves: it is not held


def test_the_reduced_law_makes_the_actuated_coordinates_double_integrators():
    rng = np.random.default_rng(2)
    q = START + np.concatenate([rng.normal(0, 0.1, 3), np.zeros(4), rng.normal(0, 0.2, 6)])
    qd = rng.normal(0, 0.05, 12)
    wanted = reference(2.1)
    plugin = controller(kp=3.0, kd=2.0)
    command = plugin.command(0.0, estimate_of(0.0, q, qd), wanted, Surroundings())
    tau = np.concatenate([command.force, command.torque, command.joint_torques])
    acceleration = np.linalg.solve(MODEL.mass_matrix(q), tau - MODEL.bias(q, qd))
    rate_error = np.concatenate([-qd[3:6], wanted.joint_velocities - qd[6:]])
    error = np.concatenate([np.zeros(3), wanted.joint_positions - q[7:]])
    u = np.concatenate([np.zeros(3), wanted.joint_accelerations]) + 2.0 * rate_error + 3.0 * error
    np.testing.assert_allclose(acceleration[3:], u, atol=1e-9)


def test_reduced_dynamics_match_eliminating_the_base_translation():
    rng = np.random.default_rng(3)
    q = START + np.concatenate([np.zeros(7), rng.normal(0, 0.3, 6)])
    qd = rng.normal(0, 0.1, 12)
    mass, coriolis = MODEL.mass_matrix(q), MODEL.coriolis_matrix(q, qd)
    reduced_m, reduced_c1, reduced_c2 = reduced_dynamics(mass, coriolis)
    qdd_a = rng.normal(0, 0.1, 9)
    qdd_u = -np.linalg.solve(mass[:3, :3], mass[:3, 3:] @ qdd_a + coriolis[:3] @ qd)  # eq. 6.15
    full = mass @ np.concatenate([qdd_u, qdd_a]) + coriolis @ qd
    reduced = reduced_m @ qdd_a + reduced_c1 @ qd[3:] + reduced_c2 @ qd[:3]
    np.testing.assert_allclose(full[3:], reduced, atol=1e-9)
    np.testing.assert_allclose(full[:3], 0.0, atol=1e-9)
    np.testing.assert_allclose(reduced_m, reduced_m.T, atol=1e-9)


def test_commands_stay_within_the_robots_limits_and_never_thrust():
    robot = thesis_robot(max_force=3.0, max_torque=1.0, joint_torque=0.5)
    far = START.copy()
    far[7:] += 0.5
    loop = simulate(controller(robot), robot, reference, far, np.zeros(12), 0.5, 0.01)
    assert all(not c.force.any() for c in loop.commands)
    assert max(np.linalg.norm(c.torque) for c in loop.commands) <= 1.0 + 1e-12
    assert max(np.abs(c.joint_torques).max() for c in loop.commands) == pytest.approx(0.5)


def test_defaults_are_the_thesis_gains_and_determinism():
    plugin = controller()
    assert (plugin.kp, plugin.kd) == (10.0, 100.0)
    estimate = estimate_of(0.2, START, np.full(12, 0.01))
    first = plugin.command(0.2, estimate, reference(0.2), Surroundings())
    second = controller().command(0.2, estimate, reference(0.2), Surroundings())
    np.testing.assert_array_equal(first.joint_torques, second.joint_torques)
    np.testing.assert_array_equal(first.torque, second.torque)


def test_a_free_flyer_is_refused_at_reset_with_a_reason():
    free_flyer = RobotSpec(mass=100.0, inertia=np.eye(3), max_force=5.0, max_torque=1.0)
    with pytest.raises(PluginError, match="manipulator"):
        UnderactuatedController().reset(free_flyer)
