"""Packaging: every package is listed, and a wheel installs and runs on its own."""

from __future__ import annotations

import tomllib
import zipfile

from tests.conftest import REPO


def _source_packages() -> set[str]:
    config = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]
    found = set()
    for name, directory in config["package-dir"].items():
        for init in (REPO / directory).rglob("__init__.py"):
            relative = init.parent.relative_to(REPO / directory)
            found.add(".".join([name, *relative.parts]))
    return found


def test_every_package_directory_is_listed_in_pyproject():
    config = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]
    assert set(config["packages"]) == _source_packages()


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
        and "dcsim = dcsim.cli:main" in entry_points
    )


def test_wheel_installs_into_a_fresh_environment_and_runs(fresh_env, tmp_path):
    run = fresh_env.run("dcsim", "run", "--out", "out", "--set", "world.duration=5", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert run.stdout.startswith("default seed 0: completed (duration reached)")
    assert (tmp_path / "out" / "scenario.yaml").is_file()
    assert (tmp_path / "out" / "plots" / "trajectory.png").is_file()
    listing = fresh_env.run("dcsim", "plugins", cwd=tmp_path)
    assert "straight-line" in listing.stdout and listing.stderr == ""
