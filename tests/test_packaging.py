"""Packaging: every package is listed, and a wheel installs and runs on its own."""

from __future__ import annotations

import configparser
import re
import zipfile
from pathlib import Path

from tests.conftest import REPO, SHARES_WHEEL


def _setuptools_options() -> configparser.SectionProxy:
    config = configparser.ConfigParser()
    config.read(REPO / "setup.cfg")
    return config["options"]


def _package_dirs() -> dict[str, Path]:
    """Each top-level package's source directory, from setup.cfg's package_dir."""
    pairs = [line.split("=") for line in _setuptools_options()["package_dir"].split("\n") if line]
    return {name.strip(): REPO / directory.strip() for name, directory in pairs}


def _source_files() -> set[str]:
    """Every file under the package directories, as its path inside an installation."""
    return {
        "/".join([name, *path.relative_to(directory).parts])
        for name, directory in _package_dirs().items()
        for path in directory.rglob("*")
        if path.is_file() and "__pycache__" not in path.parts
    }


def _source_packages() -> set[str]:
    """Every directory holding files under the package directories.

    Python imports each of them, a directory of data files as a namespace package, and
    setuptools warns about any left out of ``packages``.
    """
    found = set()
    for installed in _source_files():
        parts = installed.split("/")[:-1]
        found.update(".".join(parts[:n]) for n in range(1, len(parts) + 1))
    return found


def test_every_package_directory_is_listed_in_setup_cfg():
    assert set(_setuptools_options()["packages"].split()) == _source_packages()


@SHARES_WHEEL
def test_the_wheel_builds_without_a_warning(wheel_build):
    assert not re.findall(r"\w*Warning: .*", wheel_build.output)


@SHARES_WHEEL
def test_wheel_carries_every_module_and_data_file(wheel):
    with zipfile.ZipFile(wheel) as archive:
        names = set(archive.namelist())
    assert _source_files() - names == set()


@SHARES_WHEEL
def test_wheel_carries_the_default_scenario_plugins_and_entry_points(wheel):
    with zipfile.ZipFile(wheel) as archive:
        names = set(archive.namelist())
        entry_points = next(
            archive.read(n).decode() for n in names if n.endswith("entry_points.txt")
        )
    assert "dcsim/scenarios/default.yaml" in names
    assert {"dcsim_plugins/controllers/pd.py", "dcsim_plugins/task_planners/nearest.py"} <= names
    assert not any(n.startswith("plugins/") for n in names)
    assert (
        "pd = dcsim_plugins.controllers.pd" in entry_points
        and "dcsim = dcsim.cli.main:main" in entry_points
    )


@SHARES_WHEEL
def test_wheel_installs_into_a_fresh_environment_and_runs(fresh_env, tmp_path):
    run = fresh_env.run("dcsim", "run", "--out", "out", "--set", "world.duration=5", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert run.stdout.startswith("default seed 0: completed (duration reached)")
    assert (tmp_path / "out" / "scenario.yaml").is_file()
    assert (tmp_path / "out" / "plots" / "trajectory.png").is_file()
    listing = fresh_env.run("dcsim", "plugins", cwd=tmp_path)
    assert "straight-line" in listing.stdout and listing.stderr == ""
