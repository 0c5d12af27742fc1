"""Runs that survive: streamed telemetry, a run directory useful at every instant,
checked output paths, and a run that fails cleanly when its disk fills."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
import tracemalloc

import numpy as np
import pytest

from dcsim.registry.discovery import PluginRegistry
from dcsim.run.loop import Runner
from dcsim.run.recording import FLUSH_ROWS, Recorder, column_unit, header_name, read_telemetry
from dcsim.run.setup import setup_run
from dcsim.scenario import read_scenario
from tests.conftest import DCSIM

LONG_RUN = ["world.duration=100000", "mission.stop_on_all_delivered=false"]


def long_runner(out):
    setup = setup_run(None, LONG_RUN, registry=PluginRegistry.discover())
    runner = Runner(setup, out)
    runner.open()
    return runner


def test_telemetry_streams_to_disk_and_memory_stays_flat(tmp_path):
    runner = long_runner(tmp_path)
    telemetry = tmp_path / "telemetry.csv"
    header = telemetry.stat().st_size
    try:
        for _ in range(500):
            runner.advance()
        # Rows wait in a buffer of at most FLUSH_ROWS for up to FLUSH_SECONDS of wall
        # time, so how many wait depends on the machine's speed: memory is compared
        # with the buffer emptied, and the buffer's bound is checked on its own.
        runner.recorder.flush()
        tracemalloc.start()
        early = tracemalloc.get_traced_memory()[0]
        sizes, waiting = [], 0
        for _ in range(2):
            for _ in range(1500):
                runner.advance()
                waiting = max(waiting, runner.recorder.waiting_rows)
            sizes.append(telemetry.stat().st_size)
        runner.recorder.flush()
        grown = tracemalloc.get_traced_memory()[0] - early
        tracemalloc.stop()
    finally:
        summary = runner.close()
    assert runner.recorder.rows == [] and runner.recorder.count == 3501
    assert header < sizes[0] < sizes[1]
    # Keeping the 3000 rows would take about 3 MB.
    assert grown < 250_000, grown
    assert waiting < FLUSH_ROWS
    assert summary["status"] == "stopped"
    table = read_telemetry(telemetry)
    assert len(table["time"]) == 3501
    np.testing.assert_allclose(np.diff(table["time"]), 0.1, atol=1e-9)


def test_a_killed_run_leaves_a_readable_repeatable_run_directory(tmp_path):
    out = tmp_path / "run"
    args = [str(DCSIM), "run", "--out", str(out)] + [a for s in LONG_RUN for a in ("--set", s)]
    child = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    telemetry = out / "telemetry.csv"
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            if telemetry.exists() and telemetry.read_text().count("\n") > 20:
                break
            time.sleep(0.2)
    finally:
        child.send_signal(signal.SIGKILL)
        child.wait()
    assert child.returncode == -signal.SIGKILL
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "running" and summary["scenario"] == "default"
    repeated = read_scenario(out / "scenario.yaml")
    assert repeated.world.duration == 100000 and not repeated.mission.stop_on_all_delivered
    table = read_telemetry(telemetry)
    assert len(table["time"]) > 20 and table["time"][0] == 0.0
    assert np.all(np.diff(table["time"]) > 0)


def test_a_cut_last_line_is_left_out_and_mode_changes_survive_thinning(tmp_path):
    path = tmp_path / "telemetry.csv"
    modes = ["A"] * 500 + ["B"] + ["A"] * 499
    lines = [f"{k * 0.1!r},{mode},{k}" for k, mode in enumerate(modes)]
    path.write_text("time,mode,x\n" + "\n".join(lines) + "\n1000.0,A")
    full = read_telemetry(path)
    assert len(full["time"]) == 1000 and full["x"][-1] == 999
    thin = read_telemetry(path, max_points=10)
    assert len(thin["time"]) < 20
    assert "B" in thin["mode"] and thin["x"][0] == 0 and thin["x"][-1] == 999
    assert {499, 500, 501} <= set(thin["x"].astype(int))


def test_thinned_rows_carry_the_mean_duty_cycles_of_the_rows_they_stand_for(tmp_path):
    path = tmp_path / "telemetry.csv"
    # a thruster fires half the period on every row that ends in 5, which a stride of
    # ten never lands on; a mode change at row 500 keeps rows 499-501
    rows = [(k, "B" if k == 500 else "A", 0.5 if k % 10 == 5 else 0.0) for k in range(1000)]
    lines = [f"{k * 0.1!r},{mode},{k},{duty!r}" for k, mode, duty in rows]
    path.write_text("time,mode,x,duty_1\n" + "\n".join(lines) + "\n")
    thin = read_telemetry(path, max_points=100)
    kept = thin["x"].astype(int)
    assert 0 < len(kept) < 120 and thin["duty_1"].max() > 0
    # each kept row's duty times the rows it stands for adds up to every firing
    stands_for = np.diff(np.concatenate([[-1], kept]))
    assert thin["duty_1"] @ stands_for == pytest.approx(0.5 * 100)
    assert np.array_equal(thin["x"], kept)  # other columns are the kept rows' own


def test_the_header_carries_units_and_the_reader_gives_the_row_names(tmp_path):
    recorder = Recorder(tmp_path, ("time", "mode", "x", "hits"), units={"time": "s", "x": "m"})
    recorder.start("name: t\n", {"status": "running"})
    recorder.row({"time": 0.0, "mode": "A", "x": 1.5, "hits": 2})
    recorder.finish({"status": "completed"})
    lines = (tmp_path / "telemetry.csv").read_text().splitlines()
    assert lines == ["time_s,mode,x_m,hits", "0.0,A,1.5,2"]
    table = read_telemetry(tmp_path / "telemetry.csv")
    assert list(table) == ["time", "mode", "x", "hits"] and table["x"][0] == 1.5
    assert [column_unit(name) for name in lines[0].split(",")] == ["s", "", "m", ""]
    assert column_unit("vx_mps") == "m/s" and column_unit("tx_Nm") == "N·m"


def test_a_unit_the_header_could_not_carry_back_is_refused():
    with pytest.raises(ValueError, match="unknown unit 'furlong'"):
        header_name("x", "furlong")
    with pytest.raises(ValueError, match="ends like a unit suffix"):
        header_name("mass_kg")  # read back, the header would say: mass, in kg


def test_bad_output_paths_are_refused_before_the_run(dcsim_cli, tmp_path):
    blocker = tmp_path / "a_file"
    blocker.write_text("")
    cases = {
        "/proc/nope": "error: cannot write the run directory /proc/nope:",
        str(blocker / "x"): f"error: cannot use {blocker / 'x'} as a run directory: "
        f"{blocker} is a file",
    }
    for out, message in cases.items():
        result = dcsim_cli("run", "--out", out, "--set", "world.duration=1")
        assert result.returncode == 2, result.stderr
        assert message in result.stderr and "Traceback" not in result.stderr


def test_an_existing_run_is_replaced_only_with_force(dcsim_cli, tmp_path):
    out = tmp_path / "run"
    assert dcsim_cli("run", "--out", str(out), "--set", "world.duration=1").returncode == 0
    (out / "stale.txt").write_text("from before")
    again = dcsim_cli("run", "--out", str(out), "--set", "world.duration=2")
    assert again.returncode == 2
    assert f"error: {out} holds a run; choose another --out or add --force" in again.stderr
    forced = dcsim_cli("run", "--out", str(out), "--force", "--set", "world.duration=2")
    assert forced.returncode == 0, forced.stderr
    assert not (out / "stale.txt").exists()
    assert json.loads((out / "summary.json").read_text())["sim_time_s"] == 2.0


DISK_FULL = """
import resource, sys
resource.setrlimit(resource.RLIMIT_FSIZE, (60_000, 60_000))
from dcsim.cli.main import main
sys.argv = ["dcsim", "run", "--out", sys.argv[1], "--set", "world.duration=600",
            "--set", "mission.stop_on_all_delivered=false"]
main()
"""


def test_a_full_disk_ends_the_run_failed_and_keeps_what_was_written(tmp_path):
    out = tmp_path / "run"
    done = subprocess.run(
        [sys.executable, "-c", DISK_FULL, str(out)],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "PYTHONPATH": ""},
    )
    assert done.returncode == 1, done.stderr
    assert "Traceback" not in done.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed"
    assert "cannot write" in summary["reason"] and "telemetry.csv" in summary["reason"]
    assert "File too large" in summary["reason"]
    assert (out / "telemetry.csv").stat().st_size <= 60_000
    table = read_telemetry(out / "telemetry.csv")
    assert len(table["time"]) > 100
    assert summary["sim_time_s"] < 600
