"""The PD baseline controller."""

from __future__ import annotations

import numpy as np
import pytest
from dcsim_plugins.controllers.pd import PDController, design_gains

from dcsim.api import Reference, RobotSpec, StateEstimate, Surroundings

ROBOT = RobotSpec(
    mass=100.0, inertia=10.0 * np.eye(3), radius=0.5, max_force=5.0, max_torque=0.5, max_speed=0.5
)


def controller(**params):
    pd = PDController(params)
    pd.reset(ROBOT)
    return pd


@pytest.mark.parametrize("bandwidth, damping", [(0.2, 0.9), (1.0, 1.0), (0.05, 2.0)])
def test_pole_placement_gives_the_second_order_gains(bandwidth, damping):
    kp, kd = design_gains(bandwidth, damping)
    assert kp == pytest.approx(bandwidth**2)
    assert kd == pytest.approx(2 * damping * bandwidth)


def test_no_error_and_no_reference_velocity_commands_nothing():
    pd = controller()
    estimate = StateEstimate(time=0.0, position=[3, 4, 5], velocity=[0, 0, 0])
    command = pd.command(0.0, estimate, Reference(time=0.0, position=[3, 4, 5]), Surroundings())
    assert not command.force.any() and not command.torque.any()


def test_unsaturated_law_is_textbook_pd():
    pd = controller(bandwidth=0.2, damping=0.9)
    estimate = StateEstimate(time=0.0, position=[0.1, 0, 0], velocity=[0, 0.01, 0])
    command = pd.command(0.0, estimate, Reference(time=0.0, position=[0, 0, 0]), Surroundings())
    expected = ROBOT.mass * (0.04 * np.array([-0.1, 0, 0]) + 0.36 * np.array([0, -0.01, 0]))
    np.testing.assert_allclose(command.force, expected, atol=1e-12)


def test_brings_a_double_integrator_to_the_reference_within_its_limits():
    pd = controller(bandwidth=0.2, damping=0.9)
    position, velocity, dt = np.array([20.0, -10.0, 5.0]), np.zeros(3), 0.1
    reference = Reference(time=0.0, position=[0, 0, 0])
    peak_force = peak_speed = 0.0
    for step in range(3000):
        estimate = StateEstimate(time=step * dt, position=position, velocity=velocity)
        force = pd.command(step * dt, estimate, reference, Surroundings()).force
        peak_force = max(peak_force, np.linalg.norm(force))
        velocity = velocity + force / ROBOT.mass * dt
        position = position + velocity * dt
        peak_speed = max(peak_speed, np.linalg.norm(velocity))
    assert np.linalg.norm(position) < 1e-3
    assert peak_force <= ROBOT.max_force + 1e-9
    assert peak_speed <= ROBOT.max_speed * 1.01
