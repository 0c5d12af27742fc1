"""Campaigns on real Dask clusters: results equal direct runs, dying workers, Ctrl-C and
resume, replay, and a scheduler and workers started as separate processes."""

from __future__ import annotations

import filecmp
import json
import signal
import socket
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pandas
import pytest

import dcsim.api
from dcsim.campaign import ClusterOptions, load_campaign, replay_case, run_campaign
from dcsim.campaign.cases import campaign_cases
from dcsim.campaign.engine import ClusterError, dask_client
from dcsim.campaign.run import read_journal
from dcsim.registry.discovery import PluginRegistry
from dcsim.run.loop import Runner
from dcsim.run.setup import setup_run
from tests.conftest import make_distribution

REPO = Path(__file__).resolve().parents[2]
DEFAULT = REPO / "scenarios" / "default.yaml"
BIN = Path(sys.executable).parent
ON_DASK = pytest.mark.xdist_group("dask")
"""Tests that start clusters: one pytest worker runs them, one after the other."""

TWELVE_CASES = """
    name: twelve
    scenario: BASE
    seed: 5
    cases: 6
    set: {world.duration: 4.0, task_planner.plugin: nearest}
    grid: {controller.plugin: [pd, elastic]}
    dispersions:
      robot.initial.position: {type: normal, sigma: [1.0, 1.0, 0.5]}
      beacons.noise_sigma: {type: uniform, low: 0.02, high: 0.1}
    metrics: [delta_v_mps, localisation_rmse_m, sim_time_s]
"""

MOODY_CONTROLLER = """
    import os
    from pathlib import Path
    from typing import Literal
    from dcsim.api import Command, Controller, PluginParams, quantity

    class MoodyParams(PluginParams):
        mood: Literal["calm", "exit", "raise"] = quantity("calm", description="What it does.")
        log: str = quantity("", description="File each attempt appends a line to.")

    class MoodyController(Controller):
        name = "moody"
        summary = "Commands nothing; or kills its process, or raises, when told"
        Params = MoodyParams

        def reset(self, robot):
            if self.params.log:
                with open(self.params.log, "a") as log:
                    log.write(self.params.mood + "\\n")

        def command(self, time, estimate, reference, surroundings):
            if self.params.mood == "exit":
                os._exit(3)
            if self.params.mood == "raise":
                raise ValueError("told to raise")
            return Command()
"""


def campaign_file(folder: Path, text: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "campaign.yaml"
    path.write_text(textwrap.dedent(text).lstrip().replace("BASE", str(DEFAULT)))
    return path


@pytest.fixture(scope="module")
def twelve(tmp_path_factory) -> tuple[Path, pandas.DataFrame]:
    """The twelve-case campaign run from Python on a local cluster of two workers."""
    root = tmp_path_factory.mktemp("twelve")
    path = campaign_file(root, TWELVE_CASES)
    table = dcsim.api.run_campaign(path, root / "out", workers=2)
    assert isinstance(table, pandas.DataFrame)
    return root / "out", table


@ON_DASK
def test_campaign_results_equal_direct_runs(twelve, tmp_path):
    out, table = twelve
    campaign = load_campaign(out / "campaign.yaml")
    cases = campaign_cases(campaign, PluginRegistry.discover())
    assert len(cases) == len(table) == 12
    assert list(table["status"]) == ["completed"] * 12
    for case in cases:
        direct = tmp_path / case.name
        summary = Runner(setup_run(DEFAULT, case.overrides), direct, plots=False).run()
        recorded = out / "cases" / case.name
        for name in ("telemetry.csv", "events.jsonl", "scenario.yaml"):
            assert filecmp.cmp(recorded / name, direct / name, shallow=False), (case.index, name)
        row = table.set_index("case").loc[case.index]
        assert row["seed"] == case.seed
        assert row["delta_v_mps"] == summary["delta_v_mps"]
        assert row["localisation_rmse_m"] == summary["localisation_rmse_m"]
        manifest = json.loads((recorded / "case.json").read_text())
        assert manifest["overrides"] == list(case.overrides)
        assert manifest["dcsim_version"]


@ON_DASK
def test_results_are_written_as_tables_statistics_and_plots(twelve):
    out, table = twelve
    from_csv = pandas.read_csv(out / "results.csv")
    from_parquet = pandas.read_parquet(out / "results.parquet")
    pandas.testing.assert_frame_equal(from_parquet, table)
    assert list(from_csv.columns) == list(table.columns)
    assert "robot.initial.position[2]" in table and "controller.plugin" in table
    statistics = pandas.read_csv(out / "statistics.csv")
    assert set(statistics["controller.plugin"]) == {"pd", "elastic"}
    assert set(statistics["count"]) == {6}
    assert (out / "plots" / "metrics.png").stat().st_size > 10_000
    assert (out / "plots" / "scatter.png").stat().st_size > 10_000
    assert len(read_journal(out / "results.jsonl")) == 12


@ON_DASK
def test_rerun_repeats_a_case_bit_for_bit(twelve, tmp_path):
    out, _ = twelve
    replay = replay_case(out, 7, tmp_path / "again")
    assert replay.identical == {"telemetry.csv": True, "events.jsonl": True}
    assert replay.case.index == 7


@ON_DASK
def test_a_local_cluster_s_workers_keep_their_event_loop_off_the_case():
    import dask

    from dcsim.campaign.engine import QUIET_WORKER_SETTINGS

    with dask_client(ClusterOptions(workers=1)) as client:
        seen = client.run(lambda: {key: dask.config.get(key) for key in QUIET_WORKER_SETTINGS})
    assert list(seen.values()) == [QUIET_WORKER_SETTINGS]
    here = {key: dask.config.get(key) for key in QUIET_WORKER_SETTINGS}  # Dask's defaults
    assert all(here[key] != value for key, value in QUIET_WORKER_SETTINGS.items())


@ON_DASK
def test_a_dying_worker_loses_no_case_and_a_raising_plugin_is_a_failed_case(tmp_path, monkeypatch):
    dist = make_distribution(
        tmp_path / "dist",
        "dcsim-moody",
        "1.0",
        {"moody": MOODY_CONTROLLER},
        {"moody": "moody:MoodyController"},
    )
    monkeypatch.syspath_prepend(str(dist))  # the workers' processes inherit the path
    monkeypatch.setenv("DCSIM_LOAD_PLUGINS", "dcsim-moody")
    log = tmp_path / "attempts.log"
    path = campaign_file(
        tmp_path,
        f"""
        name: moody
        scenario: BASE
        set: {{world.duration: 2.0, task_planner.plugin: nearest, controller.plugin: moody,
               controller.params.log: {log}}}
        grid: {{controller.params.mood: [calm, exit, raise, calm, calm, calm]}}
        """,
    )
    run = run_campaign(path, tmp_path / "out", ClusterOptions(workers=2, worker_deaths=2))
    status = dict(zip(run.table["controller.params.mood"].index, run.table["status"], strict=True))
    assert status == {
        0: "completed",
        1: "failed",
        2: "failed",
        3: "completed",
        4: "completed",
        5: "completed",
    }
    reasons = list(run.table["reason"])
    assert "worker died" in reasons[1]
    assert "told to raise" in reasons[2]
    attempts = log.read_text().split()
    assert attempts.count("exit") == 2  # the scheduler's retries, then a failed case
    assert attempts.count("raise") == 1  # a raising plugin is not retried
    assert attempts.count("calm") >= 4
    cases = sorted(p.name for p in (tmp_path / "out" / "cases").iterdir())
    assert cases == ["case-000000", "case-000002", "case-000003", "case-000004", "case-000005"]


def as_from_a_terminal() -> None:
    """SIGINT delivered and handled by default in the child, as under a terminal.

    An ignored or blocked SIGINT is inherited across exec; this test process may have
    either from what ran in it before.
    """
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@ON_DASK
def test_ctrl_c_keeps_the_finished_cases_and_resume_completes_them(tmp_path):
    path = campaign_file(
        tmp_path,
        """
        name: slow
        scenario: BASE
        cases: 10
        set: {world.duration: 25.0, task_planner.plugin: nearest}
        dispersions:
          beacons.noise_sigma: {type: uniform, low: 0.02, high: 0.1}
        """,
    )
    out = tmp_path / "out"
    command = [
        str(BIN / "dcsim"),
        "campaign",
        "run",
        str(path),
        "--out",
        str(out),
        "--workers",
        "2",
    ]
    process = subprocess.Popen(
        command,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=as_from_a_terminal,
    )
    journal = out / "results.jsonl"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and len(read_journal(journal)) < 2:
        time.sleep(0.2)
    process.send_signal(signal.SIGINT)
    stdout, stderr = process.communicate(timeout=120)
    assert process.returncode == 130, stderr
    assert "dcsim campaign resume" in stderr
    kept = read_journal(journal)
    assert 2 <= len(kept) < 10
    table = pandas.read_csv(out / "results.csv")
    assert (table["status"] == "not run").sum() == 10 - len(kept)

    resumed = subprocess.run(
        [str(BIN / "dcsim"), "campaign", "resume", str(out), "--workers", "2"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert resumed.returncode == 0, resumed.stderr
    table = pandas.read_csv(out / "results.csv")
    assert list(table["status"]) == ["completed"] * 10
    assert all(kept[i] == read_journal(journal)[i] for i in kept)  # finished cases not rerun
    assert len(list((out / "cases").iterdir())) == 10


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


@ON_DASK
def test_a_campaign_runs_on_a_scheduler_and_workers_started_apart(tmp_path):
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    dask = str(BIN / "dask")
    scheduler = [dask, "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"]
    worker = [dask, "worker", address, "--nthreads", "1", "--no-dashboard"]
    processes = [subprocess.Popen(scheduler, stderr=subprocess.DEVNULL)]
    try:
        processes += [subprocess.Popen(worker, stderr=subprocess.DEVNULL) for _ in range(2)]
        path = campaign_file(
            tmp_path,
            """
            name: apart
            scenario: BASE
            cases: 4
            set: {world.duration: 3.0, task_planner.plugin: nearest}
            dispersions:
              robot.initial.position: {type: normal, sigma: 1.0}
            """,
        )
        out = tmp_path / "out"
        done = subprocess.run(
            [
                str(BIN / "dcsim"),
                "campaign",
                "run",
                str(path),
                "--out",
                str(out),
                "--scheduler",
                address,
            ],
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert done.returncode == 0, done.stderr
        assert f"on the cluster at {address}" in done.stderr
        table = pandas.read_csv(out / "results.csv")
        assert list(table["status"]) == ["completed"] * 4
    finally:
        for process in processes:
            process.terminate()
        for process in processes:
            process.wait(timeout=30)


def test_an_unreachable_scheduler_is_an_error_not_a_traceback(tmp_path, dcsim_cli):
    path = campaign_file(tmp_path, "name: c\nscenario: BASE\n")
    address = f"tcp://127.0.0.1:{free_port()}"
    done = dcsim_cli("campaign", "run", str(path), "--scheduler", address, "--connect-timeout", "1")
    assert done.returncode == 2
    assert "\nerror: cannot reach the Dask scheduler at tcp://127.0.0.1:" in done.stderr
    assert "Traceback" not in done.stderr
    assert not (tmp_path / "runs").exists()  # nothing written


def test_the_connect_timeout_is_how_long_an_unreachable_scheduler_is_waited_for():
    options = ClusterOptions(f"tcp://127.0.0.1:{free_port()}", connect_timeout=0.5)
    started = time.perf_counter()
    with pytest.raises(ClusterError, match="cannot reach the Dask scheduler"):
        with dask_client(options):
            pass
    assert time.perf_counter() - started < 5  # half a second, not the default's ten


def test_the_python_api_passes_the_connect_timeout_on(tmp_path):
    from dcsim.api import run_campaign

    path = campaign_file(tmp_path, "name: c\nscenario: BASE\n")
    address = f"tcp://127.0.0.1:{free_port()}"
    started = time.perf_counter()
    with pytest.raises(ClusterError, match="cannot reach the Dask scheduler"):
        run_campaign(path, tmp_path / "out", scheduler=address, connect_timeout=0.5)
    assert time.perf_counter() - started < 8  # not the default's ten seconds
    assert not (tmp_path / "out").exists()


def test_the_command_line_s_connect_timeout_reaches_the_cluster_options():
    from dcsim.cli.options import cluster_choice

    chosen = cluster_choice("tcp://127.0.0.1:8786", None, 3, 2.5)
    assert chosen.scheduler_wait == 2.5
    assert cluster_choice("tcp://127.0.0.1:8786", None, 3, None).scheduler_wait == 10.0


@pytest.mark.parametrize(
    ("scheduler", "timeout", "message"),
    [(None, 5.0, "is for a scheduler"), ("tcp://h:1", 0.0, "positive")],
)
def test_cluster_options_refuse_a_connect_timeout_they_cannot_use(scheduler, timeout, message):
    with pytest.raises(ValueError, match=message):
        ClusterOptions(scheduler, connect_timeout=timeout)


def test_a_connect_timeout_without_a_scheduler_is_a_usage_error(tmp_path, dcsim_cli):
    path = campaign_file(tmp_path, "name: c\nscenario: BASE\n")
    done = dcsim_cli("campaign", "run", str(path), "--connect-timeout", "5")
    assert done.returncode == 2 and "--connect-timeout is for a cluster given by" in done.stderr
    assert not (tmp_path / "runs").exists()


@ON_DASK
def test_the_campaign_bench_compares_direct_runs_with_the_engine(tmp_path):
    from dcsim.bench.campaign import bench_campaign, markdown_table

    path = campaign_file(tmp_path / "campaign", TWELVE_CASES)
    bench = bench_campaign(path, tmp_path / "bench", 2, [1], 2.0, progress=lambda line: None)
    assert bench.cases == 2 and set(bench.campaign_s) == {1}
    assert bench.same_results and min(bench.direct_s) > 0
    results = tmp_path / "bench" / "workers-1" / "results.csv"
    # the bench holds the floats as written; pandas parses them exactly only when told
    table = pandas.read_csv(results, float_precision="round_trip")
    assert bench.worker_case_s == list(table.sort_values("case")["case_wall_time_s"])
    assert 0 < sum(bench.worker_case_s) < bench.campaign_s[1]
    direct = [(a + b) / 2 for a, b in zip(*bench.direct_case_s, strict=True)]
    ratios = [w / d for w, d in zip(bench.worker_case_s, direct, strict=True)]
    assert bench.case_overhead() == pytest.approx(sum(ratios) / 2 - 1)  # two cases: the mean
    text = markdown_table(bench)
    assert "| campaign, 1 worker |" in text and "(after the campaigns)" in text
    for folder in ("direct", "direct-again"):
        assert len(list((tmp_path / "bench" / folder).iterdir())) == 2
