"""Third-party sensor models and trackers, written by ``dcsim new-plugin`` and installed by
pip as distributions of their own: they register in their kinds' groups, pass their
conformance suites as written, and a sensor model is flown in a run, its readings
reaching the observations."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from dcsim.api import (
    PluginRegistry,
    close_run,
    open_run,
    quaternion_conjugate,
    quaternion_multiply,
    rotation_vector,
)
from dcsim.registry.scaffold import new_plugin
from dcsim.testing import checks_for

NOISE = 60.0
"""The star tracker's noise in the run, arcsec (1 sigma per axis)."""


def install(root, site) -> None:
    """``pip install`` the package at ``root`` into the folder ``site``."""
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "install",
            "--quiet",
            "--no-deps",
            "--target",
            str(site),
            str(root),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr


@pytest.mark.parametrize("kind", ["sensor", "tracker"])
def test_a_scaffolded_package_installs_registers_and_passes_its_tests_as_written(kind, tmp_path):
    name = f"own-{kind}"
    root = new_plugin(kind, name, tmp_path)
    site = tmp_path / "site"
    install(root, site)
    environment = {**os.environ, "PYTHONPATH": str(site)}
    listed = subprocess.run(
        [sys.executable, "-m", "dcsim", "plugins", "--json", "--kind", kind],
        capture_output=True,
        text=True,
        env=environment,
        timeout=120,
    )
    assert listed.returncode == 0, listed.stderr
    assert f'"distribution": "dcsim-{name}"' in listed.stdout
    # the package's own tests, as written, against the installed package
    tested = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", str(root / "tests")],
        capture_output=True,
        text=True,
        env=environment,
        cwd=tmp_path,
        timeout=300,
    )
    assert tested.returncode == 0, tested.stdout
    assert f"{len(checks_for(kind))} passed" in tested.stdout


def turn_between(a: np.ndarray, b: np.ndarray) -> float:
    """Angle of the rotation from attitude ``b`` to ``a``, rad."""
    return float(np.linalg.norm(rotation_vector(quaternion_multiply(a, quaternion_conjugate(b)))))


def test_a_scaffolded_sensor_model_installed_as_a_distribution_is_flown(tmp_path, monkeypatch):
    install(new_plugin("sensor", "blurry-star", tmp_path), tmp_path / "site")
    monkeypatch.syspath_prepend(str(tmp_path / "site"))
    registry = PluginRegistry.discover()
    assert registry.get("sensor", "blurry-star").origin.distribution == "dcsim-blurry-star"
    star_tracker = {"model": "blurry-star", "params": {"noise": NOISE, "rate": 2.0}}
    runner = open_run(
        None,
        {"world.duration": 2.0, "sensors.star_tracker": star_tracker},
        tmp_path / "run",
        plots=False,
        registry=registry,
    )
    try:
        model = runner.world.sensing.models["star_tracker"]
        assert type(model).__module__ == "dcsim_blurry_star"
        seen = []
        while not runner.ended:
            seen.append((runner.world.time, runner.estimate.attitude, runner.outputs["attitude"]))
            runner.advance()
    finally:
        sys.modules.pop("dcsim_blurry_star", None)
        close_run(runner)
    sigma = np.radians(NOISE / 3600.0)
    measured_at = {round(time, 9): measured for time, measured, _ in seen}
    for time, measured, truth in seen:
        reading = np.floor(time / 0.5 + 1e-9) * 0.5  # readings at 2 Hz, from t = 0
        if abs(time - reading) < 1e-9:  # a reading now: the true attitude, off by the noise
            assert 0.0 < turn_between(measured, truth) < 6.0 * sigma, time
        else:  # between readings the latest one is held
            np.testing.assert_array_equal(measured, measured_at[round(reading, 9)])
    assert len({tuple(m) for _, m, _ in seen}) == 4  # t = 0, 0.5, 1 and 1.5 s
