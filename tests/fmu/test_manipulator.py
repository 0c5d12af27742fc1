"""A manipulator's FMUs (the reach scenario) in fmpy: joints, end effector, joint torques."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from fmpy.validation import validate_fmu

from dcsim.fmu.export import export_fmu
from dcsim.fmu.instance import FmuCallError, FmuInstance
from dcsim.fmu.variables import (
    JOINT_ANGLE,
    JOINT_RATE,
    JOINT_TORQUE,
    closed_loop_variables,
    plant_variables,
)
from dcsim.missions.reach import ReachMission
from dcsim.run.loop import Runner
from dcsim.run.seeding import component_rng
from dcsim.run.setup import setup_run
from dcsim.scenario import read_scenario
from dcsim.world import World, WorldInputs

REACH = Path(__file__).resolve().parents[2] / "scenarios" / "space_manipulator_reach.yaml"
SHORT = ["world.duration=0.3"]  # 30 control periods of the reach
PERIOD = 0.01  # s, the reach scenario's control period
JOINTS = 6
TYPES = {float: "Real", int: "Integer", bool: "Boolean"}


@pytest.fixture(scope="module")
def reach_closed_loop_fmu(tmp_path_factory) -> Path:
    """The reach scenario, cut to 0.3 s, as a closed-loop FMU."""
    return export_fmu(REACH, tmp_path_factory.mktemp("reach") / "closed.fmu", overrides=SHORT)


@pytest.fixture(scope="module")
def reach_plant_fmu(tmp_path_factory) -> Path:
    """The reach scenario's world as a plant-only FMU (K = 4 beacons)."""
    return export_fmu(REACH, tmp_path_factory.mktemp("reach") / "plant.fmu", plant_only=True)


def test_both_variants_are_valid_and_declare_the_scenarios_arm(
    reach_closed_loop_fmu, reach_plant_fmu
):
    scenario = read_scenario(REACH, SHORT)
    variants = (
        (reach_closed_loop_fmu, closed_loop_variables(scenario)),
        (reach_plant_fmu, plant_variables(scenario, 4)),
    )
    for path, table in variants:
        assert validate_fmu(str(path)) == []
        with FmuInstance(path) as fmu:
            described = {n: (v.causality, v.type) for n, v in fmu.description.variables.items()}
        assert described == {v.name: (v.causality, TYPES[v.type]) for v in table}
        for i in range(1, JOINTS + 1):
            assert described[JOINT_ANGLE.format(i)] == ("output", "Real")
            assert described[JOINT_RATE.format(i)] == ("output", "Real")
        assert "end_effector.z" in described and "captured" not in described
    inputs = [v.name for v in variants[1][1] if v.causality == "input"]
    assert inputs[6:] == [JOINT_TORQUE.format(i) for i in range(1, JOINTS + 1)]


def test_closed_loop_reproduces_dcsim_run_tick_by_tick(reach_closed_loop_fmu):
    runner = Runner(setup_run(REACH, SHORT))
    runner.run()
    telemetry = runner.recorder.telemetry()
    columns = {
        **{column: f"position.{column}" for column in "xyz"},
        **{f"q{axis}": f"attitude.{axis}" for axis in "xyzw"},
        **{f"ee_{axis}": f"end_effector.{axis}" for axis in "xyz"},
        **{f"joint_{i}": JOINT_ANGLE.format(i) for i in range(1, JOINTS + 1)},
        "fuel_used": "fuel_used",
        "delta_v": "delta_v",
    }
    fmu = FmuInstance(reach_closed_loop_fmu)
    fmu.initialise()
    for tick in range(len(telemetry["time"])):
        if tick:
            fmu.step((tick - 1) * PERIOD, PERIOD)
        out = fmu.get([*columns.values(), "mode", "localisation_error"])
        for column, name in columns.items():
            assert out[name] == telemetry[column][tick], f"{name} at tick {tick}"
        assert out["mode"] == ReachMission.modes.index(telemetry["mode"][tick])
        assert out["localisation_error"] == 0.0  # no localiser: the mission sees the truth
    assert tick == 30 and fmu.get(["run_status"]) == {"run_status": 1}
    fmu.terminate()
    fmu.close()


def _world_joints(torques: np.ndarray, periods: int) -> World:
    """The reach scenario's world driven directly by joint torques over ``periods``."""
    scenario = read_scenario(REACH)
    world = World(scenario, component_rng(scenario.world.seed, "world"))
    for _ in range(periods):
        world.step(WorldInputs(joint_torques=torques))
    return world


def test_plant_joint_torque_turns_the_joint_and_the_base_reacts(reach_plant_fmu):
    torque = 150.0  # N·m on joint 2, beyond its 100 N·m limit
    periods = 10
    with FmuInstance(reach_plant_fmu) as fmu:
        fmu.initialise(start_values={JOINT_TORQUE.format(2): torque})
        start = fmu.get([JOINT_ANGLE.format(2)])[JOINT_ANGLE.format(2)]
        for k in range(periods):
            fmu.step(k * PERIOD, PERIOD)
        out = fmu.get(fmu.description.names("output"))
    angles = np.array([out[JOINT_ANGLE.format(i)] for i in range(1, JOINTS + 1)])
    rates = np.array([out[JOINT_RATE.format(i)] for i in range(1, JOINTS + 1)])
    assert angles[1] > start and rates[1] > 0  # the joint turns the torque's way

    applied = np.zeros(JOINTS)
    applied[1] = torque
    world = _world_joints(applied, periods)
    state = world.robot_state()
    assert np.array_equal(angles, state.joint_positions)  # the world's own path, to the bit
    assert np.array_equal(rates, state.joint_velocities)
    assert [out[f"position.{a}"] for a in "xyz"] == state.position.tolist()
    limited = _world_joints(np.minimum(applied, 100.0), periods)  # clipped to the limit
    assert np.array_equal(angles, limited.robot_state().joint_positions)

    # The base reacts: it turns against joint 2 and moves, the total momentum stays ~0.
    model = world.robot_spec().model
    axis = model.forward_kinematics(state.configuration).joint_axes[1]
    assert state.angular_velocity @ axis < 0
    base_momentum = world.robot.mass * np.linalg.norm(state.velocity)
    assert base_momentum > 1.0  # kg·m/s
    momentum = model.momentum(state.configuration, state.generalised_velocity)
    assert np.linalg.norm(momentum[:3]) < 0.01 * base_momentum
    world.close()
    limited.close()


@pytest.mark.parametrize("bad", [float("nan"), float("inf")])
def test_a_non_finite_joint_torque_is_refused(reach_plant_fmu, bad):
    name = JOINT_TORQUE.format(3)
    with FmuInstance(reach_plant_fmu) as fmu:
        fmu.initialise()
        fmu.set({name: bad})
        with pytest.raises(FmuCallError) as refused:
            fmu.step(0.0, PERIOD)
        assert refused.value.status == 2  # fmi2Discard: the step was not taken
        assert ("ERROR", f"input {name} = {bad} refused: inputs must be finite") in fmu.messages
