"""``dcsim bench path-planners``: problems, runs, OMPL's log and database, the command."""

from __future__ import annotations

import dataclasses
import math
import os
import signal
import sqlite3
import sys
import time
import tracemalloc

import numpy as np
import pytest
import yaml
from click.testing import CliRunner
from dcsim_plugins.path_planners.straight_line import StraightLinePlanner

from dcsim.bench import path_reports
from dcsim.bench.asteroids import escape_scenario
from dcsim.bench.ompl_log import write_database
from dcsim.bench.path_planners import (
    PlanRun,
    bench_path_planners,
    evaluate,
    plan_in_process,
    select_planners,
)
from dcsim.bench.path_problems import expand_specs, load_problem
from dcsim.cli.main import cli
from dcsim.errors import DcsimError
from dcsim.messages import NoPath, Trajectory
from dcsim.registry.discovery import PluginOrigin, PluginRegistry, RegisteredPlugin
from tests.conftest import REPO


def entry(cls) -> RegisteredPlugin:
    return RegisteredPlugin(cls, PluginOrigin("tests", "0", cls.__module__))


# ----------------------------------------------------------------- runs


class CrashingPlanner(StraightLinePlanner):
    name = "crashing"
    summary = "Dies at once, as a crash in C would (test)"

    def plan(self, problem):
        os.kill(os.getpid(), signal.SIGKILL)


class TraceShyPlanner(StraightLinePlanner):
    name = "trace-shy"
    summary = "Answers, then dies in the traced call (test)"

    def plan(self, problem):
        if tracemalloc.is_tracing():
            os.kill(os.getpid(), signal.SIGKILL)
        return super().plan(problem)


class HangingPlanner(StraightLinePlanner):
    name = "hanging"
    summary = "Never answers (test)"

    def plan(self, problem):
        time.sleep(60)


class RaisingPlanner(StraightLinePlanner):
    name = "raising"
    summary = "Raises (test)"

    def plan(self, problem):
        raise RuntimeError("lost in space")


class SeededPlanner(StraightLinePlanner):
    name = "seeded"
    summary = "Flies at a random fraction of the speed limit, with statistics (test)"

    def plan(self, problem):
        fraction = 0.5 + 0.5 * self.rng.random()
        trajectory = super().plan(
            dataclasses.replace(problem, max_speed=fraction * problem.max_speed)
        )
        if isinstance(trajectory, NoPath):
            return trajectory
        statistics = {"nodes_expanded": 12, "draw": fraction}
        return dataclasses.replace(trajectory, statistics=statistics)


class DeadlineEcho(StraightLinePlanner):
    name = "deadline-echo"
    summary = "Answers with the deadline it was given and when it was called (test)"

    def plan(self, problem):
        return NoPath(f"{problem.deadline!r} {time.monotonic()!r}")


@pytest.fixture(scope="module")
def quick():
    bench = load_problem("static-spheres")  # the straight line is clear on seed 0
    return dataclasses.replace(bench, problem=dataclasses.replace(bench.problem, time_budget=0.05))


def test_every_plan_is_due_its_budget_after_the_bench_starts_its_clock(quick):
    budget = quick.problem.time_budget
    assert quick.problem.deadline is None
    answer, seconds, _ = plan_in_process(DeadlineEcho, 0, quick.problem, memory=False)
    deadline, called = (float(word) for word in answer.reason.split())
    assert budget - 0.01 < deadline - called <= budget
    assert 0 <= seconds < 0.5


def test_each_run_plans_in_its_own_process_with_its_seed(quick):
    answers = [plan_in_process(SeededPlanner, seed, quick.problem) for seed in (4, 4, 5)]
    assert all(isinstance(a, Trajectory) for a, _, _ in answers)
    assert answers[0][0] == answers[1][0] != answers[2][0]
    assert all(0 < seconds < 0.5 and peak > 0 for _, seconds, peak in answers)


def test_crashes_hangs_and_exceptions_are_results_not_failures(quick):
    crashed, _, _ = plan_in_process(CrashingPlanner, 0, quick.problem)
    assert crashed == f"the planning process died (exit code {-signal.SIGKILL})"
    began = time.perf_counter()
    hung, waited, _ = plan_in_process(HangingPlanner, 0, quick.problem)
    assert hung is None and waited == pytest.approx(1.26)
    assert time.perf_counter() - began < 3.0
    raised, _, _ = plan_in_process(RaisingPlanner, 0, quick.problem)
    assert raised == "RuntimeError: lost in space"
    answered, seconds, peak = plan_in_process(TraceShyPlanner, 0, quick.problem)
    assert isinstance(answered, Trajectory) and seconds > 0 and np.isnan(peak)


def test_answers_are_judged_by_status_arrival_and_swept_clearance(quick):
    trajectory, seconds, peak = plan_in_process(StraightLinePlanner, 0, quick.problem)
    solved = evaluate("straight-line", quick, 0, trajectory, seconds, peak)
    assert solved.status == "solved" and solved.exact and not solved.approximate
    assert solved.success and solved.collides is False and 0 < solved.clearance < 5
    assert solved.length == pytest.approx(60.0) and solved.delta_v == trajectory.delta_v
    short = dataclasses.replace(trajectory, positions=trajectory.positions * 0.5)
    assert evaluate("p", quick, 0, short, seconds, peak).approximate
    late = evaluate("p", quick, 0, trajectory, 0.5, peak)
    assert late.status == "timeout" and "with a budget of 0.05 s" in late.reason
    assert evaluate("p", quick, 0, None, 1.26, np.nan).reason == "killed after 1.3 s"
    refused = evaluate("p", quick, 0, NoPath("walled in"), seconds, peak)
    assert (refused.status, refused.reason, refused.success) == ("no path", "walled in", False)
    assert evaluate("p", quick, 0, 42, seconds, peak).reason == "returned int"
    blocker = quick.problem.obstacles[0].position
    through = Trajectory(
        times=[0.0, 30.0, 60.0],
        positions=[[0.0, 0.0, 0.0], blocker, [60.0, 0.0, 0.0]],
        velocities=np.zeros((3, 3)),
    )
    crashed = evaluate("p", quick, 0, through, seconds, peak)
    assert crashed.collides and not crashed.success and crashed.clearance < 0


# ----------------------------------------------------------------- log and database


def test_the_log_reads_back_with_ompls_parser_into_planner_arenas_tables(quick, tmp_path):
    planners = [entry(StraightLinePlanner), entry(SeededPlanner), entry(RaisingPlanner)]
    results = bench_path_planners([quick, quick], planners, 3, False, None, progress=lambda _: None)
    logs = path_reports.write_logs(results[:1], planners, 3, False, tmp_path / "out" / "b.log")
    assert [p.name for p in logs] == ["b.static-spheres-0.log"]
    database = tmp_path / "arena.db"
    write_database(logs, database)
    with sqlite3.connect(database) as db:
        tables = {row[0] for row in db.execute("SELECT name FROM sqlite_master WHERE type='table'")}
        assert {"experiments", "plannerConfigs", "runs", "progress", "enums"} <= tables
        ((version, name, runcount),) = db.execute("SELECT version, name, runcount FROM experiments")
        assert version.startswith("dcsim ") and name == "static-spheres-0" and runcount == 3
        rows = db.execute(
            "SELECT plannerConfigs.name, seed, status, solved, correct_solution, "
            "planner_nodes_expanded FROM runs JOIN plannerConfigs ON plannerid = plannerConfigs.id"
        ).fetchall()
        statuses = dict(db.execute("SELECT value, description FROM enums WHERE name = 'status'"))
    assert len(rows) == 9
    assert statuses == {0: "solved", 1: "no path", 2: "error", 3: "timeout"}
    by_planner = {(n, seed): row for n, seed, *row in rows}
    assert by_planner["straight-line", 2] == [0, 1, 1, None]
    assert by_planner["seeded", 1] == [0, 1, 1, 12.0]
    assert by_planner["raising", 0] == [2, 0, None, None]


def test_the_table_gives_success_and_medians_per_problem_and_planner(quick):
    planners = [entry(StraightLinePlanner), entry(RaisingPlanner)]
    (result,) = bench_path_planners([quick], planners, 2, False, None, progress=lambda _: None)
    table = path_reports.markdown_table([result], flights=False).splitlines()
    assert table[0].startswith("| problem | planner | runs | success | not solved |")
    assert table[2].startswith("| static-spheres-0 | straight-line | 2 | 100% | – |")
    assert table[2].endswith("| 60.00 | 1.60 | 1.56 |")
    assert table[3].startswith("| static-spheres-0 | raising | 2 | 0% | 2 error |")
    assert table[3].endswith("| – | – | – |")


def test_runs_keep_their_fields_for_the_log():
    run = PlanRun("p", "q", 0, "no path", reason="x", time=0.001, peak_memory=2**20)
    assert path_reports._run_values(run)[:4] == [0, 0.001, 1.0, 1]
    assert (
        path_reports.statistic_property("nodes-expanded (total)") == "planner nodes expanded total"
    )


# ----------------------------------------------------------------- the command


def test_the_command_writes_table_logs_database_and_plot(transfer_file, tmp_path):
    out = tmp_path / "out"
    result = CliRunner().invoke(
        cli,
        [
            "bench",
            "path-planners",
            "--planners",
            "straight-line",
            "--runs",
            "2",
            "--problems",
            f"shapes:1,{transfer_file}",
            "--fly",
            "--log",
            str(out / "bench.log"),
            "--db",
            str(out / "bench.db"),
            "--plot",
            str(out / "bench.png"),
        ],
    )
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()
    assert "| shapes-1 | straight-line | 2 | 0% | 2 no path |" in lines[2]
    assert lines[3].startswith("| two_obstacles | straight-line | 2 | 100% | – |")
    assert lines[3].endswith("| 0 | 2 / 2 |")  # flown: no collision, both arrived
    assert sorted(p.name for p in out.iterdir()) == [
        "bench.db",
        "bench.png",
        "bench.shapes-1.log",
        "bench.two_obstacles.log",
    ]
    with sqlite3.connect(out / "bench.db") as db:
        assert db.execute("SELECT count(*) FROM runs").fetchone() == (4,)
        flown = db.execute("SELECT flown_reached, flown_collisions FROM runs WHERE solved = 1")
        assert flown.fetchall() == [(1, 0), (1, 0)]


def test_the_command_refuses_a_database_without_ompl_before_any_run(monkeypatch, tmp_path):
    monkeypatch.setitem(sys.modules, "ompl.tools", None)
    result = CliRunner().invoke(cli, ["bench", "path-planners", "--db", str(tmp_path / "x.db")])
    assert result.exit_code == 2 and "pip install 'dcsim[bench]'" in result.output
    assert " seed 0: " not in result.output and not (tmp_path / "x.db").exists()


def test_the_command_refuses_unknown_planners_and_problems():
    unknown = CliRunner().invoke(cli, ["bench", "path-planners", "--planners", "rrt-nope"])
    assert unknown.exit_code == 2 and "no path_planner plugin named 'rrt-nope'" in unknown.output
    bad = CliRunner().invoke(cli, ["bench", "path-planners", "--problems", "mars:x"])
    assert bad.exit_code == 2 and "'mars:x' is neither a problem family" in bad.output


# ----------------------------------------------------------------- variants and families


def test_planners_can_be_named_with_parameters():
    registry = PluginRegistry.discover()
    plain, tuned = select_planners(
        registry, ["straight-line", "straight-line:speed_fraction=0.4:check_obstacles=false"]
    )
    assert (plain.name, tuned.name) == (
        "straight-line",
        "straight-line:speed_fraction=0.4:check_obstacles=False",
    )
    assert tuned.params == {"speed_fraction": 0.4, "check_obstacles": False}
    assert tuned.settings()["speed_fraction"] == 0.4 and plain.settings()["speed_fraction"] == 0.8
    for spec in ("straight-line:speed_fraction", "straight-line:speed_fraction=-1"):
        with pytest.raises(DcsimError):
            select_planners(registry, [spec])


def test_a_planner_is_given_no_margin_of_its_own():
    registry = PluginRegistry.discover()
    with pytest.raises(DcsimError, match="safety_margin.*mission.safety_distance"):
        select_planners(registry, ["straight-line:clearance=1.5"])


def test_a_planners_parameters_reach_its_runs(quick):
    tuned = select_planners(PluginRegistry.discover(), ["straight-line:speed_fraction=0.4"])
    plain = select_planners(PluginRegistry.discover(), ["straight-line"])
    (result,) = bench_path_planners([quick], [*plain, *tuned], 1, False, None, lambda _: None)
    slow, fast = result.runs[1], result.runs[0]
    assert slow.planner == "straight-line:speed_fraction=0.4"
    assert slow.duration > 1.5 * fast.duration


def test_seed_ranges_expand_and_the_escape_family_is_the_scenario_file():
    assert expand_specs(["asteroid-escape:3..5", "shapes", "x.yaml"]) == [
        "asteroid-escape:3",
        "asteroid-escape:4",
        "asteroid-escape:5",
        "shapes",
        "x.yaml",
    ]
    scenario = yaml.safe_load((REPO / "scenarios" / "asteroid_escape.yaml").read_text())
    family = escape_scenario(2023)
    for key in ("world", "robot", "obstacles", "path_planner", "controller", "stop"):
        assert family[key] == scenario[key], key
    assert family["mission"] == {**scenario["mission"], "planning_budget": 10.0}
    assert escape_scenario(1)["obstacles"] != family["obstacles"]


def test_the_family_table_pools_a_familys_problems(quick):
    other = dataclasses.replace(quick, name="static-spheres-1")
    planners = [entry(StraightLinePlanner)]
    results = bench_path_planners([quick, other], planners, 2, False, None, lambda _: None)
    table = path_reports.family_table(results, flights=False).splitlines()
    assert table[0].startswith("| family | planner | runs | success | time median [ms] |")
    assert table[2].startswith("| static-spheres | straight-line | 4 | 4 |")
    assert table[2].endswith("| – | – | 91.0 | 1.60 |")  # no statistics; 60 m in 91 s


def test_memory_tracing_can_be_left_out(quick):
    answer, seconds, peak = plan_in_process(StraightLinePlanner, 0, quick.problem, memory=False)
    assert isinstance(answer, Trajectory) and seconds > 0 and math.isnan(peak)


class MisplacedPlanner(StraightLinePlanner):
    name = "misplaced"
    summary = "Starts its trajectory 1 m off the start (test)"

    def plan(self, problem):
        trajectory = super().plan(problem)
        return dataclasses.replace(trajectory, positions=trajectory.positions + [0.0, 1.0, 0.0])


def test_a_trajectory_that_does_not_start_at_the_start_is_no_success(quick):
    answer, seconds, peak = plan_in_process(MisplacedPlanner, 0, quick.problem, memory=False)
    run = evaluate("misplaced", quick, 0, answer, seconds, peak)
    assert run.status == "solved" and not run.exact and not run.success
    assert run.reason == "starts 1 m and 0 s from the start state"
