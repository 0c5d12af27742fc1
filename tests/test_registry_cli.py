"""Plugin discovery through entry points, seen from the command line.

Each test installs a throw-away distribution (modules plus a dist-info with an entry
point in ``dcsim`` or a kind's group) on PYTHONPATH, so discovery goes through
importlib.metadata for real.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

from tests.conftest import GOOD_PLUGIN, CliResult, make_distribution


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


IMPORTED_AFTER_CLI = """
import sys
from dcsim.cli.main import cli
try:
    cli.main(sys.argv[1:], prog_name="dcsim")
except SystemExit:
    pass
plugins = (m for m in sys.modules if m.startswith("dcsim_plugins.") or m == "dcsim_hold")
print("imported:", *sorted(plugins), file=sys.stderr)
"""


def _imported_by(args: list[str], extra_path: list) -> tuple[CliResult, list[str]]:
    """Run ``dcsim ARGS`` in a fresh interpreter; its result and the plugin modules it
    imported (dcsim's built-ins and the ``dcsim_hold`` test plugin)."""
    environment = {k: v for k, v in os.environ.items() if k != "DCSIM_LOAD_PLUGINS"}
    environment["PYTHONPATH"] = os.pathsep.join(str(p) for p in extra_path)
    done = subprocess.run(
        [sys.executable, "-c", IMPORTED_AFTER_CLI, *args],
        capture_output=True,
        text=True,
        env=environment,
        timeout=120,
    )
    *stderr, last = done.stderr.splitlines()
    assert last.startswith("imported:"), done.stderr
    return CliResult(done.returncode, done.stdout, "\n".join(stderr)), last.split()[1:]


def _kind_group_plugin(root, modules=None):
    """``dcsim-hold`` declaring its ``hold`` controller in ``dcsim.controllers``."""
    return make_distribution(
        root,
        "dcsim-hold",
        "1.2.3",
        modules or {"dcsim_hold": GOOD_PLUGIN},
        {"hold": "dcsim_hold"},
        group="dcsim.controllers",
    )


def test_help_and_the_listing_import_no_plugin_and_plugins_name_imports_only_it(tmp_path):
    dist = _kind_group_plugin(tmp_path / "site")
    for args in (["--help"], ["plugins"], ["plugins", "--kind", "controller"]):
        result, imported = _imported_by(args, [dist])
        assert result.returncode == 0, result.stderr
        assert imported == [], args
    listing, imported = _imported_by(["plugins", "--json"], [dist])
    assert imported == []
    assert {("controller", "hold", "dcsim-hold"), ("controller", "pd", "dcsim")} <= _names(listing)
    shown, imported = _imported_by(["plugins", "pd"], [dist])
    assert shown.stdout.startswith("controller pd: ")
    assert imported == [  # pd and the attitude loop it shares with elastic
        "dcsim_plugins.controllers",
        "dcsim_plugins.controllers.attitude",
        "dcsim_plugins.controllers.pd",
    ]
    held, imported = _imported_by(["plugins", "hold"], [dist])
    assert held.stdout.startswith("controller hold: Damps the velocity to zero")
    assert imported == ["dcsim_hold"]


def test_a_plugin_that_fails_to_import_is_listed_and_reported_when_used(dcsim_cli, tmp_path):
    broken = _kind_group_plugin(tmp_path / "site", {"dcsim_hold": "import not_a_module_anywhere\n"})
    listing = dcsim_cli("plugins", "--json", extra_path=[broken])
    assert listing.returncode == 0 and "warning" not in listing.stderr
    assert ("controller", "hold", "dcsim-hold") in _names(listing)
    message = (
        "controller plugin 'hold' of dcsim-hold 1.2.3 (hold = dcsim_hold) failed to import: "
        "ModuleNotFoundError: No module named 'not_a_module_anywhere'"
    )
    for args in (["plugins", "hold"], ["run", "--set", "controller.plugin=hold"]):
        used = dcsim_cli(*args, extra_path=[broken])
        assert used.returncode == 2, used.stderr
        assert message in used.stderr and "Traceback" not in used.stderr
    other = dcsim_cli("run", "--set", "world.duration=1", "--out", "run", extra_path=[broken])
    assert other.returncode == 0, other.stderr


RUN_END_HOOK = """
    import os
    from pathlib import Path


    @hookimpl
    def dcsim_run_end(run, summary):
        Path(os.environ["HOLD_SAW"]).write_text(summary["outcome"])
"""


def test_the_hooks_of_the_plugins_a_run_uses_fire(dcsim_cli, tmp_path):
    source = GOOD_PLUGIN + RUN_END_HOOK
    dist = _kind_group_plugin(tmp_path / "site", {"dcsim_hold": source})
    saw = tmp_path / "saw.txt"
    common = ("--set", "world.duration=2")
    unused = dcsim_cli("run", *common, "--out", "a", extra_path=[dist], env={"HOLD_SAW": str(saw)})
    assert unused.returncode == 0, unused.stderr
    assert not saw.exists()  # a run that does not use the plugin does not import it
    used = dcsim_cli(
        "run",
        *common,
        "--set",
        "controller.plugin=hold",
        "--out",
        "b",
        extra_path=[dist],
        env={"HOLD_SAW": str(saw)},
    )
    assert used.returncode == 0, used.stderr
    assert saw.read_text() == json.loads((tmp_path / "b" / "summary.json").read_text())["outcome"]
