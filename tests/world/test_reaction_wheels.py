"""Reaction wheels (``robot.actuators: {reaction_wheels: [...]}``): the scenario key, the
allocation of the commanded torque, saturation, and the angular momentum of base plus
wheels over a slew flown by the wheels alone."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from dcsim.errors import ScenarioError
from dcsim.missions import mission_class
from dcsim.run.recording import telemetry_columns
from dcsim.run.scripting import run
from dcsim.scenario.loader import dump_scenario, read_scenario
from dcsim.scenario.model import ActuatorsSpec, wheel_axes
from dcsim.world import World, WorldInputs
from dcsim.world.pybullet_client import pb

GOAL = [0.0, 0.0, 0.38268343236508984, 0.9238795325112867]  # 45° about +z


def wheel(axis, max_torque=0.05, max_momentum=2.0):
    return {"axis": axis, "inertia": 0.02, "max_torque": max_torque, "max_momentum": max_momentum}


PYRAMID = [wheel([1, 0, 0]), wheel([0, 1, 0]), wheel([0, 0, 1]), wheel([1, 1, 1])]
"""Three orthogonal wheels and a skewed fourth (its axis normalised by the world)."""


def scenario(wheels=PYRAMID, duration=600.0, **robot):
    """A hold mission turning the base by 98° with torque alone (no thrust)."""
    return {
        "name": "wheel slew",
        "world": {"frame": "geocentric", "duration": duration},
        "robot": {
            "actuators": {"reaction_wheels": wheels},
            "initial": {
                "attitude": [0.5, 0.5, 0.5, 0.5],
                "angular_velocity": [0.01, -0.005, 0.008],
            },
            **robot,
        },
        "mission": {"type": "hold", "attitude": GOAL, "hold_position": False},
    }


def problems(data):
    with pytest.raises(ScenarioError) as info:
        read_scenario(data)
    return [(p.path, p.message) for p in info.value.problems]


# ------------------------------------------------------------------ scenario
def test_the_default_is_ideal_and_records_no_wheel_columns():
    robot = read_scenario(None).robot
    assert robot.actuators == ActuatorsSpec() and robot.actuators.ideal
    assert robot.max_torque == 0.5
    default = read_scenario(None)
    mission = mission_class(default.mission.type).telemetry_columns(default)
    assert not [c for c in telemetry_columns(mission) if c.startswith("wheel")]


def test_wheels_fill_in_max_torque_and_survive_a_dump():
    loaded = read_scenario(scenario())
    # minimum-norm allocation: the skewed wheel takes a quarter of the load on the x axis
    # and the weakest direction is limited by the orthogonal wheels' rows of A⁺
    rows = np.linalg.norm(
        np.linalg.pinv(wheel_axes(loaded.robot.actuators.reaction_wheels)), axis=1
    )
    assert loaded.robot.max_torque == pytest.approx(0.05 / rows.max(), rel=1e-12)
    assert loaded.robot.max_torque > 0.05  # four wheels give more than one alone
    assert read_scenario(yaml.safe_load(dump_scenario(loaded))) == loaded


@pytest.mark.parametrize(
    ("wheels", "robot", "path", "words"),
    [
        (PYRAMID[:2], {}, "robot.actuators.reaction_wheels", "at least 3"),
        ([wheel([1, 0, 0]), wheel([0, 1, 0]), wheel([1, 1, 0])], {}, "robot.actuators.reaction_wheels",
         "span three dimensions"),
        ([wheel([0, 0, 0]), *PYRAMID[1:]], {}, "robot.actuators.reaction_wheels[0].axis", "not be zero"),
        ([*PYRAMID[:3], wheel([1, 1, 1], max_momentum=0)], {},
         "robot.actuators.reaction_wheels[3].max_momentum", "greater than 0"),
        (PYRAMID, {"max_torque": 1.0}, "robot.max_torque", "leave max_torque out"),
    ],
)  # fmt: skip
def test_invalid_wheels_are_named_by_their_key(wheels, robot, path, words):
    found = problems(scenario(wheels, **robot))
    assert len(found) == 1
    assert found[0][0] == path and words in found[0][1], found


def test_a_max_torque_below_the_wheels_limit_is_kept():
    assert read_scenario(scenario(max_torque=0.01)).robot.max_torque == 0.01


def test_the_old_actuator_type_key_says_where_the_wheels_went():
    data = scenario()
    data["robot"]["actuators"] = {"type": "reaction_wheels", "wheels": PYRAMID}
    [(path, message)] = problems(data)
    assert path == "robot.actuators" and "`reaction_wheels: [...]`" in message


# ------------------------------------------------------------------ allocation
def open_world(**robot):
    data = scenario(**robot)
    data["robot"]["initial"]["angular_velocity"] = [0.0, 0.0, 0.0]
    return World(read_scenario(data), np.random.default_rng(0))


def body_momentum(world):
    """The base's angular momentum, world frame, from PyBullet's inertia and state."""
    _, _, attitude, angular = world.base_state()
    rotation = np.reshape(pb.getMatrixFromQuaternion(attitude.tolist()), (3, 3))
    moments = pb.getDynamicsInfo(world.robot_id, -1, physicsClientId=world.client)[2]
    return (rotation * moments) @ rotation.T @ angular


def rotation_of(world):
    return np.reshape(pb.getMatrixFromQuaternion(world.base_state()[2].tolist()), (3, 3))


def test_a_torque_within_the_limit_is_delivered_exactly():
    with open_world() as world:
        limit = world.robot_spec().max_torque
        direction = np.array([0.3, -0.8, 0.5]) / np.linalg.norm([0.3, -0.8, 0.5])
        torque = 0.999 * limit * direction
        rotation = rotation_of(world)
        world.step(WorldInputs(torque=torque))
        delivered = world.outputs()["wheel_torque"]
        np.testing.assert_allclose(rotation @ delivered, torque, rtol=0, atol=1e-15)
        # the base turned by it: from rest, its momentum is the torque times the period
        expected = torque * world.control_period
        np.testing.assert_allclose(body_momentum(world), expected, rtol=1e-6)


def test_a_torque_beyond_the_limit_is_clipped_wheel_by_wheel():
    with open_world() as world:
        wheels = world.wheels
        assert wheels is not None
        rotation = rotation_of(world)
        torque = np.array([0.0, 0.0, 1.0])  # 20 times what the z wheel gives alone
        world.step(WorldInputs(torque=torque))
        delivered = world.outputs()["wheel_torque"]
        wanted = -np.linalg.pinv(wheels.axes) @ (rotation.T @ torque)
        expected = -wheels.axes @ np.clip(wanted, -0.05, 0.05)
        np.testing.assert_allclose(delivered, expected, rtol=0, atol=1e-15)
        assert np.linalg.norm(delivered) < 0.2 * np.linalg.norm(torque)
        # what the world reports is what the base received
        received = body_momentum(world) / world.control_period
        np.testing.assert_allclose(received, rotation @ delivered, rtol=1e-5)


def test_a_saturated_wheel_gives_no_more_torque_that_way_and_says_so_once():
    small = [*PYRAMID[:3], wheel([1, 1, 1], max_momentum=0.004)]
    with open_world(wheels=small) as world:
        wheels = world.wheels
        assert wheels is not None
        torque = rotation_of(world) @ (-np.array([1.0, 1.0, 1.0]) * 0.02)  # loads wheel 4
        for _ in range(20):  # 2 s: the fourth wheel fills in about 0.35 s
            world.step(WorldInputs(torque=torque))
        assert wheels.momentum[3] == 0.004 and wheels.torque[3] == 0.0
        assert world.actuators is not None
        saturations = [e for e in world.actuators.events if e.name == "wheel_saturated"]
        assert [e.data["wheel"] for e in saturations] == [4]
        assert saturations[0].data["momentum"] == 0.004
        # the other way it turns again and leaves the limit
        world.step(WorldInputs(torque=-torque))
        assert wheels.torque[3] < 0 and wheels.momentum[3] < 0.004
        assert wheels.peak_fraction == 1.0


def test_a_run_records_wheel_momenta_saturation_events_and_the_peak_fraction():
    small = [*PYRAMID[:3], wheel([1, 1, 1], max_momentum=0.05)]
    result = run(scenario(wheels=small, duration=30.0))
    columns = [c for c in result.telemetry.columns if c.startswith("wheel")]
    assert columns == [f"wheel_h_{i}_Nms" for i in range(1, 5)]
    saturated = [e for e in result.events if e["event"] == "wheel_saturated"]
    assert saturated and {e["wheel"] for e in saturated} == {4}
    assert abs(saturated[0]["momentum"]) == 0.05
    assert result.summary["peak_wheel_momentum_fraction"] == 1.0
    assert np.abs(result.telemetry["wheel_h_4_Nms"]).max() == 0.05


# ------------------------------------------------------------------ conservation
@pytest.mark.parametrize(
    ("inertia", "bound"),
    [
        (None, 1e-9),  # the 100 kg sphere's 40 kg m^2 about every axis: 1.7e-13 measured
        # unequal moments: PyBullet's explicit gyroscopic term drifts the base's own
        # momentum, wheels or not (first order in the step); 1.9e-3 measured
        ([8.0, 12.0, 15.0], 5e-3),
    ],
)
def test_base_plus_wheel_momentum_is_conserved_over_a_600_s_slew(inertia, bound):
    data = scenario(inertia=inertia)
    with World(read_scenario(data), np.random.default_rng(0)) as world:
        spec_inertia = world.robot_spec().inertia  # body axes, kg m^2
        assert world.wheels is not None
        axes = world.wheels.axes
    result = run(data)
    summary, telemetry = result.summary, result.telemetry
    assert summary["final_attitude_error_deg"] < 1e-6 and summary["fuel_used_kg"] == 0.0
    assert 0.2 < summary["peak_wheel_momentum_fraction"] < 1.0  # a real slew, unsaturated
    quaternions = telemetry[["qx", "qy", "qz", "qw"]].to_numpy()
    rates = telemetry[["wx_radps", "wy_radps", "wz_radps"]].to_numpy()
    momenta = telemetry[[f"wheel_h_{i}_Nms" for i in range(1, 5)]].to_numpy()
    rotations = np.array(
        [np.reshape(pb.getMatrixFromQuaternion(q.tolist()), (3, 3)) for q in quaternions]
    )
    base = np.einsum("nij,jk,nlk,nl->ni", rotations, spec_inertia, rotations, rates)
    carried = np.einsum("nij,jk,nk->ni", rotations, axes, momenta)
    total = base + carried
    assert np.linalg.norm(carried, axis=1).max() > 2 * np.linalg.norm(total[0])  # wheels took it
    drift = np.linalg.norm(total - total[0], axis=1).max() / np.linalg.norm(total[0])
    print(f"inertia {inertia}: relative drift of base plus wheel momentum {drift:.2g}")
    assert drift <= bound
