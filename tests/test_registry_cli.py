"""Plugin discovery through entry points, seen from the command line.

Each test installs a throw-away distribution (modules plus a dist-info with a ``dcsim``
entry point) on PYTHONPATH, so discovery goes through importlib.metadata for real.
"""

from __future__ import annotations

import json

from tests.conftest import GOOD_PLUGIN, make_distribution


def _names(result) -> set[tuple[str, str, str]]:
    return {(e["kind"], e["name"], e["distribution"]) for e in json.loads(result.stdout)}


def test_external_plugin_is_listed_with_its_distribution(dcsim_cli, good_plugin_dist):
    result = dcsim_cli("plugins", "--json", extra_path=[good_plugin_dist])
    assert result.returncode == 0, result.stderr
    entry = next(e for e in json.loads(result.stdout) if e["name"] == "hold")
    assert (entry["kind"], entry["distribution"], entry["version"]) == (
        "controller",
        "dcsim-hold",
        "1.2.3",
    )
    table = dcsim_cli("plugins", extra_path=[good_plugin_dist]).stdout
    assert any(
        line.split()[:2] == ["controller", "hold"] and line.endswith("dcsim-hold 1.2.3")
        for line in table.splitlines()
    )


def test_external_plugin_runs_in_a_scenario(dcsim_cli, good_plugin_dist, tmp_path):
    result = dcsim_cli(
        "run",
        "--out",
        str(tmp_path / "hold"),
        "--set",
        "controller.plugin=hold",
        "--set",
        "world.duration=2",
        extra_path=[good_plugin_dist],
    )
    assert result.returncode == 0, result.stderr
    summary = json.loads((tmp_path / "hold" / "summary.json").read_text())
    assert summary["plugins"]["controller"] == {
        "name": "hold",
        "distribution": "dcsim-hold",
        "version": "1.2.3",
    }


def test_load_plugins_env_restricts_external_plugins(dcsim_cli, good_plugin_dist):
    only_builtin = dcsim_cli(
        "plugins", "--json", extra_path=[good_plugin_dist], env={"DCSIM_LOAD_PLUGINS": ""}
    )
    assert ("controller", "hold", "dcsim-hold") not in _names(only_builtin)
    assert ("controller", "pd", "dcsim") in _names(only_builtin)
    other = dcsim_cli(
        "plugins",
        "--json",
        extra_path=[good_plugin_dist],
        env={"DCSIM_LOAD_PLUGINS": "something-else"},
    )
    assert ("controller", "hold", "dcsim-hold") not in _names(other)
    chosen = dcsim_cli(
        "plugins",
        "--json",
        extra_path=[good_plugin_dist],
        env={"DCSIM_LOAD_PLUGINS": "dcsim_hold, other"},
    )
    assert ("controller", "hold", "dcsim-hold") in _names(chosen)


def test_plugin_that_fails_to_import_warns_and_others_still_load(
    dcsim_cli, tmp_path, good_plugin_dist
):
    broken = make_distribution(
        tmp_path / "site_broken",
        "dcsim-broken",
        "0.1",
        {"dcsim_broken": "import not_a_module_anywhere\n"},
        {"broken": "dcsim_broken"},
    )
    result = dcsim_cli("plugins", "--json", extra_path=[broken, good_plugin_dist])
    assert result.returncode == 0
    assert "warning: plugin package dcsim-broken" in result.stderr
    assert "ModuleNotFoundError" in result.stderr and "not_a_module_anywhere" in result.stderr
    assert {("controller", "hold", "dcsim-hold"), ("controller", "pd", "dcsim")} <= _names(result)


def test_plugin_missing_an_interface_method_is_rejected_naming_it(dcsim_cli, tmp_path):
    source = GOOD_PLUGIN.replace("def reset(self, robot):", "def _reset(self, robot):")
    dist = make_distribution(
        tmp_path / "site_half", "dcsim-half", "0.1", {"dcsim_half": source}, {"half": "dcsim_half"}
    )
    result = dcsim_cli("plugins", "--json", extra_path=[dist])
    assert result.returncode == 0
    assert "plugin 'hold'" in result.stderr and "does not implement reset()" in result.stderr
    assert ("controller", "hold", "dcsim-half") not in _names(result)
    run = dcsim_cli("run", "--set", "controller.plugin=hold", extra_path=[dist])
    assert run.returncode == 2 and "no controller plugin named 'hold'" in run.stderr


def test_two_plugins_with_one_name_name_both_origins(dcsim_cli, tmp_path, good_plugin_dist):
    twin = make_distribution(
        tmp_path / "site_twin",
        "dcsim-twin",
        "2.0",
        {"dcsim_twin": GOOD_PLUGIN},
        {"twin": "dcsim_twin"},
    )
    listing = dcsim_cli("plugins", extra_path=[good_plugin_dist, twin])
    assert listing.returncode == 0
    assert "two plugins register the controller name 'hold'" in listing.stderr
    run = dcsim_cli("run", "--set", "controller.plugin=hold", extra_path=[good_plugin_dist, twin])
    assert run.returncode == 2
    assert "dcsim-hold 1.2.3" in run.stderr and "dcsim-twin 2.0" in run.stderr
    assert "Traceback" not in run.stderr
