"""The transfer mission: planning, re-planning, tracking tolerance and feed-forward."""

from __future__ import annotations

import csv
import json
import textwrap

import numpy as np
import pytest

from dcsim.api import NoPath, PathPlanner, Trajectory
from dcsim.registry.discovery import PluginOrigin, PluginRegistry
from dcsim.run.loop import Runner
from dcsim.run.recording import SIGMA_COLUMNS, read_telemetry
from dcsim.run.setup import setup_run

TEST_ORIGIN = PluginOrigin("tests", "0", "test module")

BASE = """\
    name: transfer-test
    world: {frame: geocentric, duration: 120}
    robot: {max_speed: 0.5}
    mission:
      type: transfer
      retry: 2
      goal: {position: [5, 0, 0], radius: 0.2, velocity_tolerance: 0.02}
    path_planner: {plugin: %s}
"""


def line(start, end, duration, samples=41) -> Trajectory:
    """Rest-to-rest along a straight line with a smooth (cosine) speed profile."""
    tau = np.linspace(0.0, 1.0, samples)
    s = 0.5 * (1 - np.cos(np.pi * tau))
    ds = 0.5 * np.pi * np.sin(np.pi * tau) / duration
    offset = np.asarray(end) - np.asarray(start)
    return Trajectory(
        times=duration * tau,
        positions=np.asarray(start) + np.outer(s, offset),
        velocities=np.outer(ds, offset),
    )


class FlakyPlanner(PathPlanner):
    """No path on the first call, then a smooth straight line from where it is asked."""

    name = "flaky"
    summary = "no path once, then a line (test)"
    calls = 0

    def plan(self, problem):
        FlakyPlanner.calls += 1
        if FlakyPlanner.calls == 1:
            return NoPath("the way is blocked for now")
        trajectory = line(problem.start.position, problem.goal.position, 40.0)
        return Trajectory(
            times=problem.start.time + trajectory.times,
            positions=trajectory.positions,
            velocities=trajectory.velocities,
            statistics={"nodes_expanded": 7.0},
        )


class DetourPlanner(PathPlanner):
    """First a trajectory that starts 3 m off the robot, then a good one."""

    name = "detour"
    summary = "a bad trajectory, then a good one (test)"
    calls = 0

    def plan(self, problem):
        DetourPlanner.calls += 1
        shift = np.array([0.0, 3.0, 0.0]) if DetourPlanner.calls == 1 else np.zeros(3)
        trajectory = line(problem.start.position + shift, problem.goal.position, 40.0)
        return Trajectory(
            times=problem.start.time + trajectory.times,
            positions=trajectory.positions,
            velocities=trajectory.velocities,
        )


class NeverPlanner(PathPlanner):
    name = "never"
    summary = "never finds a path (test)"

    def plan(self, problem):
        return NoPath("there is no way through")


def run_transfer(tmp_path, planner: type, overrides=()):
    registry = PluginRegistry.discover()
    registry.register_class(planner, TEST_ORIGIN)
    tmp_path.mkdir(parents=True, exist_ok=True)
    path = tmp_path / "scenario.yaml"
    path.write_text(textwrap.dedent(BASE % planner.name))
    out = tmp_path / "run"
    summary = Runner(setup_run(path, overrides, registry=registry), out).run()
    events = [json.loads(text) for text in (out / "events.jsonl").read_text().splitlines()]
    return summary, events, out


def test_no_path_is_retried_after_the_wait_and_the_goal_is_reached(tmp_path):
    FlakyPlanner.calls = 0
    summary, events, out = run_transfer(tmp_path, FlakyPlanner)
    assert summary["status"] == "completed" and summary["reason"] == "goal reached"
    no_path = [e for e in events if e["event"] == "no_path"]
    paths = [e for e in events if e["event"] == "path"]
    assert [e["t"] for e in no_path] == [0.0] and [e["t"] for e in paths] == [2.0]
    assert summary["reached"] and 42.0 <= summary["time_to_goal_s"] < 60.0
    assert summary["nodes_expanded"] == 7.0 and summary["replans"] == 0
    assert summary["localiser"] == "none: the mission was fed the true state"
    telemetry = read_telemetry(out / "telemetry.csv")
    assert all(np.all(telemetry[c] == 0.0) for c in SIGMA_COLUMNS)  # the truth: σ = 0
    with (out / "trajectory.csv").open() as stream:
        rows = list(csv.DictReader(stream))
    assert len(rows) == 41 and float(rows[-1]["x_m"]) == pytest.approx(5.0)


def test_straying_beyond_the_tracking_tolerance_replans_from_the_estimate(tmp_path):
    DetourPlanner.calls = 0
    summary, events, _ = run_transfer(tmp_path, DetourPlanner)
    off = [e for e in events if e["event"] == "off_track"]
    assert len(off) == 1 and off[0]["t"] == 0.0 and off[0]["error"] == pytest.approx(3.0)
    assert DetourPlanner.calls == 2 and summary["replans"] == 1
    assert summary["status"] == "completed" and summary["max_tracking_error_m"] < 2.0


def test_planning_is_given_up_after_the_attempts_allowed(tmp_path):
    summary, events, _ = run_transfer(tmp_path, NeverPlanner)
    assert summary["status"] == "stopped"
    assert summary["reason"] == "no path after 3 attempts: there is no way through"
    assert [e["t"] for e in events if e["event"] == "no_path"] == [0.0, 2.0, 4.0]
    assert not summary["reached"] and summary["time_to_goal_s"] is None


FORCE, HALF = 2.0, 15.0  # N, s: thrust along +x, then along −x


class BangBangPlanner(PathPlanner):
    """Full thrust for HALF seconds, full braking for HALF seconds, with the forces given."""

    name = "bang-bang"
    summary = "a bang-bang profile with its forces (test)"

    def plan(self, problem):
        mass = 100.0
        a = FORCE / mass
        t = np.linspace(0.0, 2 * HALF, 61)
        braking = t > HALF
        v = np.where(braking, a * (2 * HALF - t), a * t)
        x = np.where(braking, a * HALF**2 - 0.5 * a * (2 * HALF - t) ** 2, 0.5 * a * t**2)
        forces = np.zeros((60, 3))
        forces[:, 0] = np.where(t[:-1] < HALF, FORCE, -FORCE)
        zeros = np.zeros_like(t)
        return Trajectory(
            times=problem.start.time + t,
            positions=problem.start.position + np.column_stack([x, zeros, zeros]),
            velocities=np.column_stack([v, zeros, zeros]),
            forces=forces if self.feed_forward else None,
            duration=2 * HALF,
        )

    feed_forward = True


def test_a_trajectory_with_forces_is_flown_as_planned(tmp_path):
    goal = [
        "mission.goal.position=[4.5, 0, 0]",
        "mission.goal.radius=0.01",
        "mission.goal.velocity_tolerance=0.001",
        "mission.tracking_tolerance=1.0",
    ]
    summary, _, out = run_transfer(tmp_path, BangBangPlanner, goal)
    with (out / "telemetry.csv").open() as stream:
        rows = list(csv.DictReader(stream))
    errors = np.array([float(r["tracking_error_m"]) for r in rows])
    # The profile ends at x = a·HALF² = 4.5 m at rest; fed forward, the PD loop only
    # mops up the propellant's mass loss and the sampling of the reference.
    assert summary["status"] == "completed", summary["reason"]
    assert summary["time_to_goal_s"] <= 2 * HALF + 1.0
    assert errors.max() < 5e-3
    BangBangPlanner.feed_forward = False
    try:
        plain, _, plain_out = run_transfer(tmp_path / "plain", BangBangPlanner, goal)
    finally:
        BangBangPlanner.feed_forward = True
    with (plain_out / "telemetry.csv").open() as stream:
        plain_errors = np.array([float(r["tracking_error_m"]) for r in csv.DictReader(stream)])
    assert plain_errors.max() > 10 * errors.max()
