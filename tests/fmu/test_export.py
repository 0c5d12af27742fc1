"""The exported FMUs, run for real in fmpy: validity, equality with `dcsim run`, robustness."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.validation import validate_fmu

from dcsim.errors import ScenarioError
from dcsim.fmu.export import export_fmu
from dcsim.fmu.instance import FmuCallError, FmuError, FmuInstance
from dcsim.fmu.variables import (
    closed_loop_variables,
    hardware_inputs,
    hardware_outputs,
    plant_variables,
)
from dcsim.missions.debris import DebrisMission
from dcsim.run.loop import Runner
from dcsim.run.seeding import component_rng
from dcsim.run.setup import setup_run
from dcsim.scenario import read_scenario
from dcsim.scenario.model import point_to_cartesian
from dcsim.world import World, WorldInputs
from tests.conftest import SHARES_DEFAULT_RUN

PERIOD = 0.1  # s, the default scenario's control period
VECTORS = {"position": "x y z", "velocity": "vx vy vz", "attitude": "qx qy qz qw"}


def native(seed: int, duration: float) -> dict[str, np.ndarray]:
    """Telemetry of `dcsim run` on the default scenario, cut to ``duration`` seconds."""
    runner = Runner(setup_run(None, [f"world.duration={duration}"], seed))
    runner.run()
    return runner.recorder.telemetry()


@pytest.fixture(scope="module")
def native_run(default_run):
    """Telemetry of `dcsim run` on the default scenario."""
    runner, _, _ = default_run
    return runner.recorder.telemetry()


def fmu_row(fmu: FmuInstance) -> dict[str, float]:
    """The closed-loop FMU's outputs under the telemetry's column names."""
    values = fmu.get(fmu.description.names("output"))
    row = {}
    for name, columns in VECTORS.items():
        for axis, column in zip("xyzw", columns.split(), strict=False):
            row[column] = values[f"{name}.{axis}"]
    for key in ("delivered", "fuel_used", "delta_v", "localisation_error", "mode"):
        row[key] = values[key]
    return row


def telemetry_row(telemetry: dict[str, np.ndarray], i: int) -> dict[str, float]:
    row = {c: telemetry[c][i] for cols in VECTORS.values() for c in cols.split()}
    row.update({k: telemetry[k][i] for k in ("delivered", "fuel_used", "delta_v")})
    true = np.array([telemetry[c][i] for c in ("x", "y", "z")])
    estimate = np.array([telemetry[c][i] for c in ("est_x", "est_y", "est_z")])
    row["localisation_error"] = float(np.linalg.norm(true - estimate))
    row["mode"] = DebrisMission.modes.index(telemetry["mode"][i])
    return row


def assert_rows_equal(fmu_values: dict, expected: dict, where: str) -> None:
    """Equal to the bit: the FMU runs the very code `dcsim run` does."""
    for key, value in expected.items():
        assert fmu_values[key] == value, f"{key} at {where}"


def open_closed_loop(path, name="a", **start) -> FmuInstance:
    fmu = FmuInstance(path, name)
    fmu.initialise(start_values=start)
    return fmu


@dataclass
class Flight:
    """The closed-loop FMU flown over the default run's ticks, then 50 periods more."""

    rows: list[dict[str, float]]  # the outputs at each tick of the run
    status: dict[str, int]  # the run's status variables at its last tick
    after: dict[str, float]  # outputs 50 periods after the last tick


@pytest.fixture(scope="module")
def flight(closed_loop_fmu, native_run) -> Flight:
    """One flight shared by the tests of the run and of what comes after it."""
    fmu = open_closed_loop(closed_loop_fmu)
    ticks = len(native_run["time"])
    rows = [fmu_row(fmu)]
    for i in range(1, ticks):
        fmu.step((i - 1) * PERIOD, PERIOD)
        rows.append(fmu_row(fmu))
    status = fmu.get(["run_status", "delivered", "captured", "collisions"])
    for i in range(ticks - 1, ticks + 50):
        fmu.step(i * PERIOD, PERIOD)
    after = fmu.get(["run_status", "delta_v", "position.x", "velocity.x"])
    fmu.terminate()
    fmu.close()
    return Flight(rows, status, after)


# ----------------------------------------------------------------- validity


@pytest.mark.parametrize("variant", ["closed_loop_fmu", "plant_fmu"])
def test_fmpy_validation_finds_no_problems(variant, request):
    assert validate_fmu(str(request.getfixturevalue(variant))) == []


def test_variables_are_those_documented(closed_loop_fmu, plant_fmu):
    scenario = read_scenario()
    variants = (
        (closed_loop_fmu, closed_loop_variables(scenario)),
        (plant_fmu, plant_variables(scenario, 4)),
    )
    for path, table in variants:
        with FmuInstance(path) as fmu:
            described = {n: (v.causality, v.type) for n, v in fmu.description.variables.items()}
        types = {float: "Real", int: "Integer", bool: "Boolean"}
        assert described == {v.name: (v.causality, types[v.type]) for v in table}


def test_docs_list_the_variables():
    from dcsim.fmu import reference as r
    from dcsim.report.docgen import block

    text = (Path(__file__).resolve().parents[2] / "docs" / "fmu.md").read_text()
    for begin, end, table in r.generated_blocks():
        assert block(text, begin, end) == table, "docs/fmu.md is stale: run `make docs`"


def test_every_free_flyer_scenario_has_the_default_scenarios_variables():
    """A free flyer with thrusters or wheels has their variables besides
    (scenarios/default_hardware.yaml)."""

    def signature(variables, hardware):
        return [(v.name, v.causality, v.type) for v in variables if v.name not in hardware]

    default = read_scenario()
    expected = (
        signature(closed_loop_variables(default), ()),
        signature(plant_variables(default, 4), ()),
    )
    scenarios = sorted((Path(__file__).resolve().parents[2] / "scenarios").glob("*.yaml"))
    free_flyers = [s for s in map(read_scenario, scenarios) if s.robot.type == "free-flyer"]
    assert {s.mission.type for s in free_flyers} == {"debris", "transfer"}
    with_hardware = []
    for scenario in free_flyers:
        added = [*hardware_inputs(scenario), *hardware_outputs(scenario.robot)]
        hardware = {v.name for v in added} | ({"attitude_error"} if added else set())
        closed, plant = closed_loop_variables(scenario), plant_variables(scenario, 4)
        got = signature(closed, hardware), signature(plant, hardware)
        assert got == expected, scenario.name
        assert {v.name for v in [*closed, *plant]} >= hardware, scenario.name
        with_hardware += [scenario.name] if added else []
    assert "default_hardware" in with_hardware


@SHARES_DEFAULT_RUN
def test_simulate_fmu_runs_both_variants(closed_loop_fmu, plant_fmu, native_run):
    closed = simulate_fmu(str(closed_loop_fmu), stop_time=20.0, step_size=PERIOD)
    assert closed["time"][-1] == pytest.approx(20.0)
    assert closed["position.x"][-1] == native_run["x"][200]
    plant = simulate_fmu(
        str(plant_fmu), stop_time=10.0, step_size=PERIOD, start_values={"force.y": 2.0}
    )
    # 2 N on 100 kg for 10 s from rest: 0.2 m/s (a little more as propellant burns).
    assert plant["velocity.y"][-1] == pytest.approx(0.2, rel=2e-3)


# ----------------------------------------------------------------- equality with dcsim run


@SHARES_DEFAULT_RUN
def test_closed_loop_reproduces_dcsim_run_tick_by_tick(flight, native_run):
    for i, row in enumerate(flight.rows):
        assert_rows_equal(row, telemetry_row(native_run, i), f"row {i}")
    assert flight.status == {"run_status": 1, "delivered": 4, "captured": 4, "collisions": 0}


@SHARES_DEFAULT_RUN
def test_after_the_run_ends_the_world_coasts(flight, native_run):
    after = flight.after
    assert after["run_status"] == 1
    assert after["delta_v"] == pytest.approx(native_run["delta_v"][-1], abs=1e-12)  # no thrust
    assert after["position.x"] != native_run["x"][-1]  # but it drifts on


# ----------------------------------------------------------------- instances, reset, inputs


def test_two_instances_in_one_process_stay_independent(closed_loop_fmu):
    first, second = native(0, duration=30.0), native(1, duration=30.0)
    a, b = open_closed_loop(closed_loop_fmu, "a"), open_closed_loop(closed_loop_fmu, "b", seed=1)
    for i in range(1, 301):
        a.step((i - 1) * PERIOD, PERIOD)
        b.step((i - 1) * PERIOD, PERIOD)
    assert_rows_equal(fmu_row(a), telemetry_row(first, 300), "instance a")
    assert_rows_equal(fmu_row(b), telemetry_row(second, 300), "instance b")
    assert fmu_row(a)["localisation_error"] != fmu_row(b)["localisation_error"]
    a.close()
    b.close()


def test_terminate_reset_reinitialise_repeats_the_run(closed_loop_fmu):
    fmu = open_closed_loop(closed_loop_fmu)
    passes = []
    for _ in range(2):
        for i in range(100):
            fmu.step(i * PERIOD, PERIOD)
        passes.append(fmu_row(fmu))
        fmu.terminate()
        fmu.reset()
        fmu.initialise()
    assert passes[0] == passes[1]
    fmu.close()


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), -float("inf")])
def test_non_finite_input_gets_an_error_status_and_a_message(closed_loop_fmu, bad):
    fmu = open_closed_loop(closed_loop_fmu)
    fmu.step(0.0, PERIOD)
    before = fmu_row(fmu)
    fmu.set({"disturbance_force.y": bad})
    with pytest.raises(FmuCallError) as refused:
        fmu.step(PERIOD, PERIOD)
    assert refused.value.status == 2  # fmi2Discard: the step was not taken
    assert ("ERROR", f"input disturbance_force.y = {bad} refused: inputs must be finite") in (
        fmu.messages
    )
    assert fmu_row(fmu) == before
    fmu.set({"disturbance_force.y": 0.0})
    fmu.step(PERIOD, PERIOD)
    assert fmu_row(fmu) != before
    fmu.close()


@SHARES_DEFAULT_RUN
def test_step_not_a_multiple_of_the_period_holds_the_last_boundary(closed_loop_fmu, native_run):
    fmu = open_closed_loop(closed_loop_fmu)
    for k in range(1, 9):  # communication points 0.25, 0.5, ... 2.0 s
        fmu.step((k - 1) * 0.25, 0.25)
        boundary = int(np.floor(k * 0.25 / PERIOD + 1e-6))
        assert_rows_equal(fmu_row(fmu), telemetry_row(native_run, boundary), f"t={k * 0.25}")
    warnings = [m for status, m in fmu.messages if status == "WARNING"]
    assert len(warnings) == 1 and "not a multiple of the control period" in warnings[0]
    fmu.close()


def test_a_bad_parameter_is_logged_and_every_step_refused(closed_loop_fmu):
    fmu = FmuInstance(closed_loop_fmu)
    fmu.initialise(start_values={"robot.mass": -5.0})
    errors = [m for status, m in fmu.messages if status == "ERROR"]
    assert len(errors) == 1 and errors[0].startswith("cannot start") and "robot.mass" in errors[0]
    for _ in range(2):
        with pytest.raises(FmuCallError) as refused:
            fmu.step(0.0, PERIOD)
        assert refused.value.status == 2
    fmu.terminate()
    fmu.close()


# ----------------------------------------------------------------- plant only


def test_plant_parameters_reach_the_world(plant_fmu):
    speeds = []
    for mass in (100.0, 200.0):
        with FmuInstance(plant_fmu) as fmu:
            fmu.initialise(start_values={"robot.mass": mass, "force.x": 1.0})
            for i in range(100):
                fmu.step(i * PERIOD, PERIOD)
            speeds.append(fmu.get(["velocity.x"])["velocity.x"])
            assert fmu.get(["mass"])["mass"] < mass  # propellant burnt
    assert speeds[0] / speeds[1] == pytest.approx(2.0, rel=1e-3)


def test_plant_state_is_the_worlds_and_beacons_are_nearest_first(plant_fmu):
    scenario = read_scenario()
    world = World(scenario, component_rng(scenario.world.seed, "world"))
    force = np.array([0.5, -1.0, 0.3])
    with FmuInstance(plant_fmu) as fmu:
        fmu.initialise(start_values={f"force.{a}": f for a, f in zip("xyz", force, strict=True)})
        for i in range(200):
            fmu.step(i * PERIOD, PERIOD)
            world.step(WorldInputs(force=force))
        out = fmu.get(fmu.description.names("output"))
    truth = world.outputs()
    for axis, value in zip("xyz", truth["position"], strict=True):
        assert out[f"position.{axis}"] == value
    ids = [out[f"beacon[{k}].id"] for k in range(1, 5)]
    ranges = [out[f"beacon[{k}].range"] for k in range(1, 5)]
    assert sorted(ids) == [0, 1, 2, 3] and ranges == sorted(ranges)
    beacons = np.array([point_to_cartesian(p) for p in scenario.beacons.positions])
    true_ranges = np.linalg.norm(beacons[ids] - truth["position"], axis=1)
    assert np.allclose(ranges, true_ranges, atol=5 * scenario.beacons.noise_sigma)
    assert out["nearest_obstacle"] == pytest.approx(truth["nearest_obstacle_distance"], abs=1e-6)
    world.close()


def test_plant_collision_flag_marks_the_step_a_contact_starts(plant_fmu):
    scenario = read_scenario()
    obstacle = point_to_cartesian(scenario.obstacles[0].motion.position)  # id 10, at rest
    push = 5.0 * obstacle / np.linalg.norm(obstacle)
    flags, counts = [], []
    with FmuInstance(plant_fmu) as fmu:
        fmu.initialise(start_values={f"force.{a}": f for a, f in zip("xyz", push, strict=True)})
        for i in range(600):
            fmu.step(i * PERIOD, PERIOD)
            got = fmu.get(["collision", "collisions"])
            flags.append(got["collision"])
            counts.append(got["collisions"])
    assert counts[-1] >= 1
    started = [i for i in range(1, 600) if counts[i] > counts[i - 1]]
    assert [i for i, flag in enumerate(flags) if flag] == started


# ----------------------------------------------------------------- export errors


def test_export_refuses_a_bad_scenario_or_file_name(tmp_path):
    with pytest.raises(ScenarioError):
        export_fmu(None, tmp_path / "x.fmu", overrides=["robot.mass=-1"])
    with pytest.raises(FmuError, match=r"\.fmu"):
        export_fmu(None, tmp_path / "x.zip")
    assert not list(tmp_path.iterdir())


def test_an_fmu_that_cannot_start_is_reported_with_its_reason(closed_loop_fmu, tmp_path):
    import zipfile

    broken = tmp_path / "broken.fmu"
    with zipfile.ZipFile(closed_loop_fmu) as source, zipfile.ZipFile(broken, "w") as target:
        for item in source.infolist():
            data = source.read(item)
            if item.filename == "resources/scenario.yaml":
                data = b"world: [unclosed"
            target.writestr(item, data)
    with pytest.raises(FmuError, match="(?s)cannot be instantiated: .*not valid YAML"):
        FmuInstance(broken)


def _slave_of_default_scenario(tmp_path):
    """The closed-loop slave itself, in this process, on the default scenario."""
    from dcsim.fmu.slaves import SCENARIO_RESOURCE, ClosedLoopSlave
    from dcsim.registry.discovery import PluginRegistry
    from dcsim.scenario import dump_scenario

    resolved = read_scenario(None, registry=PluginRegistry.discover())
    (tmp_path / SCENARIO_RESOURCE).write_text(dump_scenario(resolved))
    return ClosedLoopSlave(instance_name="test", resources=str(tmp_path))


@pytest.mark.parametrize("fails_at", [0.0, 1.0])
def test_a_failing_plugin_is_logged_and_refuses_steps_without_raising(
    tmp_path, monkeypatch, fails_at
):
    from dcsim_plugins.controllers.pd import PDController

    original = PDController.command

    def command(self, time, *args):
        if time >= fails_at:
            raise RuntimeError("controller broke")
        return original(self, time, *args)

    monkeypatch.setattr(PDController, "command", command)
    slave = _slave_of_default_scenario(tmp_path)
    slave.setup_experiment(0.0, None, None)
    slave.exit_initialization_mode()
    steps = [slave.do_step(k * PERIOD, PERIOD) for k in range(15)]
    first_refused = max(round(fails_at / PERIOD) - 1, 0)  # step k ends at (k + 1) PERIOD
    assert steps == [True] * first_refused + [False] * (15 - first_refused)
    messages = [log.msg for log in slave.log_queue]
    assert any("run failed" in m and "controller broke" in m for m in messages)
    assert slave.values["run_status"] == 3
    slave.terminate()
