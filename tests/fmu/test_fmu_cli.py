"""`dcsim fmu export` and `dcsim fmu cosim` from the console script."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
from fmpy.validation import validate_fmu

from dcsim.fmu.cosim import output_units, plot_panels


def test_export_writes_a_valid_fmu_of_either_kind(dcsim_cli, tmp_path):
    for args, name in (([], "closed.fmu"), (["--plant-only", "--beacons", "2"], "plant.fmu")):
        done = dcsim_cli("fmu", "export", "-o", str(tmp_path / name), *args)
        assert done.returncode == 0, done.stderr
        assert validate_fmu(str(tmp_path / name)) == []


def test_export_takes_a_manipulator_scenario(dcsim_cli, tmp_path):
    reach = Path(__file__).resolve().parents[2] / "scenarios" / "space_manipulator_reach.yaml"
    done = dcsim_cli("fmu", "export", str(reach), "--plant-only", "-o", str(tmp_path / "arm.fmu"))
    assert done.returncode == 0, done.stderr
    assert validate_fmu(str(tmp_path / "arm.fmu")) == []


def test_export_reports_a_bad_override_or_name_without_a_traceback(dcsim_cli, tmp_path):
    done = dcsim_cli("fmu", "export", "-o", str(tmp_path / "x.fmu"), "--set", "robot.mass=-1")
    assert done.returncode == 2 and "robot.mass" in done.stderr
    assert "Traceback" not in done.stderr
    done = dcsim_cli("fmu", "export", "-o", str(tmp_path / "x.zip"))
    assert done.returncode == 2 and ".fmu" in done.stderr
    assert not list(tmp_path.glob("x.*"))


def test_cosim_flies_the_plant_to_the_controllers_reference(dcsim_cli, tmp_path, plant_fmu, pd_fmu):
    done = dcsim_cli(
        "fmu", "cosim", str(plant_fmu), "--controller", str(pd_fmu), "--stop", "80",
        "--set", "controller:reference.position.x=5",
        "--set", "controller:reference.position.y=-3",
        "--out", str(tmp_path / "out"),
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "connected to the plant: force.x, force.y, force.z" in done.stdout
    with (tmp_path / "out" / "results.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 801 and float(rows[-1]["time"]) == 80.0
    final = np.array([float(rows[-1][f"plant.position.{a}"]) for a in "xyz"])
    assert np.allclose(final, [5.0, -3.0, 0.0], atol=0.01)
    assert (tmp_path / "out" / "results.png").stat().st_size > 10_000


def test_cosim_refuses_fmus_that_share_no_signal(dcsim_cli, tmp_path, plant_fmu):
    done = dcsim_cli("fmu", "cosim", str(plant_fmu), "--controller", str(plant_fmu))
    assert done.returncode == 2 and "share no signal" in done.stderr
    done = dcsim_cli("fmu", "cosim", str(plant_fmu), "--controller", str(plant_fmu),
                     "--set", "nowhere=1")  # fmt: skip
    assert done.returncode == 2 and "plant:NAME=VALUE" in done.stderr


def test_cosim_plot_gives_the_controller_outputs_the_unit_of_the_input_they_feed(plant_fmu, pd_fmu):
    units = output_units(plant_fmu, pd_fmu)
    assert units["plant.position.x"] == "m" and units["plant.velocity.z"] == "m/s"
    assert units["controller.force.x"] == "N"  # the PD's own description gives none
    time = np.zeros(2)
    results = {"time": time, **{name: time for name in ["plant.position.x", "controller.force.x"]}}
    results["controller.gain"] = time  # an output of no known unit
    labels = [label for label, _, _ in plot_panels(results, units)]
    assert labels == [
        "plant position, m",
        "plant velocity, m/s",
        "controller outputs, N",
        "controller outputs (no unit given)",
    ]
