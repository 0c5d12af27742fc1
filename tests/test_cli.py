"""The dcsim command through its real console entry point."""

from __future__ import annotations

import json
import re

import click
import pytest
import yaml

from dcsim import __version__
from tests.conftest import REPO


def test_version(dcsim_cli):
    result = dcsim_cli("--version")
    assert result.returncode == 0
    assert __version__ in result.stdout


def test_help_lists_commands(dcsim_cli):
    result = dcsim_cli("--help")
    assert result.returncode == 0
    for command in ("plugins", "validate", "run", "view"):
        assert command in result.stdout


@pytest.mark.parametrize(
    "command, options",
    [
        ("plugins", ["--kind", "--json", "NAME"]),
        ("validate", ["FILES"]),
        ("run", ["--out", "--force", "--seed", "--set", "--view", "SCENARIO"]),
        ("view", ["RUN_DIR", "--out", "--max-frames"]),
    ],
)
def test_command_help_explains_every_option(dcsim_cli, command, options):
    result = dcsim_cli(command, "--help")
    assert result.returncode == 0
    for option in options:
        assert option in result.stdout


def test_plugins_table_lists_builtins_with_origin(dcsim_cli):
    result = dcsim_cli("plugins")
    assert result.returncode == 0
    lines = result.stdout.splitlines()
    assert lines[0].split() == ["KIND", "NAME", "ORIGIN"]
    for kind, name in [
        ("localiser", "trilateration"),
        ("task_planner", "nearest"),
        ("path_planner", "straight-line"),
        ("controller", "pd"),
    ]:
        row = next(line for line in lines if line.split()[:2] == [kind, name])
        assert row.rstrip().endswith(f"dcsim {__version__}")


def test_plugins_json_and_kind_filter(dcsim_cli):
    result = dcsim_cli("plugins", "--json", "--kind", "controller")
    assert result.returncode == 0
    entries = json.loads(result.stdout)
    assert [e["name"] for e in entries] == [
        "capture-detumble",
        "computed-torque",
        "elastic",
        "fmu",
        "pd",
        "underactuated",
    ]
    assert entries[0]["kind"] == "controller"
    assert entries[0]["distribution"] == "dcsim"
    assert (
        entries[0]["entry_point"] == "capture-detumble = dcsim_plugins.controllers.capture_detumble"
    )


def test_plugins_rejects_unknown_kind(dcsim_cli):
    result = dcsim_cli("plugins", "--kind", "teleporter")
    assert result.returncode == 2
    assert "Traceback" not in result.stderr


def test_plugins_name_prints_every_parameter_with_default_unit_and_bounds(dcsim_cli):
    result = dcsim_cli("plugins", "pd")
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[0].startswith("controller pd: PD tracking")
    assert lines[1].startswith(f"origin: dcsim {__version__}") and lines[2] == "robots: free-flyer"
    assert lines[4].split()[:5] == ["PARAMETER", "DEFAULT", "UNIT", "BOUNDS", "DESCRIPTION"]
    assert lines[5].split()[:4] == ["bandwidth", "0.2", "rad/s", ">"]
    assert "> 0, <= 5  Damping ratio" in lines[6]


def test_plugins_name_as_json_gives_defaults_choices_and_required_values(dcsim_cli):
    (ekf,) = json.loads(dcsim_cli("plugins", "ekf", "--json").stdout)
    initialise = next(p for p in ekf["parameters"] if p["name"] == "initialise")
    assert initialise["bounds"] == "one of: fix, prior" and initialise["default"] == "fix"
    (fmu,) = json.loads(dcsim_cli("plugins", "fmu", "--kind", "controller", "--json").stdout)
    path = fmu["parameters"][0]
    assert (path["name"], path["required"], path["default"]) == ("path", True, None)
    assert fmu["robots"] == ["free-flyer"] and fmu["distribution"] == "dcsim"


@pytest.mark.parametrize(
    "args, message",
    [
        (["ekff"], "error: no plugin named 'ekff' (see dcsim plugins); did you mean 'ekf'?"),
        (["pd", "--kind", "localiser"], "error: no localiser plugin named 'pd' (available: ekf"),
    ],
)
def test_plugins_name_that_is_not_installed_is_a_user_error(dcsim_cli, args, message):
    result = dcsim_cli("plugins", *args)
    assert result.returncode == 2 and result.stderr.startswith(message)
    assert "Traceback" not in result.stderr


def test_new_plugin_refuses_the_name_of_an_installed_plugin_of_its_kind(dcsim_cli, tmp_path):
    result = dcsim_cli("new-plugin", "controller", "pd", "--dir", str(tmp_path))
    assert result.returncode == 2
    assert result.stderr.startswith(
        "error: an installed controller plugin is already named 'pd' (dcsim "
    )
    assert "Traceback" not in result.stderr and not (tmp_path / "dcsim-pd").exists()
    other_kind = dcsim_cli("new-plugin", "localiser", "pd", "--dir", str(tmp_path))
    assert other_kind.returncode == 0, other_kind.stderr


def test_validate_prints_ok_per_file(dcsim_cli):
    files = [
        str(REPO / "scenarios" / "default.yaml"),
        str(REPO / "scenarios" / "thesis_debris_field.yaml"),
    ]
    result = dcsim_cli("validate", *files)
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines() == [f"ok {f}" for f in files]


def test_validate_reports_each_problem_with_line_and_path(dcsim_cli, tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("world:\n  seed: -4\nrobot:\n  mass: 100\n  capcity: 2\n")
    good = REPO / "scenarios" / "default.yaml"
    result = dcsim_cli("validate", str(bad), str(good))
    assert result.returncode == 2
    assert f"ok {good}" in result.stdout
    assert f"{bad}:2:3: world.seed: -4 is not allowed" in result.stderr
    assert f"{bad}:5:3: robot.capcity: unknown key" in result.stderr
    assert result.stderr.startswith("error: ")
    assert "Traceback" not in result.stderr


def test_run_default_writes_a_run_directory_and_prints_a_summary(dcsim_cli, tmp_path):
    result = dcsim_cli("run", "--set", "world.duration=3")
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("default seed 0: completed (duration reached)")
    (run_dir,) = (tmp_path / "runs").glob("default-*")
    assert f"results in runs/{run_dir.name}" in result.stdout
    assert (
        f"  sensors: beacon_ranges beacon-range (dcsim {__version__})\n"
        f"  plugins: localiser ekf (dcsim {__version__}), task_planner ga (dcsim {__version__}), "
        f"path_planner straight-line (dcsim {__version__}), controller pd (dcsim {__version__})\n"
    ) in result.stdout
    names = {p.name for p in run_dir.iterdir()}
    assert {"scenario.yaml", "telemetry.csv", "events.jsonl", "summary.json", "plots"} <= names
    resolved = yaml.safe_load((run_dir / "scenario.yaml").read_text())
    assert resolved["controller"]["params"]["bandwidth"] > 0  # defaults filled in
    summary = json.loads((run_dir / "summary.json").read_text())
    assert summary["plugins"]["localiser"]["name"] == "ekf"
    assert summary["sim_time_s"] == pytest.approx(3.0)
    assert result.stderr == ""  # no progress bar when piped, no PyBullet banner


def test_run_writes_resolved_scenario_with_seed_and_overrides(dcsim_cli, tmp_path):
    out = tmp_path / "run1"
    result = dcsim_cli(
        "run",
        str(REPO / "scenarios" / "thesis_debris_field.yaml"),
        "--out",
        str(out),
        "--seed",
        "7",
        "--set",
        "robot.max_force=123.5",
        "--set",
        "controller.params.response_time=12.5",
        "--set",
        "world.duration=2",
    )
    assert result.returncode == 0, result.stderr
    written = yaml.safe_load((out / "scenario.yaml").read_text())
    assert written["world"]["seed"] == 7
    assert written["robot"]["max_force"] == 123.5
    assert written["controller"]["params"]["gain"] == 0.05  # from the file
    assert written["controller"]["params"]["response_time"] == 12.5  # from --set


@pytest.mark.parametrize(
    "override, expected",
    [
        (
            "controller.plugin=pdd",
            "no controller plugin named 'pdd' (available: capture-detumble, computed-torque, elastic, fmu, "
            "pd, underactuated); did you mean 'pd'?",
        ),
        (
            "controller.params.bandwidth=-1",
            "controller.params.bandwidth: -1 is not allowed: Input should be greater than 0 (allowed: > 0 rad/s)",
        ),
        (
            "controller.params.gian=2",
            "controller.params.gian: unknown key (known keys: bandwidth, damping, attitude_bandwidth, attitude_damping)",
        ),
        (
            "mission.targets[7].mass=1",
            "mission.targets[7]: index 7 is out of range (the list has 4 items; [+] appends)",
        ),
        ("robot.mass", "expected key.path=value"),
    ],
)
def test_run_user_errors_exit_2_without_traceback(dcsim_cli, override, expected):
    result = dcsim_cli("run", "--set", override)
    assert result.returncode == 2
    assert result.stderr.startswith("error: ")
    assert expected in result.stderr
    assert f"--set {override}" in result.stderr
    assert "Traceback" not in result.stderr


@pytest.mark.parametrize("command", ["run", "validate"])
def test_a_campaign_file_given_as_a_scenario_gets_one_error_naming_the_command(dcsim_cli, command):
    campaign = REPO / "scenarios" / "campaigns" / "default_dispersed.yaml"
    result = dcsim_cli(command, str(campaign))
    assert result.returncode == 2
    assert "(1 problem)" in result.stderr
    assert f"this is a campaign file: run it with `dcsim campaign run {campaign}`" in result.stderr
    assert "Traceback" not in result.stderr


def test_missing_scenario_file_is_a_user_error(dcsim_cli, tmp_path):
    result = dcsim_cli("run", str(tmp_path / "nope.yaml"))
    assert result.returncode == 2
    assert "cannot read the file" in result.stderr
    assert "Traceback" not in result.stderr


def test_debug_shows_the_traceback(dcsim_cli):
    result = dcsim_cli("--debug", "run", "--set", "world.seed=-1")
    assert result.returncode != 0
    assert "Traceback" in result.stderr
    assert "ScenarioError" in result.stderr


@pytest.mark.parametrize("group", [(), ("bench",), ("campaign",), ("fmu",), ("robot",)])
def test_every_help_lists_its_commands_with_whole_one_line_descriptions(dcsim_cli, group):
    from dcsim.cli.main import cli

    found = cli
    context = click.Context(cli)  # the plugin packages' commands too
    for name in group:
        found = found.get_command(context, name)
    names = found.list_commands(context)
    lines = dcsim_cli(*group, "--help").stdout.split("Commands:\n")[1].splitlines()
    assert len(lines) == len(names)  # one line each, none wrapped
    for name in names:
        command = found.get_command(context, name)
        line = next(line for line in lines if line.split()[0] == name)
        description = command.get_short_help_str(limit=1000)
        assert description.endswith(".") and "..." not in line
        assert f"  {name}  " in line and line.endswith(description)


# The least values the options of `bench world`, `manipulator` and `localisers` allow
# (tests/bench/test_smallest_options.py runs the other benches at theirs).
def test_bench_world_prints_a_table_for_each_size(dcsim_cli):
    result = dcsim_cli("bench", "world", "--objects", "0,5", "--duration", "1")
    assert result.returncode == 0, result.stderr
    rows = [
        line for line in result.stdout.splitlines() if line.startswith("| ") and line[2].isdigit()
    ]
    assert [row.split("|")[1].strip() for row in rows] == ["0", "5"]
    assert "default scenario: completed (all targets delivered)" in result.stdout
    floor = re.search(
        r"floor of the default scenario over its 724\.2 s: stepping ([\d.]+) s \+ per-step "
        r"state reads and forces ([\d.]+) s \+ localiser plugin alone ([\d.]+) s = ([\d.]+) s, "
        r"so a real-time factor of at most (\d+)",
        result.stdout,
    )
    assert floor, result.stdout
    parts, total, ceiling = [float(v) for v in floor.groups()[:3]], *map(float, floor.groups()[3:])
    assert min(parts) >= 0 and parts[0] > 0 and parts[2] > 0
    assert total == pytest.approx(sum(parts), abs=0.021)  # four roundings to 0.01
    assert ceiling == pytest.approx(724.2 / total, rel=0.05)
    loop = float(re.search(r"\(the whole loop: ([\d.]+) s\)", result.stdout).group(1))
    last = result.stdout.splitlines()[-1]
    ratio = re.fullmatch(r"default scenario: the whole loop is (\d+\.\d)× its floor", last)
    assert ratio, last
    rounding = 0.05 + 0.005 / total + 0.005 * loop / total**2  # one decimal; 0.01 s inputs
    assert float(ratio.group(1)) == pytest.approx(loop / total, abs=rounding)
    assert "5 objects: bare stepping" in result.stderr
    negative = dcsim_cli("bench", "world", "--objects", "5,-1")
    assert negative.returncode == 2 and "expected integers >= 0" in negative.stderr


def test_bench_manipulator_prints_the_table_and_the_verdict(dcsim_cli):
    result = dcsim_cli("bench", "manipulator", "--states", "1", "--repeats", "1", "--number", "1")
    assert result.returncode == 0, result.stderr
    assert "| M + C, two calls |" in result.stdout
    assert "M + C within 10× of Pinocchio: " in result.stdout
    assert "agreement with dcsim over the 1 states" in result.stdout
    assert "dcsim: timed 6 quantities at 1 states" in result.stderr


def test_bench_localisers_prints_the_bound_and_every_localiser(dcsim_cli, tmp_path):
    plot = tmp_path / "localisers.png"
    result = dcsim_cli("bench", "localisers", "--runs", "1", "--steps", "10", "--plot", str(plot))
    assert result.returncode == 0, result.stderr
    rows = [
        [cell.strip() for cell in line.split("|")[1:3]]
        for line in result.stdout.splitlines()
        if line.startswith("| ")
    ]
    assert rows[0] == ["ranges", "localiser"]
    for case in ("white", "biased", "outliers"):
        labels = [label for ranges, label in rows if ranges == case]
        for name in ("PCRB", "trilateration", "ekf", "ukf", "sspf 1k", "sspf 10k", "sspf 100k"):
            assert name in labels
    assert plot.stat().st_size > 10_000
    unknown = dcsim_cli("bench", "localisers", "--ranges", "white,coloured")
    assert unknown.returncode == 2 and "--ranges: unknown coloured" in unknown.stderr
    assert "Traceback" not in unknown.stderr


def test_bench_controllers_refuses_another_mission_type_before_any_run(dcsim_cli):
    result = dcsim_cli("bench", "controllers", "--seeds", "1", "--set", "mission={type: hold}")
    assert result.returncode == 2
    assert "flies the debris mission, not mission.type 'hold'" in result.stderr
    assert "Traceback" not in result.stderr
