"""The PD baseline controller."""

from __future__ import annotations

import numpy as np
import pytest
from dcsim_plugins.controllers.pd import PDController, design_gains
from scipy.spatial.transform import Rotation

from dcsim.api import Reference, RobotSpec, StateEstimate, Surroundings
from dcsim.scenario import read_scenario
from dcsim.world import World, WorldInputs

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


@pytest.mark.parametrize("bandwidth", [0.05, 0.2, 0.5, 1.0, 3.0, 17.3])
@pytest.mark.parametrize("damping", [0.3, 0.7, 0.9, 1.0, 1.5, 5.0])
def test_the_gains_are_python_control_s_ackermann_placement_to_the_bit(bandwidth, damping):
    import control  # the test extra's reference

    a = np.array([[0.0, 1.0], [0.0, 0.0]])
    b = np.array([[0.0], [1.0]])
    poles = np.roots([1.0, 2.0 * damping * bandwidth, bandwidth**2])
    expected = np.asarray(control.acker(a, b, poles)).ravel()
    assert design_gains(bandwidth, damping) == (expected[0], expected[1])


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


def test_without_an_attitude_reference_no_torque_is_commanded():
    pd = controller()
    estimate = StateEstimate(
        time=0.0, position=[1, 2, 3], attitude=[0, 0, 1, 0], angular_velocity=[0.1, 0, 0]
    )
    command = pd.command(0.0, estimate, Reference(time=0.0, position=[0, 0, 0]), Surroundings())
    assert command.force.any() and not command.torque.any()


def test_attitude_loop_is_textbook_pd_about_the_rotation_vector():
    pd = controller(attitude_bandwidth=0.5, attitude_damping=1.0)
    small = Rotation.from_rotvec([0.0, 0.0, 0.01])
    estimate = StateEstimate(time=0.0, attitude=small.as_quat(), angular_velocity=[0, 0, 0.002])
    reference = Reference(time=0.0, position=[0, 0, 0], attitude=[0, 0, 0, 1])
    torque = pd.command(0.0, estimate, reference, Surroundings()).torque
    expected = ROBOT.inertia @ (0.25 * np.array([0, 0, -0.01]) + 1.0 * np.array([0, 0, -0.002]))
    np.testing.assert_allclose(torque, expected, atol=1e-12)


def test_slews_a_free_flyer_in_pybullet_to_a_held_attitude_within_its_torque_limit():
    start = Rotation.from_euler("xyz", [60, -30, 100], degrees=True)
    target = Rotation.from_euler("xyz", [-20, 10, 0], degrees=True)
    quaternion = ",".join(f"{q:.17g}" for q in start.as_quat())
    scenario = read_scenario(
        None,
        [
            f"robot.initial.attitude=[{quaternion}]",
            "robot.initial.angular_velocity=[0.02,-0.01,0.03]",
            "world.frame=geocentric",
            "mission.targets=[]",
            "obstacles=[]",
        ],
    )
    pd = PDController({"attitude_bandwidth": 0.3})
    world = World(scenario, np.random.default_rng(0))
    try:
        pd.reset(world.robot_spec())
        home = world.base_state()[0].copy()
        reference = Reference(time=0.0, position=home, attitude=target.as_quat())
        peak_torque = 0.0
        for _ in range(1500):
            position, velocity, attitude, angular = world.base_state()
            estimate = StateEstimate(world.time, position, attitude, velocity, angular)
            command = pd.command(world.time, estimate, reference, Surroundings())
            peak_torque = max(peak_torque, float(np.linalg.norm(command.torque)))
            world.step(WorldInputs(force=command.force, torque=command.torque))
        _, _, attitude, angular = world.base_state()
    finally:
        world.close()
    assert (Rotation.from_quat(attitude) * target.inv()).magnitude() < 1e-3
    assert np.linalg.norm(angular) < 1e-3
    assert peak_torque <= scenario.robot.max_torque + 1e-9
