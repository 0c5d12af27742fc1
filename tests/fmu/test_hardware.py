"""A free flyer's thrusters and reaction wheels in its FMUs (scenarios/default_hardware.yaml)
run for real in fmpy: the variables and their units, on-times and wheel torques given
per actuator flown as a World flies them, and the closed loop's hardware outputs equal
to the telemetry of `dcsim run`."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from fmpy.validation import validate_fmu

from dcsim.fmu.export import export_fmu
from dcsim.fmu.instance import FmuInstance
from dcsim.fmu.variables import (
    THRUSTER_DUTY,
    THRUSTER_ON_TIME,
    WHEEL_MOMENTUM,
    WHEEL_TORQUE,
    closed_loop_variables,
    plant_variables,
)
from dcsim.run.loop import Runner
from dcsim.run.seeding import component_rng
from dcsim.run.setup import setup_run
from dcsim.scenario import read_scenario
from dcsim.world import World, WorldInputs
from tests.conftest import REPO
from tests.world.test_thrusters import momenta

HARDWARE = REPO / "scenarios" / "default_hardware.yaml"
# Eight seconds of the mission starting with a spin the wheels take out: their momenta
# and the attitude error are far from zero from the first second on.
SPIN = ["world.duration=8", "robot.initial.angular_velocity=[0.01, -0.02, 0.03]"]
PERIOD = 0.1  # s, the scenario's control period
THRUSTERS, WHEELS = 12, 4
TYPES = {float: "Real", int: "Integer", bool: "Boolean"}


@pytest.fixture(scope="module")
def hardware_plant_fmu(tmp_path_factory) -> Path:
    """The hardware scenario's world as a plant FMU."""
    folder = tmp_path_factory.mktemp("hardware")
    return export_fmu(HARDWARE, folder / "plant.fmu", plant_only=True)


@pytest.fixture(scope="module")
def hardware_closed_loop_fmu(tmp_path_factory) -> Path:
    """The hardware scenario, spinning at the start and cut to 8 s, as a closed-loop FMU."""
    folder = tmp_path_factory.mktemp("hardware")
    return export_fmu(HARDWARE, folder / "closed.fmu", overrides=SPIN)


def indexed(name: str, count: int) -> list[str]:
    return [name.format(i) for i in range(1, count + 1)]


def vector(values: dict, name: str) -> np.ndarray:
    return np.array([values[f"{name}.{axis}"] for axis in "xyz"])


def open_world() -> World:
    scenario = read_scenario(HARDWARE)
    return World(scenario, component_rng(scenario.world.seed, "world"))


def fly_plant(path: Path, start: dict, periods: int = 1) -> tuple[dict, list]:
    """The plant's outputs after ``periods`` control periods from ``start``, and its log."""
    with FmuInstance(path) as fmu:
        fmu.initialise(start_values=start)
        for k in range(periods):
            fmu.step(k * PERIOD, PERIOD)
        return fmu.get(fmu.description.names("output")), fmu.messages


def assert_flies_as_the_world(out: dict, world: World) -> None:
    """The plant's state and hardware outputs are the World's, to the bit."""
    truth = world.outputs()
    for name in ("position", "velocity", "angular_velocity"):
        assert vector(out, name).tolist() == truth[name].tolist(), name
    assert [out[n] for n in indexed(WHEEL_MOMENTUM, WHEELS)] == truth["wheel_momentum"].tolist()
    assert [out[n] for n in indexed(THRUSTER_DUTY, THRUSTERS)] == truth["thruster_duty"].tolist()
    assert out["attitude_fuel_used"] == world.attitude_fuel_used
    assert out["fuel_used"] == truth["fuel_used"]


# ----------------------------------------------------------------- variables


def test_both_variants_declare_the_hardware_with_units(
    hardware_plant_fmu, hardware_closed_loop_fmu
):
    thrusters = {n: ("output", "Real", "") for n in indexed(THRUSTER_DUTY, THRUSTERS)}
    wheels = {n: ("output", "Real", "N.m.s") for n in indexed(WHEEL_MOMENTUM, WHEELS)}
    both = {**thrusters, **wheels, "attitude_fuel_used": ("output", "Real", "kg")}
    plant = {
        **both,
        **{n: ("input", "Real", "s") for n in indexed(THRUSTER_ON_TIME, THRUSTERS)},
        **{n: ("input", "Real", "N.m") for n in indexed(WHEEL_TORQUE, WHEELS)},
        "thrusters_direct": ("input", "Boolean", ""),
        "wheels_direct": ("input", "Boolean", ""),
    }
    closed = {**both, "attitude_error": ("output", "Real", "rad")}
    scenario = read_scenario(HARDWARE, SPIN)
    variants = (
        (hardware_plant_fmu, plant, plant_variables(scenario, 4)),
        (hardware_closed_loop_fmu, closed, closed_loop_variables(scenario)),
    )
    for path, expected, table in variants:
        assert validate_fmu(str(path)) == []
        with FmuInstance(path) as fmu:
            described = fmu.description.variables
        assert {n: (v.causality, v.type) for n, v in described.items()} == {
            v.name: (v.causality, TYPES[v.type]) for v in table
        }
        for name, (causality, kind, unit) in expected.items():
            variable = described[name]
            assert (variable.causality, variable.type) == (causality, kind), name
            assert variable.description.endswith(f"[{unit}]") == bool(unit), name


# ----------------------------------------------------------------- plant


def test_direct_on_times_change_the_momentum_as_in_the_world(hardware_plant_fmu):
    """Two periods: one firing three couples (force, no torque), then one couple giving
    torque about the principal z axis alone (no force); the attitude turns about z only,
    so the momenta follow from the layout without gyroscopic terms."""
    pushes = np.zeros(THRUSTERS)
    pushes[[0, 1, 4, 5, 10, 11]] = [0.05, 0.05, 0.032, 0.032, 0.007, 0.007]  # +x, +y, -z
    flown = np.where(pushes == 0.007, 0.01, pushes)  # 7 ms: below the 10 ms bit, above half
    turn = np.zeros(THRUSTERS)
    turn[[0, 3]] = 0.024  # +x at y = +0.4 and -x at y = -0.4: torque along -z
    outputs, momentum = [], []
    with FmuInstance(hardware_plant_fmu) as fmu, open_world() as world:
        # the wheels given no torque: the base keeps the whole of the thrusters' torque
        fmu.initialise(start_values={"thrusters_direct": True, "wheels_direct": True})
        momentum.append(momenta(world))
        for k, on_times in enumerate((pushes, turn)):
            fmu.set(dict(zip(indexed(THRUSTER_ON_TIME, THRUSTERS), on_times.tolist(), strict=True)))
            fmu.step(k * PERIOD, PERIOD)
            world.step(WorldInputs(thruster_on_times=on_times, wheel_torques=np.zeros(WHEELS)))
            outputs.append(fmu.get(fmu.description.names("output")))
            assert_flies_as_the_world(outputs[-1], world)
            momentum.append(momenta(world))
        scenario, physics_step = world.scenario, world.physics_step
    (linear0, angular0), (linear1, angular1), (_, angular2) = momentum
    # Independently, from the scenario's layout (body frame = LVLH at the start)
    layout = scenario.robot.actuators.thrusters
    directions = np.array([t.direction for t in layout], dtype=float)
    thrust = np.array([t.max_thrust for t in layout])[:, None] * directions
    thrust /= np.linalg.norm(directions, axis=1, keepdims=True)
    impulse = flown @ thrust
    # Coriolis force 2 n m (v_y, -v_x, 0), the velocity growing while each thruster fires
    n, swept = scenario.mean_motion, (flown * PERIOD - flown**2 / 2) @ thrust
    coriolis = 2 * n * np.array([swept[1], -swept[0], 0.0])
    # the world samples the velocity at each physics step's start: off by up to |Δv| dt
    tolerance = 2 * n * np.linalg.norm(impulse) * physics_step
    assert np.linalg.norm(linear1 - linear0 - impulse - coriolis) <= tolerance
    assert not np.any(angular1 - angular0)
    moment = np.cross([t.position for t in layout], turn[:, None] * thrust).sum(axis=0)
    assert angular2 - angular1 == pytest.approx(moment, abs=1e-6)  # 0.048 N·m·s
    for out, on_times in zip(outputs, (flown, turn), strict=True):
        duty = [out[name] for name in indexed(THRUSTER_DUTY, THRUSTERS)]
        assert duty == pytest.approx(on_times / PERIOD, abs=1e-12)
        assert not any(out[name] for name in indexed(WHEEL_MOMENTUM, WHEELS))


def test_direct_wheel_torques_drive_the_wheels_as_in_the_world(hardware_plant_fmu):
    torques = np.array([0.1, -0.05, 0.3, 0.0])  # N·m; the third beyond its 0.2 N·m
    given = dict(zip(indexed(WHEEL_TORQUE, WHEELS), torques.tolist(), strict=True))
    out, _ = fly_plant(hardware_plant_fmu, {"wheels_direct": True, **given})
    with open_world() as world:
        _, angular0 = momenta(world)
        world.step(WorldInputs(wheel_torques=torques))
        _, angular1 = momenta(world)
        assert_flies_as_the_world(out, world)
    flown = np.clip(torques, -0.2, 0.2) * PERIOD
    assert [out[n] for n in indexed(WHEEL_MOMENTUM, WHEELS)] == pytest.approx(flown, abs=1e-12)
    axes = np.array([w.axis for w in world.scenario.robot.actuators.reaction_wheels], dtype=float)
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    # the reaction; the base turns by 2e-4 rad: gyroscopic terms stay below 1e-6 N·m·s
    assert angular1 - angular0 == pytest.approx(-axes.T @ flown, abs=1e-6)
    assert not any(out[n] for n in indexed(THRUSTER_DUTY, THRUSTERS))


def test_on_times_are_unused_until_thrusters_direct_and_a_warning_says_so(hardware_plant_fmu):
    force = np.array([1.0, -0.5, 0.25])
    with FmuInstance(hardware_plant_fmu) as fmu:
        fmu.initialise(start_values={"force.x": 1.0, "force.y": -0.5, "force.z": 0.25})
        fmu.set({THRUSTER_ON_TIME.format(1): 0.08})
        for k in range(2):
            fmu.step(k * PERIOD, PERIOD)
        allocated = fmu.get(fmu.description.names("output"))
        fmu.set({"thrusters_direct": True})
        fmu.step(2 * PERIOD, PERIOD)
        direct = fmu.get(indexed(THRUSTER_DUTY, THRUSTERS))
        messages = fmu.messages
    with open_world() as world:
        for _ in range(2):
            world.step(WorldInputs(force=force))
        assert_flies_as_the_world(allocated, world)
    warnings = [m for status, m in messages if status == "WARNING"]
    assert warnings == [
        "thruster_on_time[i] inputs are not used while thrusters_direct is false: "
        "set thrusters_direct to true to fly them"
    ]
    assert list(direct.values()) == pytest.approx([0.8] + [0.0] * (THRUSTERS - 1), abs=1e-12)


# ----------------------------------------------------------------- closed loop


def test_closed_loop_hardware_outputs_equal_the_telemetry(hardware_closed_loop_fmu):
    runner = Runner(setup_run(HARDWARE, SPIN, 0))
    summary = runner.run()
    telemetry = runner.recorder.telemetry()
    columns = {
        **dict(zip(indexed(WHEEL_MOMENTUM, WHEELS), indexed("wheel_h_{}", WHEELS), strict=True)),
        **dict(zip(indexed(THRUSTER_DUTY, THRUSTERS), indexed("duty_{}", THRUSTERS), strict=True)),
        "attitude_error": "attitude_error",
    }
    fmu = FmuInstance(hardware_closed_loop_fmu)
    fmu.initialise()
    ticks = len(telemetry["time"])
    for i in range(ticks):
        if i:
            fmu.step((i - 1) * PERIOD, PERIOD)
        got = fmu.get(columns)
        assert got == {name: telemetry[column][i] for name, column in columns.items()}, i
    assert fmu.get(["attitude_fuel_used"])["attitude_fuel_used"] == summary["fuel_attitude_kg"]
    fmu.terminate()
    fmu.close()
    momentum = np.abs([telemetry[f"wheel_h_{j}"] for j in range(1, WHEELS + 1)])
    assert momentum.max() > 0.1 and telemetry["attitude_error"].max() > 0.01  # not trivial
