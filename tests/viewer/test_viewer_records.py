"""The viewer reads run directories: either style of telemetry header, cut lines, bad folders."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from dcsim.report.viewer.records import ViewError, plain_name, read_run, read_table
from tests.conftest import REPO

PLAIN = "time,x,y,z,mode,fuel_used,nearest_obstacle\n0.0,1.5,2.0,3.0,LOCALIZE,0.0,inf\n0.1,1.6,2.1,3.2,GRAB,0.01,4.5\n"
SUFFIXED = "time_s,x_m,y_m,z_m,mode,fuel_used_kg,nearest_obstacle [m]\n0.0,1.5,2.0,3.0,LOCALIZE,0.0,inf\n0.1,1.6,2.1,3.2,GRAB,0.01,4.5\n"


@pytest.mark.parametrize(
    "column, name",
    [
        ("x_m", "x"),
        ("time_s", "time"),
        ("est_vx_mps", "est_vx"),
        ("fuel_used_kg", "fuel_used"),
        ("joint_3_rad", "joint_3"),
        ("tx_Nm", "tx"),
        ("det_jjt_m6", "det_jjt"),
        ("hx_Nms", "hx"),
        ("est_sigma_x_m", "est_sigma_x"),
        ("wx_radps", "wx"),
        ("delta_v [m/s]", "delta_v"),
        ("x", "x"),
        ("joint_3", "joint_3"),
        ("mode", "mode"),
        ("nearest_obstacle", "nearest_obstacle"),
    ],
)
def test_a_unit_suffix_is_taken_off_a_column_name(column, name):
    assert plain_name(column) == name


def test_a_table_reads_the_same_with_or_without_unit_suffixes(tmp_path):
    (tmp_path / "plain.csv").write_text(PLAIN)
    (tmp_path / "suffixed.csv").write_text(SUFFIXED)
    plain, suffixed = read_table(tmp_path / "plain.csv"), read_table(tmp_path / "suffixed.csv")
    assert list(plain) == list(suffixed) == [
        "time", "x", "y", "z", "mode", "fuel_used", "nearest_obstacle"
    ]  # fmt: skip
    for name in plain:
        np.testing.assert_array_equal(plain[name], suffixed[name])
    assert plain["mode"].tolist() == ["LOCALIZE", "GRAB"]
    assert plain["nearest_obstacle"][0] == np.inf


def test_a_last_line_cut_short_is_left_out(tmp_path):
    (tmp_path / "cut.csv").write_text(PLAIN + "0.2,1.7,2.")
    table = read_table(tmp_path / "cut.csv")
    assert table["time"].tolist() == [0.0, 0.1]


@pytest.fixture
def tiny_run(tmp_path):
    """A run directory of two rows of the default scenario's telemetry."""
    run = tmp_path / "run"
    run.mkdir()
    shutil.copy(REPO / "scenarios" / "default.yaml", run / "scenario.yaml")
    (run / "telemetry.csv").write_text(PLAIN)
    return run


def test_a_run_directory_reads_with_events_cut_short(tiny_run):
    (tiny_run / "events.jsonl").write_text(
        '{"t": 0.0, "event": "plan", "tasks": [], "drops": [], "cost": 0.0}\n{"t": 0.1, "ev'
    )
    records = read_run(tiny_run)
    assert records.scenario.name == "default"
    assert [e["event"] for e in records.events] == ["plan"]
    assert records.summary == {}
    assert records.planned.shape == (0, 3)


@pytest.mark.parametrize(
    "change, message",
    [
        (lambda run: shutil.rmtree(run), "is not a run directory: no such folder"),
        (lambda run: (run / "scenario.yaml").unlink(), "it has no scenario.yaml"),
        (lambda run: (run / "telemetry.csv").unlink(), "it has no telemetry.csv"),
        (lambda run: (run / "telemetry.csv").write_text("time,x,y,z\n"), "has no rows yet"),
        (lambda run: (run / "telemetry.csv").write_text("time,a\n0,1\n"), "has no column x, y, z"),
        (lambda run: (run / "telemetry.csv").write_text(""), "cannot read"),
        (
            lambda run: (run / "scenario.yaml").write_text("world: 3\n"),
            "cannot read the run's scenario",
        ),
    ],
)
def test_what_is_not_a_readable_run_directory_is_a_view_error(tiny_run, change, message):
    change(tiny_run)
    with pytest.raises(ViewError, match=message):
        read_run(tiny_run)
