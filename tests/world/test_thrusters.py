"""Thrusters (``robot.actuators: {thrusters: [...]}``): the scenario key, allocation and
its shortfall, the minimum impulse bit, the firing recomputed from the recorded
on-times, each thruster's propellant, momentum unloading, commands given per thruster
and per wheel, and the default mission flown on hardware with its attitude held."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import nnls

from dcsim.api import (
    Command,
    Controller,
    RobotSpec,
    quaternion_conjugate,
    quaternion_multiply,
    rotate,
    rotation_vector,
)
from dcsim.errors import ScenarioError
from dcsim.registry.answers import ActuatorCounts, output_problem
from dcsim.run.scripting import run
from dcsim.scenario.loader import read_scenario
from dcsim.testing import ContractViolation, checks_for
from dcsim.world import World, WorldInputs
from dcsim.world.environment import STANDARD_GRAVITY
from dcsim.world.pybullet_client import pb
from dcsim.world.thrusters import Thrusters
from tests.conftest import REPO

ARM = 0.4
THRUST = 2.5
MIB = 0.025  # N·s: 10 ms at full thrust


def couples(isp=None, mib=MIB):
    """Twelve thrusters in six opposed couples: ±x at y = ±ARM, ±y at z = ±ARM, ±z at
    x = ±ARM."""
    thrusters = []
    for axis, offset in ((0, 1), (1, 2), (2, 0)):
        for sign in (1, -1):
            for side in (1, -1):
                position, direction = [0.0] * 3, [0.0] * 3
                position[offset], direction[axis] = side * ARM, sign
                thrusters.append(
                    {
                        "position": position,
                        "direction": direction,
                        "max_thrust": THRUST,
                        "min_impulse_bit": mib,
                        **({} if isp is None else {"specific_impulse": isp}),
                    }
                )
    return thrusters


def wheel(axis):
    return {"axis": axis, "inertia": 0.02, "max_torque": 0.2, "max_momentum": 1.0}


PYRAMID = [wheel([1, 1, 1]), wheel([-1, 1, 1]), wheel([-1, -1, 1]), wheel([1, -1, 1])]


def scenario(thrusters=None, wheels=None, duration=60.0, **robot):
    """A free flyer far from anything, in a frame with no orbital forces, holding its
    initial attitude and position."""
    actuators = {"thrusters": couples() if thrusters is None else thrusters}
    if wheels is not None:
        actuators["reaction_wheels"] = wheels
    return {
        "name": "thrusters",
        "world": {"frame": "geocentric", "duration": duration},
        "robot": {"inertia": [8.0, 9.0, 10.0], "actuators": actuators, **robot},
        "mission": {"type": "hold"},
    }


def open_world(**kwargs):
    return World(read_scenario(scenario(**kwargs)), np.random.default_rng(0))


def momenta(world):
    """Linear (world frame) and angular (body frame) momentum of the base, from
    PyBullet's state and inertia."""
    _, velocity, attitude, angular = world.base_state()
    rotation = np.reshape(pb.getMatrixFromQuaternion(attitude.tolist()), (3, 3))
    info = pb.getDynamicsInfo(world.robot_id, -1, physicsClientId=world.client)
    return info[0] * velocity, np.array(info[2]) * (rotation.T @ angular)


# ------------------------------------------------------------------ scenario
def test_the_limits_are_the_thrusters_along_the_weakest_axis():
    robot = read_scenario(scenario()).robot
    assert robot.max_force == pytest.approx(2 * THRUST)  # one couple per direction
    assert robot.max_torque == pytest.approx(2 * THRUST * ARM)


def test_a_layout_that_cannot_push_some_way_is_named():
    without_minus_x = [t for t in couples() if t["direction"] != [-1.0, 0.0, 0.0]]
    with pytest.raises(ScenarioError) as info:
        read_scenario(scenario(thrusters=without_minus_x))
    [problem] = info.value.problems
    assert problem.path == "robot.actuators.thrusters"
    # the -x thrusters also made the couples about z: +x at +y with -x at -y
    assert "no force along -x; no torque along +z, -z" in problem.message


def test_a_max_force_beyond_the_thrusters_is_refused():
    with pytest.raises(ScenarioError) as info:
        read_scenario(scenario(max_force=6.0))
    [problem] = info.value.problems
    assert problem.path == "robot.max_force" and "exceeds the thrusters' force" in problem.message


# ------------------------------------------------------------------ allocation
def thrusters(**kwargs):
    return Thrusters(read_scenario(scenario(**kwargs)).robot.actuators.thrusters, 220.0, 0.1, 0.01)


def test_a_wrench_within_reach_is_allocated_exactly():
    layout = thrusters(thrusters=couples(mib=0.0))
    force, torque = np.array([1.0, -2.0, 0.5]), np.array([0.1, 0.2, -0.3])
    firing = layout.allocate(force, torque)
    duty = firing.on_times / layout.period
    assert firing.shortfall == pytest.approx(0.0, abs=1e-9)
    assert layout.forces @ duty == pytest.approx(force, abs=1e-9)
    assert layout.torques @ duty == pytest.approx(torque, abs=1e-9)
    assert np.all(duty >= 0) and np.all(duty <= 1)


def test_a_wrench_beyond_reach_keeps_its_direction_and_reports_the_shortfall():
    layout = thrusters(thrusters=couples(mib=0.0))
    force, torque = np.array([5.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])  # x couple busy
    firing = layout.allocate(force, torque)
    duty = firing.on_times / layout.period
    delivered = np.concatenate([layout.forces @ duty, layout.torques @ duty])
    wanted = np.concatenate([force, torque])
    assert firing.shortfall > 0.1
    assert duty.max() == pytest.approx(1.0)
    cosine = delivered @ wanted / np.linalg.norm(delivered) / np.linalg.norm(wanted)
    assert cosine > 0.99


def test_the_minimum_impulse_bit_rounds_short_firings():
    layout = thrusters()
    t_min = MIB / THRUST
    asked = np.array([0.3 * t_min, 0.5 * t_min, 0.9 * t_min, 2 * t_min, 0.2, *[0.0] * 7])
    on = layout.round_on_times(asked)
    assert on.tolist() == pytest.approx([0.0, t_min, t_min, 2 * t_min, 0.1, *[0.0] * 7])


def test_each_step_gets_the_part_of_it_a_firing_covers():
    layout = thrusters()
    fractions = layout.step_fractions(np.array([0.025, *[0.0] * 11]))
    assert fractions[:, 0].tolist() == pytest.approx([1.0, 1.0, 0.5, *[0.0] * 7])


# ------------------------------------------------------------------ the world
def test_the_base_receives_the_firing_recomputed_from_the_recorded_on_times():
    with open_world() as world:
        world.step(WorldInputs())
        linear0, angular0 = momenta(world)
        force, torque = np.array([1.2, -0.7, 0.4]), np.array([0.02, -0.03, 0.05])
        world.step(WorldInputs(force=force, torque=torque))
        linear1, angular1 = momenta(world)
        on_times = world.outputs()["thruster_duty"] * world.control_period
        layout = world.actuators.thrusters
        impulse = layout.forces @ on_times
        angular_impulse = layout.torques @ on_times
    # the attitude barely moves in one period: the body frame is the world's to 1e-6
    assert linear1 - linear0 == pytest.approx(impulse, abs=1e-6)
    assert impulse == pytest.approx(force * world.control_period, abs=MIB)
    assert angular1 - angular0 == pytest.approx(angular_impulse, abs=1e-6)


def test_each_thruster_burns_at_its_own_specific_impulse():
    layout = couples()
    for thruster in layout[:2]:  # the +x couple
        thruster["specific_impulse"] = 70.0
    with World(read_scenario(scenario(thrusters=layout)), np.random.default_rng(0)) as world:
        world.step(WorldInputs(force=np.array([2.0, 0.0, 0.0])))
        on_times = world.outputs()["thruster_duty"] * world.control_period
        expected = THRUST * on_times[:2].sum() / (70.0 * STANDARD_GRAVITY)
        assert on_times[2:].sum() == 0.0
        assert world.fuel_used == pytest.approx(expected, rel=1e-12)


def test_a_command_beyond_the_thrusters_is_an_event_once():
    result = run(scenario(duration=1.0))
    assert not [e for e in result.events if e["event"] == "thrust_shortfall"]
    with open_world() as world:
        for _ in range(3):
            world.step(WorldInputs(force=np.array([5.0, 0.0, 0.0]), torque=np.array([0, 0, 1.0])))
        shortfalls = [e for e in world.actuators.events if e.name == "thrust_shortfall"]
        assert len(shortfalls) == 1 and shortfalls[0].data["missing"] > 0.1


def test_commands_per_thruster_and_per_wheel_are_flown_as_given():
    with open_world(wheels=PYRAMID) as world:
        on_times = np.zeros(12)
        on_times[0] = 0.05  # +x thruster at y = +ARM: force +x, torque -z
        world.step(WorldInputs(thruster_on_times=on_times, wheel_torques=np.array([0.1, 0, 0, 0])))
        duty = world.outputs()["thruster_duty"]
        assert duty[0] == pytest.approx(0.5) and not duty[1:].any()
        assert world.wheels.momentum[0] == pytest.approx(0.1 * world.control_period)
        assert not world.wheels.momentum[1:].any()


def test_a_command_for_actuators_the_robot_lacks_is_a_broken_contract():
    counts = ActuatorCounts(thrusters=12, wheels=4)
    assert output_problem("controller", "command", Command(), counts) is None
    wrong = Command(thruster_on_times=np.zeros(3))
    assert output_problem("controller", "command", wrong, counts) == (
        "returned 3 thruster on-times for a robot with 12 thrusters"
    )
    wrong = Command(wheel_torques=np.zeros(4))
    assert "for a robot with 0 reaction wheels" in output_problem(
        "controller", "command", wrong, ActuatorCounts()
    )


# ------------------------------------------------------------------ unloading
def test_thrusters_unload_full_wheels_while_the_attitude_is_held():
    data = scenario(wheels=PYRAMID, duration=120.0)
    data["robot"]["initial"] = {"angular_velocity": [0.0, 0.0, 0.25]}  # 3 N·m·s to soak up
    data["robot"]["actuators"]["unloading"] = {
        "start_fraction": 0.5,
        "stop_fraction": 0.05,
        "time_constant": 10.0,
    }
    result = run(data)
    events = [e for e in result.events if e["event"].startswith("unloading")]
    assert [e["event"] for e in events] == ["unloading_started", "unloading_ended"]
    telemetry = result.telemetry
    momenta = telemetry.filter(like="wheel_h_").abs().max(axis=1).to_numpy()
    ended = telemetry["time_s"].to_numpy() >= events[1]["t"] - 1e-9
    assert momenta.max() > 0.5 and momenta[ended][0] < 0.05 and momenta[-1] < 0.5
    # what the base still turned with when unloading ended went into the wheels: the
    # thrusters took out most of the 2.5 N·m·s the run began with
    axes = np.array([w["axis"] for w in PYRAMID], dtype=float).T / np.sqrt(3.0)
    held = axes @ telemetry.filter(like="wheel_h_").to_numpy()[-1]
    assert np.linalg.norm(held) < 0.2 * 2.5
    assert result.summary["fuel_attitude_kg"] > 0.0
    assert result.summary["fuel_translation_kg"] >= 0.0
    assert np.degrees(result.telemetry["attitude_error_rad"].iloc[-1]) < 0.1


# ------------------------------------------------------------------ a mission on hardware
def test_the_default_mission_on_hardware_delivers_and_holds_its_attitude():
    result = run(REPO / "scenarios" / "default_hardware.yaml")
    summary, telemetry = result.summary, result.telemetry
    assert summary["outcome"].startswith("delivered 4/4") and summary["collisions"] == 0
    rates = np.degrees(np.linalg.norm(telemetry[["wx_radps", "wy_radps", "wz_radps"]], axis=1))
    first_grab = next(e["t"] for e in result.events if e["event"] == "grab")
    after = telemetry["time_s"] >= first_grab
    assert rates[after].max() <= 0.5
    assert np.degrees(telemetry["attitude_error_rad"].max()) <= 1.0
    assert summary["fuel_attitude_kg"] + summary["fuel_translation_kg"] == pytest.approx(
        summary["fuel_used_kg"]
    )


# ------------------------------------------------------------------ conformance
class DirectHardware(Controller):
    """Commands each thruster's on-time and each wheel's torque itself: a PD law on the
    position and the attitude, the body force shared among the thrusters by non-negative
    least squares over the thrusters' geometry in the robot's spec, the body torque among
    the wheels by their axes' pseudo-inverse."""

    name = "direct-hardware"
    summary = "PD on thruster on-times and wheel torques"

    def reset(self, robot: RobotSpec) -> None:
        self.robot, self.last = robot, None

    def command(self, time, estimate, reference, surroundings) -> Command:
        period = 0.1 if self.last is None else time - self.last
        self.last = time
        rotation = np.column_stack([rotate(estimate.attitude, axis) for axis in np.eye(3)])
        error = reference.position - estimate.position
        force = self.robot.mass * (0.04 * error - 0.4 * estimate.velocity)
        duty = nnls(self.robot.thruster_forces, rotation.T @ force)[0]
        angle = rotation_vector(
            quaternion_multiply(reference.attitude, quaternion_conjugate(estimate.attitude))
        )
        torque = self.robot.inertia @ (
            rotation.T @ (0.25 * angle - 0.9 * estimate.angular_velocity)
        )
        return Command(
            thruster_on_times=np.clip(duty, 0.0, 1.0) * period,
            wheel_torques=-np.linalg.pinv(self.robot.wheel_axes) @ torque,
        )


def hardware_check():
    return next(c for c in checks_for("controller") if c.name == "flies_on_thrusters_and_wheels")


def test_the_conformance_suite_flies_a_controller_that_commands_the_hardware_itself():
    hardware_check().run(DirectHardware)


def test_the_conformance_suite_refuses_on_times_for_thrusters_the_robot_lacks():
    class TooFew(DirectHardware):
        def command(self, time, estimate, reference, surroundings) -> Command:
            return Command(thruster_on_times=np.zeros(5))

    with pytest.raises(ContractViolation, match="returned 5 thruster on-times for a robot with 12"):
        hardware_check().run(TooFew)
