"""Runs end to end: the mission state machine, outputs, determinism, failures, hooks."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import textwrap
import time
import types
from functools import cached_property

import numpy as np
import pytest
from dcsim_plugins.localisers.trilateration import TrilaterationLocaliser

from dcsim.api import (
    Command,
    Controller,
    PluginParams,
    PluginRegistry,
    StateEstimate,
    hookimpl,
    message,
    quantity,
)
from dcsim.geometry import quaternion_conjugate, quaternion_multiply, rotation_vector
from dcsim.registry.discovery import PluginOrigin
from dcsim.run.loop import Runner
from dcsim.run.recording import SIGMA_COLUMNS
from dcsim.run.setup import setup_run
from tests.conftest import DCSIM, REPO, SHARES_DEFAULT_RUN

TEST_ORIGIN = PluginOrigin("tests", "0", "tests")

# Mode changes the thesis's executer allows (§2.2.1, §5.2), plus replanning.
ALLOWED = {
    ("LOCALIZE", "DEVISE_PLAN"),
    ("LOCALIZE", "IDLE"),
    ("IDLE", "DEVISE_PLAN"),
    ("DEVISE_PLAN", "SELECT_NEXT"),
    ("DEVISE_PLAN", "IDLE"),
    ("SELECT_NEXT", "MOVE_TO_NEXT"),
    ("SELECT_NEXT", "MOVE_TO_DROP"),
    ("SELECT_NEXT", "LOCALIZE"),
    ("SELECT_NEXT", "IDLE"),
    ("MOVE_TO_NEXT", "GRAB"),
    ("MOVE_TO_NEXT", "MOVE_TO_DROP"),
    ("MOVE_TO_NEXT", "DEVISE_PLAN"),
    ("GRAB", "SELECT_NEXT"),
    ("GRAB", "MOVE_TO_DROP"),
    ("GRAB", "DEVISE_PLAN"),
    ("MOVE_TO_DROP", "SELECT_NEXT"),
    ("MOVE_TO_DROP", "LOCALIZE"),
    ("MOVE_TO_DROP", "IDLE"),
}


class BiasedLocaliser(TrilaterationLocaliser):
    """Believes it is 0.8 m further along -x than it is."""

    name = "biased"
    summary = "Trilateration with a constant bias (test)"

    def estimate(self):
        estimate = super().estimate()
        return type(estimate)(**{**estimate.__dict__, "position": estimate.position - [0.8, 0, 0]})


@message
class SpreadEstimate(StateEstimate):
    """An estimate with a derived quantity cached on first use (in its ``__dict__``)."""

    @cached_property
    def spread(self) -> float:
        return float(np.trace(self.covariance))


class SpreadLocaliser(TrilaterationLocaliser):
    """Trilateration whose estimates are :class:`SpreadEstimate`, their spread read."""

    name = "spread"
    summary = "Trilateration with its own estimate class (test)"

    def estimate(self):
        estimate = SpreadEstimate(**super().estimate().__dict__)
        assert estimate.spread >= 0  # cached now
        return estimate


class ExplodingParams(PluginParams):
    after: float = quantity(2.0, unit="s", ge=0, description="When to raise.")


class ExplodingController(Controller):
    name = "explodes"
    summary = "Raises after a while (test)"
    Params = ExplodingParams

    def reset(self, robot):
        pass

    def command(self, time, estimate, reference, surroundings):
        if time >= self.params.after:
            raise RuntimeError("boom")
        return Command()


def registry_with(*classes: type) -> PluginRegistry:
    registry = PluginRegistry.discover()
    for cls in classes:
        registry.register_class(cls, TEST_ORIGIN)
    return registry


def scenario_file(tmp_path, text: str):
    path = tmp_path / "scenario.yaml"
    path.write_text(textwrap.dedent(text))
    return path


def run(path=None, overrides=(), out=None, registry=None, seed=None):
    setup = setup_run(path, overrides, seed, registry=registry or PluginRegistry.discover())
    runner = Runner(setup, out)
    return runner, runner.run()


def modes(events):
    return [(e["previous"], e["mode"]) for e in events if e["event"] == "mode"]


@SHARES_DEFAULT_RUN
def test_default_run_delivers_every_target_without_collision(default_run):
    _, summary, out = default_run
    assert summary["status"] == "completed" and summary["reason"] == "all targets delivered"
    assert summary["delivered"] == summary["targets"] == 4
    assert summary["collisions"] == 0
    assert summary["min_obstacle_distance_m"] > 0
    assert summary["localisation_rmse_m"] < 0.1
    assert 0 < summary["fuel_used_kg"] < 10 and summary["delta_v_mps"] > 0
    assert json.loads((out / "summary.json").read_text()) == json.loads(json.dumps(summary))
    assert (out / "plots" / "trajectory.png").stat().st_size > 10_000
    assert (out / "plots" / "timeline.png").stat().st_size > 10_000


@SHARES_DEFAULT_RUN
def test_default_run_follows_the_executer_state_machine(default_run):
    runner, _, _ = default_run
    events = runner.recorder.events
    transitions = modes(events)
    assert transitions[0] == ("LOCALIZE", "DEVISE_PLAN")
    assert set(transitions) <= ALLOWED, set(transitions) - ALLOWED
    grabs = [e for e in events if e["event"] == "grab"]
    assert len(grabs) == 4 and all(g["success"] for g in grabs)
    releases = [e["delivered"] for e in events if e["event"] == "release"]
    assert sorted(sum(releases, [])) == [1, 2, 3, 4]
    assert all(len(r) <= 2 for r in releases)  # capacity 2
    telemetry = runner.recorder.telemetry()
    assert telemetry["carried"].max() == 2
    assert np.all(np.diff(telemetry["delivered"]) >= 0)
    # Every plan's pickups are viable: strictly increasing times after the plan was made.
    for plan in (e for e in events if e["event"] == "plan"):
        times = [t for _, t in plan["tasks"]]
        assert all(t > plan["t"] for t in times) and np.all(np.diff(times) > 0)


@SHARES_DEFAULT_RUN
def test_after_the_last_delivery_the_mode_reads_idle(default_run):
    runner, _, _ = default_run
    events = runner.recorder.events
    last_release = [e for e in events if e["event"] == "release"][-1]
    last_mode = [e for e in events if e["event"] == "mode"][-1]
    assert (last_mode["t"], last_mode["previous"], last_mode["mode"]) == (
        last_release["t"],
        "MOVE_TO_DROP",
        "IDLE",
    )
    telemetry = runner.recorder.telemetry()
    assert telemetry["mode"][-1] == "IDLE" and telemetry["mode"][-2] == "MOVE_TO_DROP"


@SHARES_DEFAULT_RUN
def test_telemetry_records_the_world_frame_angular_rate_and_the_estimates_sigma(default_run):
    runner, _, _ = default_run
    telemetry = runner.recorder.telemetry()
    rate = np.column_stack([telemetry[c] for c in ("wx", "wy", "wz")])
    attitude = np.column_stack([telemetry[c] for c in ("qx", "qy", "qz", "qw")])
    # rad/s: grabs turn the collector, the attitude loop brings it back (below 0.5 deg/s)
    assert 1e-3 < np.abs(rate).max() < np.radians(0.5)
    # q(t + dt) = exp(ω dt) ⊗ q(t) with ω in the world frame, rad/s.
    turned = rotation_vector(quaternion_multiply(attitude[1:], quaternion_conjugate(attitude[:-1])))
    observed = turned / np.diff(telemetry["time"])[:, None]
    mismatch = np.linalg.norm(observed - 0.5 * (rate[1:] + rate[:-1]), axis=1)
    assert np.percentile(mismatch, 99) < 1e-3
    sigma = np.column_stack([telemetry[c] for c in SIGMA_COLUMNS])
    error = np.column_stack([telemetry[f"est_{a}"] - telemetry[a] for a in "xyz"])
    assert np.all(sigma > 0) and np.all(sigma < 0.1)  # m
    assert np.mean(np.abs(error) <= 3 * sigma) > 0.98  # a standard deviation, not a variance


@SHARES_DEFAULT_RUN
def test_every_delivery_is_flown_on_a_planned_path_timed_by_the_plan(default_run):
    _, _, out = default_run
    events = [json.loads(line) for line in (out / "events.jsonl").read_text().splitlines()]
    plan = next(e for e in events if e["event"] == "plan")
    flying_to_drop = False
    for event in events:
        if event["event"] == "mode":
            flying_to_drop = event["mode"] == "MOVE_TO_DROP"
            paths = []
        elif event["event"] == "path" and flying_to_drop:
            paths.append(event)
        elif event["event"] == "release" and event["delivered"]:
            assert paths, f"delivery at {event['t']} s without a planned path"
    first_drop_time = plan["drops"][0][1]
    first_release = next(e for e in events if e["event"] == "release")
    assert first_release["t"] == pytest.approx(first_drop_time, abs=15.0)


def test_a_failed_grab_makes_a_new_plan(tmp_path):
    path = scenario_file(
        tmp_path,
        """\
        world: {frame: geocentric, duration: 120}
        robot: {max_force: 5, max_speed: 0.5, grab_distance: 0.6, capacity: 1}
        mission:
          reach: 0.5
          targets:
            - {id: 1, radius: 0.3, motion: {type: static, position: [-8, 0, 0]}}
          drop_point: {position: [0, 0, 0]}
        beacons: {positions: [[50, 50, 50], [50, -50, -50], [-50, 50, -50], [-50, -50, 50]], noise_sigma: 0.01}
        localiser: {plugin: biased}
        """,
    )
    runner, summary = run(path, registry=registry_with(BiasedLocaliser))
    events = runner.recorder.events
    failed = next(e for e in events if e["event"] == "grab")
    assert not failed["success"] and "out of reach" in failed["reason"]
    after = events[events.index(failed) + 1 :]
    assert after[0]["event"] == "mode" and (after[0]["mode"], after[0]["reason"]) == (
        "DEVISE_PLAN",
        "grab failed",
    )
    assert after[1]["event"] == "plan" and after[1]["tasks"][0][0] == 1
    assert summary["delivered"] == 0 and summary["reason"] == "duration reached"


def test_a_target_entering_sensor_range_triggers_a_replan(tmp_path):
    path = scenario_file(
        tmp_path,
        """\
        world: {frame: geocentric, duration: 400}
        robot: {max_force: 5, max_speed: 0.5, sensor_range: 20, capacity: 2}
        mission:
          targets:
            - {id: 1, radius: 0.3, motion: {type: static, position: [8, 0, 0]}}
            - {id: 2, radius: 0.3, motion: {type: cartesian, position: [30, 6, 0], velocity: [-0.3, 0, 0]}}
          drop_point: {position: [0, -3, 0]}
        beacons: {positions: [[50, 50, 50], [50, -50, -50], [-50, 50, -50], [-50, -50, 50]]}
        """,
    )
    runner, summary = run(path)
    events = runner.recorder.events
    plans = [e for e in events if e["event"] == "plan"]
    assert [t for t, _ in plans[0]["tasks"]] == [1]
    replan = next(
        e for e in events if e["event"] == "mode" and e["reason"].startswith("new target")
    )
    assert replan["reason"] == "new target 2 in sight" and replan["mode"] == "DEVISE_PLAN"
    row = next(r for r in runner.recorder.rows if r["time"] == replan["t"])
    gap = np.hypot(30 - 0.3 * replan["t"] - row["x"], 6 - row["y"])
    assert 19.9 < gap <= 20.0  # seen the first tick it was within sensor range
    assert 2 in [t for p in plans[1:] for t, _ in p["tasks"]]
    assert summary["delivered"] == 2 and summary["status"] == "completed"


def test_a_run_flown_before_it_is_opened_says_to_open_it():
    runner = Runner(setup_run(None, (), None, registry=PluginRegistry.discover()))
    with pytest.raises(RuntimeError, match=r"call open\(\) first"):
        runner.advance()


def test_same_scenario_and_seed_give_identical_files(tmp_path):
    for name in ("a", "b"):
        run(overrides=["world.duration=150"], out=tmp_path / name, seed=5)
    for file in ("telemetry.csv", "events.jsonl", "scenario.yaml"):
        assert (tmp_path / "a" / file).read_bytes() == (tmp_path / "b" / file).read_bytes()
    run(overrides=["world.duration=150"], out=tmp_path / "c", seed=6)
    seed_5 = (tmp_path / "a" / "telemetry.csv").read_text().splitlines()
    seed_6 = (tmp_path / "c" / "telemetry.csv").read_text().splitlines()
    assert len(seed_5) == len(seed_6) > 1000 and seed_5[-1] != seed_6[-1]  # the seed matters


def test_a_localiser_s_own_estimate_class_gets_the_attitude_readings():
    runner, summary = run(
        overrides=["localiser.plugin=spread", "world.duration=3"],
        registry=registry_with(SpreadLocaliser),
    )
    assert summary["status"] == "completed", summary["reason"]
    estimate = runner.estimate
    assert type(estimate) is SpreadEstimate and estimate.spread >= 0
    attitude = runner.world.base_state()[2]
    assert estimate.attitude.tolist() == attitude.tolist()


def test_a_raising_plugin_fails_the_run_and_keeps_what_was_recorded(tmp_path):
    out = tmp_path / "run"
    runner, summary = run(
        overrides=["controller.plugin=explodes"],
        out=out,
        registry=registry_with(ExplodingController),
    )
    assert summary["status"] == "failed"
    assert summary["reason"] == (
        "controller plugin 'explodes' raised in command() at t = 2 s: RuntimeError: boom"
    )
    last = json.loads((out / "events.jsonl").read_text().splitlines()[-1])
    assert (
        last["event"] == "plugin_failed"
        and last["plugin"] == "explodes"
        and last["error"] == "boom"
    )
    rows = (out / "telemetry.csv").read_text().splitlines()
    assert len(rows) == 1 + 20  # header, then ticks at 0.0 ... 1.9 s
    assert json.loads((out / "summary.json").read_text())["status"] == "failed"


def test_hooks_observe_the_whole_run_and_an_interrupt_keeps_the_record(tmp_path):
    seen = {"start": 0, "step": 0, "event": 0, "end": []}

    def on_step(run, row):
        seen["step"] += 1
        if row["time"] >= 1.0:
            raise KeyboardInterrupt

    observer = types.ModuleType("observer")
    observer.dcsim_run_start = hookimpl(lambda run: seen.__setitem__("start", seen["start"] + 1))
    observer.dcsim_run_step = hookimpl(on_step)
    observer.dcsim_run_event = hookimpl(
        lambda run, event: seen.__setitem__("event", seen["event"] + 1)
    )
    observer.dcsim_run_end = hookimpl(lambda run, summary: seen["end"].append(summary))
    registry = PluginRegistry.discover()
    registry.register_module(observer, TEST_ORIGIN)
    out = tmp_path / "run"
    runner, summary = run(out=out, registry=registry)
    assert summary["status"] == "stopped" and summary["reason"] == "interrupted"
    assert seen["start"] == 1 and seen["end"] == [summary]
    assert seen["step"] == runner.recorder.count == 11
    assert seen["event"] == len(runner.recorder.events)
    assert len((out / "telemetry.csv").read_text().splitlines()) == 12
    assert json.loads((out / "events.jsonl").read_text().splitlines()[-1])["event"] == "interrupted"


def test_ctrl_c_on_the_command_line_stops_the_run_and_writes_the_summary(tmp_path):
    out = tmp_path / "run"
    process = subprocess.Popen(
        [
            str(DCSIM),
            "run",
            str(REPO / "scenarios" / "thesis_debris_field.yaml"),
            "--out",
            str(out),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONPATH": ""},
        # As at a terminal: a suite started in the background has SIGINT ignored, and
        # the child would inherit that.
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    # Interrupt once rows past the start are on disk: a busy machine can take more than a
    # second over the first tick's planning, and an interrupt then stops the run at t = 0.
    telemetry = out / "telemetry.csv"
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and not (
        telemetry.exists() and len(telemetry.read_text().splitlines()) > 2
    ):
        time.sleep(0.1)
    process.send_signal(signal.SIGINT)
    stdout, stderr = process.communicate(timeout=60)
    assert process.returncode == 130, stdout + stderr
    assert "stopped (interrupted)" in stdout and "Traceback" not in stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["reason"] == "interrupted" and summary["sim_time_s"] > 0
    assert len((out / "telemetry.csv").read_text().splitlines()) > 2


def test_collisions_stop_the_run_or_are_counted(tmp_path):
    text = """\
        world: {frame: geocentric, duration: 30}
        robot: {radius: 0.5, initial: {position: [0, 0, 0], velocity: [0.5, 0, 0]}}
        obstacles:
          - {id: 3, radius: 1.0, motion: {type: static, position: [6, 0, 0]}}
        beacons: {positions: [[50, 50, 50], [50, -50, -50], [-50, 50, -50], [-50, -50, 50]]}
        controller: {plugin: explodes, params: {after: 1000}}
        """
    registry = registry_with(ExplodingController)
    runner, summary = run(scenario_file(tmp_path, text), registry=registry)
    assert summary["status"] == "stopped" and summary["reason"] == "collision with object 3"
    collision = next(e for e in runner.recorder.events if e["event"] == "collision")
    assert collision["t"] == pytest.approx(9.01) and collision["body"] == "collector"
    last, before = runner.recorder.rows[-1], runner.recorder.rows[-2]
    assert last["nearest_obstacle"] < 0
    # The row after the collision keeps the last estimate, its covariance included.
    assert [last[c] for c in SIGMA_COLUMNS] == [before[c] for c in SIGMA_COLUMNS]
    assert 0 < last["est_sigma_x"] < 0.5
    _, going_on = run(
        scenario_file(tmp_path, text + "stop: {on_collision: false}\n"), registry=registry
    )
    assert going_on["status"] == "completed" and going_on["collisions"] == 1


def test_thesis_complete_system_dcc(tmp_path):
    """The thesis's §6.2 DCc test: sspf + ga + elastic on its debris field."""
    runner, summary = run(REPO / "scenarios" / "thesis_debris_field.yaml", out=tmp_path)
    assert [summary["plugins"][role]["name"] for role in ("localiser", "task_planner")] == [
        "sspf",
        "ga",
    ]
    assert summary["plugins"]["controller"]["name"] == "elastic"
    # The DCc behaves as expected: the executer's state machine, and every state
    # coherent with what the collector holds.
    events = runner.recorder.events
    assert set(modes(events)) <= ALLOWED
    telemetry = runner.recorder.telemetry()
    delivering = telemetry["mode"] == "MOVE_TO_DROP"
    assert np.all(telemetry["carried"][delivering] > 0)
    grabs = [e for e in events if e["event"] == "grab"]
    grab_distance = runner.scenario.robot.grab_distance
    assert all(g["success"] and g["gap"] <= grab_distance for g in grabs)
    # No collision; every target captured; the drop point reached with them.
    assert summary["collisions"] == 0
    assert summary["captured"] == summary["delivered"] == summary["targets"] == 4
    releases = [e for e in events if e["event"] == "release" and e["delivered"]]
    assert sorted(sum((e["delivered"] for e in releases), [])) == [1, 2, 3, 4]
    assert summary["status"] == "completed" and summary["reason"] == "all targets delivered"
    # The parked obstacle (16) lies across the straight way to the first target, and it
    # is flown round: no contact with it or anything else.
    parked = next(o for o in runner.scenario.obstacles if o.id == 16)
    centre = parked.motion.build(0.0).position_at(0.0)
    first = np.searchsorted(telemetry["time"], grabs[0]["t"])
    path = [np.array([telemetry[k][i] for k in "xyz"]) for i in (0, first)]
    along = np.clip(
        np.dot(centre - path[0], path[1] - path[0]) / np.sum((path[1] - path[0]) ** 2), 0, 1
    )
    miss = np.linalg.norm(path[0] + along * (path[1] - path[0]) - centre)
    assert miss < parked.radius + runner.scenario.robot.radius
    assert telemetry["nearest_obstacle"].min() > 0
    assert (tmp_path / "plots" / "trajectory.png").exists()
    assert (tmp_path / "plots" / "timeline.png").exists()


@pytest.mark.parametrize("localiser", ["trilateration", "ukf", "sspf"])
def test_default_scenario_delivers_with_each_localiser(localiser):
    _, summary = run(overrides=[f"localiser.plugin={localiser}"])
    assert summary["status"] == "completed" and summary["delivered"] == 4
    assert summary["collisions"] == 0
