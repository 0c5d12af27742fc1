"""The whole path a stranger takes: install a plugin package, list it, fly it, check it."""

from __future__ import annotations

import json
import shutil

from dcsim_plugins.controllers.pd import PDController

from dcsim.testing import checks_for
from tests.conftest import REPO, SHARES_WHEEL

EXAMPLE = REPO / "docs" / "examples" / "dcsim-lqr"

pytestmark = SHARES_WHEEL

FREE_FLYER_CONTROLLER_CHECKS = checks_for("controller", PDController)
"""The checks a controller for the free flyer gets (manipulator-only checks are skipped)."""


def test_example_plugin_installs_lists_flies_and_conforms(fresh_env, tmp_path):
    # A copy, so that building it leaves no build/ or egg-info in the checkout.
    example = shutil.copytree(EXAMPLE, tmp_path / "dcsim-lqr")
    installed = fresh_env.run(
        "python", "-m", "pip", "install", "--quiet", str(example), cwd=tmp_path
    )
    assert installed.returncode == 0, installed.stderr
    listing = json.loads(fresh_env.run("dcsim", "plugins", "--json", cwd=tmp_path).stdout)
    lqr = next(entry for entry in listing if entry["name"] == "lqr")
    assert (lqr["kind"], lqr["distribution"], lqr["version"]) == (
        "controller",
        "dcsim-lqr",
        "1.0.0",
    )
    flown = fresh_env.run(
        "dcsim", "run", "--out", "run", "--set", "controller.plugin=lqr", cwd=tmp_path
    )
    assert flown.returncode == 0, flown.stderr
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["plugins"]["controller"]["distribution"] == "dcsim-lqr"
    assert summary["delivered"] == summary["targets"] and summary["collisions"] == 0
    checked = fresh_env.run(
        "python",
        "-m",
        "pytest",
        "-q",
        "-p",
        "no:cacheprovider",
        "--dcsim-plugin",
        "controller:lqr",
        cwd=tmp_path,
    )
    assert checked.returncode == 0, checked.stdout
    assert f"{len(FREE_FLYER_CONTROLLER_CHECKS)} passed" in checked.stdout
    own_tests = fresh_env.run(
        "python",
        "-m",
        "pytest",
        "-q",
        "-p",
        "no:cacheprovider",
        str(EXAMPLE / "tests"),
        cwd=tmp_path,
    )
    assert own_tests.returncode == 0, own_tests.stdout


def test_scaffolded_plugin_installs_editable_and_passes_as_generated(fresh_env, tmp_path):
    made = fresh_env.run(
        "dcsim", "new-plugin", "controller", "gentle", "--dir", str(tmp_path), cwd=tmp_path
    )
    assert made.returncode == 0, made.stderr
    root = tmp_path / "dcsim-gentle"
    assert {p.name for p in root.iterdir()} >= {
        "pyproject.toml",
        "README.md",
        "dcsim_gentle",
        "tests",
    }
    installed = fresh_env.run(
        "python", "-m", "pip", "install", "--quiet", "-e", str(root), cwd=tmp_path
    )
    assert installed.returncode == 0, installed.stderr
    listing = json.loads(
        fresh_env.run("dcsim", "plugins", "--json", "--kind", "controller", cwd=tmp_path).stdout
    )
    assert {"gentle", "pd"} <= {entry["name"] for entry in listing}
    tested = fresh_env.run("python", "-m", "pytest", "-q", "-p", "no:cacheprovider", cwd=root)
    assert tested.returncode == 0, tested.stdout
    assert f"{len(FREE_FLYER_CONTROLLER_CHECKS)} passed" in tested.stdout
    again = fresh_env.run(
        "dcsim", "new-plugin", "controller", "gentle", "--dir", str(tmp_path), cwd=tmp_path
    )
    assert again.returncode == 2 and "already named 'gentle'" in again.stderr
