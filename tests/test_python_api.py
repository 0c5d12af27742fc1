"""Runs from Python (dcsim.api): docs/python.md as written, in memory and on disk alike,
stepping, reading a run directory back, and the errors a user can make."""

from __future__ import annotations

import contextlib
import io
import json
import re
import shutil

import matplotlib
import numpy as np
import pandas as pd
import pytest

from dcsim.api import (
    RunResult,
    ScenarioError,
    close_run,
    load_scenario,
    open_run,
    read_run,
    run,
)
from dcsim.run.directory import RunDirectoryError
from tests.conftest import REPO

SHORT = ["world.duration=30"]
WALL_FIELDS = {"wall_time_s", "real_time_factor", "wall_time_by_phase_s"}

# A fenced block of Python, optionally followed by "prints" and the block of its output.
EXAMPLE = re.compile(r"```python\n(.*?)```\n(?:\nprints\n\n```\n(.*?)```\n)?", re.S)


def steady(summary: dict) -> dict:
    """A summary without the fields that measure wall time."""
    return {k: v for k, v in summary.items() if k not in WALL_FIELDS}


@pytest.fixture(scope="module")
def memory_run() -> RunResult:
    return run(overrides=SHORT)


@pytest.fixture(scope="module")
def disk_run(tmp_path_factory) -> RunResult:
    return run(None, {"world.duration": 30}, tmp_path_factory.mktemp("api") / "run", plots=False)


def test_the_python_docs_run_as_written_and_print_what_they_show(tmp_path, monkeypatch):
    matplotlib.use("Agg")
    (tmp_path / "scenarios").symlink_to(REPO / "scenarios")
    monkeypatch.chdir(tmp_path)
    examples = EXAMPLE.findall((REPO / "docs" / "python.md").read_text(encoding="utf-8"))
    assert len(examples) == 3
    namespace: dict = {}
    for code, shown in examples:
        printed = io.StringIO()
        with contextlib.redirect_stdout(printed):
            exec(compile(code, "docs/python.md", "exec"), namespace)
        assert printed.getvalue() == shown
    assert (tmp_path / "x.png").stat().st_size > 10_000
    assert (tmp_path / "runs" / "short" / "summary.json").exists()


def test_a_run_in_memory_records_what_its_run_directory_holds(memory_run, disk_run):
    assert memory_run.run_dir is None and disk_run.run_dir is not None
    pd.testing.assert_frame_equal(memory_run.telemetry, disk_run.telemetry)
    assert memory_run.events == disk_run.events
    assert steady(memory_run.summary) == steady(disk_run.summary)
    assert memory_run.plugins == {
        entry["name"]: entry["version"] for entry in memory_run.summary["plugins"].values()
    }
    assert memory_run.status == "completed" and len(memory_run.telemetry) == 301


def test_the_telemetry_has_the_file_s_names_and_their_units(disk_run):
    header = (disk_run.run_dir / "telemetry.csv").read_text().splitlines()[0]
    telemetry = disk_run.telemetry
    assert list(telemetry.columns) == header.split(",")
    units = telemetry.attrs["units"]
    assert units["time_s"] == "s" and units["vx_mps"] == "m/s" and units["fx_N"] == "N"
    assert units["mode"] == "" and units["qw"] == ""
    assert telemetry["converged"].dtype == np.int64 and telemetry["time_s"].iloc[-1] == 30.0
    grabs = disk_run.events_table().query("event == 'mode'")
    assert list(grabs.columns[:2]) == ["t", "event"] and len(grabs) > 1


def test_a_killed_run_reads_up_to_its_last_complete_row(disk_run, tmp_path):
    killed = tmp_path / "killed"
    shutil.copytree(disk_run.run_dir, killed)
    for name in ("telemetry.csv", "events.jsonl"):
        text = (killed / name).read_text()
        (killed / name).write_text(text[: len(text) - 7])  # the last line cut short
    (killed / "summary.json").write_text(json.dumps({"status": "running", "reason": ""}))
    result = read_run(killed)
    assert result.status == "running" and result.plugins == {}
    assert len(result.telemetry) == len(disk_run.telemetry) - 1
    pd.testing.assert_frame_equal(result.telemetry, disk_run.telemetry.iloc[:-1])
    assert result.events == disk_run.events[:-1]


def test_reading_what_is_not_a_run_directory_says_so(tmp_path):
    with pytest.raises(RunDirectoryError, match="is not a run directory"):
        read_run(tmp_path / "nowhere")
    (tmp_path / "summary.json").write_text("{not json")
    (tmp_path / "telemetry.csv").write_text("time_s\n0.0\n")
    (tmp_path / "events.jsonl").write_text("")
    with pytest.raises(RunDirectoryError, match="cannot read the run directory"):
        read_run(tmp_path)
    (tmp_path / "events.jsonl").unlink()
    (tmp_path / "summary.json").write_text("{}")
    with pytest.raises(RunDirectoryError, match="has no events.jsonl"):
        read_run(tmp_path)


def test_a_scenario_is_a_file_a_mapping_or_a_loaded_one_with_overrides_of_either_form():
    path = REPO / "scenarios" / "default.yaml"
    from_file = load_scenario(path, ["world.duration=30", "robot.max_force=12.5"], seed=4)
    data = from_file.model_dump(mode="json")
    assert from_file.world.seed == 4 and from_file.robot.max_force == 12.5
    assert load_scenario(data) == from_file
    assert load_scenario(from_file, {"robot.max_force": 1e-3}).robot.max_force == 1e-3
    reshaped = load_scenario(
        data, {"mission.targets[0].motion.position": [1, 2, 3.5], "name": "mapped"}
    )
    moved = reshaped.mission.targets[0].motion.position
    assert tuple(moved) == (1, 2, 3.5) and reshaped.name == "mapped"
    assert load_scenario().name == "default"
    swept = load_scenario(path, {"world.duration": np.float64(30), "world.seed": np.int64(7)})
    assert swept.world.duration == 30 and swept.world.seed == 7
    placed = load_scenario(data, {"mission.targets[0].motion.position": np.array([1.0, 2.0, 3.5])})
    assert tuple(placed.mission.targets[0].motion.position) == (1, 2, 3.5)


def test_bad_scenarios_and_overrides_are_refused_by_key_path_before_anything_runs(tmp_path):
    with pytest.raises(ScenarioError) as error:
        load_scenario({"world": {"seed": -4, "duration": np.float32(2.0)}})
    assert "scenario mapping: invalid scenario" in str(error.value)
    with pytest.raises(ScenarioError, match="world.seed: -4 is not allowed"):
        load_scenario({"world": {"seed": -4}})
    with pytest.raises(ScenarioError, match="--set world.duration=-1"):
        run(overrides={"world.duration": -1}, out=tmp_path / "never")
    with pytest.raises(ScenarioError, match="world.duration: .* is not plain data"):
        load_scenario(overrides={"world.duration": object()})
    assert not (tmp_path / "never").exists()


def test_a_stepped_run_takes_disturbances_and_closes_like_a_run(memory_run):
    runner = open_run(overrides=SHORT)
    assert runner.world.time == 0.0 and runner.mode is not None and not runner.ended
    while not runner.ended:
        runner.advance()
    stepped = close_run(runner)
    pd.testing.assert_frame_equal(stepped.telemetry, memory_run.telemetry)
    assert close_run(runner).summary == stepped.summary  # closed once only
    pushed = open_run(overrides=SHORT)
    for _ in range(50):
        pushed.advance(disturbance_force=np.array([0.0, 0.0, 5.0]))
    early = close_run(pushed)
    assert early.status == "stopped" and early.summary["reason"] == "closed before the end"
    assert len(early.telemetry) == 51
    assert early.telemetry["z_m"].iloc[-1] > memory_run.telemetry["z_m"].iloc[50] + 0.1
