"""Broken scenario input of every kind gives error lines naming file, line and key, never a crash."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner, Result

from dcsim.cli.main import cli
from dcsim.errors import ScenarioError
from dcsim.registry.discovery import PluginRegistry
from dcsim.scenario import read_scenario
from tests.conftest import REPO

DEFAULT = REPO / "scenarios" / "default.yaml"


@pytest.fixture(scope="module")
def registry() -> PluginRegistry:
    return PluginRegistry.discover()


def write(tmp_path: Path, content: str | bytes, name: str = "scenario.yaml") -> Path:
    path = tmp_path / name
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content, encoding="utf-8")
    return path


def problems(path: Path, overrides: tuple[str, ...] = (), registry=None) -> list[str]:
    with pytest.raises(ScenarioError) as info:
        read_scenario(path, overrides, registry)
    return [p.describe(info.value.filename) for p in info.value.problems]


def dcsim(*args: str) -> Result:
    """Run the dcsim command in-process."""
    return CliRunner().invoke(cli, list(args))


@pytest.mark.parametrize("text", ["", "\n\n", "# to be written\n"])
def test_an_empty_file_is_an_error(tmp_path, text):
    path = write(tmp_path, text)
    assert problems(path) == [f"{path}:1:1: the file is empty; a scenario is a mapping of sections"]


@pytest.mark.parametrize("text", ["42\n", "- world\n- robot\n", "null\n", "just words\n"])
def test_a_top_level_that_is_not_a_mapping_is_an_error(tmp_path, text):
    path = write(tmp_path, text)
    assert problems(path) == [f"{path}:1:1: the top level must be a mapping of sections"]


@pytest.mark.parametrize(
    "content, where",
    [
        (b"name: x\n\x00\x01\x02\xff", "2:1"),
        ("name: x\n".encode("utf-16"), "1:4"),  # a BOM, then "n\0"
    ],
)
def test_binary_content_and_nul_bytes_are_errors(tmp_path, content, where):
    path = write(tmp_path, content)
    assert problems(path) == [
        f"{path}:{where}: the file holds NUL bytes: it is binary data (or UTF-16 text), "
        "not a YAML scenario; save it as UTF-8 text"
    ]


def test_text_that_is_not_utf8_is_an_error(tmp_path):
    path = write(tmp_path, "name: café\nworld: {seed: 1}\n".encode("latin-1"))
    assert problems(path) == [
        f"{path}:1:10: the file is not UTF-8 text (byte 0xe9); save it as UTF-8"
    ]


def test_a_control_character_is_an_error(tmp_path):
    path = write(tmp_path, "name: ok\ndescription: a\x07b\n")
    assert problems(path) == [
        f"{path}:2:15: not valid YAML: character #x0007 is not allowed in YAML text"
    ]


@pytest.mark.parametrize(
    "text, expected",
    [
        (
            "world:\n  duration: .nan\n",
            "2:3: world.duration: nan is not allowed: Input should be a finite number (allowed: > 0 s)",
        ),
        (
            "robot:\n  initial:\n    velocity: [0, .inf, 0]\n",
            "3:19: robot.initial.velocity[1]: inf is not allowed: Input should be a finite number",
        ),
        (
            "mission:\n  targets:\n    - {id: 1, motion: {type: spherical, r: 5, polar_deg: -.inf, azimuth_deg: 0}}\n",
            "3:47: mission.targets[0].motion.polar_deg: -inf is not allowed: Input should be a finite number",
        ),
        (
            "beacons: {max_range: .inf}\n",
            "1:11: beacons.max_range: inf is not allowed: Input should be a finite number (allowed: > 0 m)",
        ),
        (
            "stop: {max_wall_time: -.inf}\n",
            "1:8: stop.max_wall_time: -inf is not allowed: Input should be a finite number (allowed: > 0 s)",
        ),
        (
            "world: {control_period: .inf}\n",
            "1:9: world.control_period: inf is not allowed: Input should be a finite number (allowed: > 0 s)",
        ),
    ],
    ids=["nan", "inf", "-inf", "inf-for-no-limit", "-inf-for-no-limit", "inf-in-a-rule"],
)
def test_nan_and_infinities_are_errors(tmp_path, text, expected):
    path = write(tmp_path, text)
    assert problems(path) == [f"{path}:{expected}"]


def test_null_still_means_no_limit(tmp_path):
    scenario = read_scenario(
        write(tmp_path, "beacons: {max_range: null}\nstop: {max_wall_time: null}\n")
    )
    assert scenario.beacons.max_range is None and scenario.stop.max_wall_time is None


@pytest.mark.parametrize(
    "params, expected",
    [
        (
            "{bandwidth: .inf}",
            "bandwidth: inf is not allowed: Input should be a finite number (allowed: > 0 rad/s)",
        ),
        (
            "{damping: .nan}",
            "damping: nan is not allowed: Input should be a finite number (allowed: > 0, <= 5)",
        ),
    ],
)
def test_plugin_parameters_reject_nan_and_infinities(tmp_path, registry, params, expected):
    path = write(tmp_path, f"controller:\n  plugin: pd\n  params: {params}\n")
    assert problems(path, registry=registry) == [f"{path}:3:12: controller.params.{expected}"]


@pytest.mark.parametrize(
    "world, expected",
    [
        (
            "{control_period: 1.0e300}",
            "1:9: world.control_period: 1e+300 s is more than 100,000 physics steps of 0.01 s; "
            "shorten world.control_period or lengthen world.physics_step",
        ),
        (
            "{duration: 1.0e300}",
            "1:9: world.duration: 1e+300 s is more than 100,000,000 physics steps of 0.01 s; "
            "shorten world.duration or lengthen world.physics_step",
        ),
        (
            "{physics_step: 1.0e-300, control_period: 1.0e-300, duration: 1.0e-291}",
            "1:59: world.duration: 1e-291 s is more than 100,000,000 physics steps of 1e-300 s; "
            "shorten world.duration or lengthen world.physics_step",
        ),
        (
            "{seed: 100000000000000000000000000000}",
            "1:9: world.seed: 100000000000000000000000000000 is not allowed: Input should be less "
            "than or equal to 2147483647 (allowed: >= 0, <= 2147483647)",
        ),
        (
            "{orbit: {radius: 1.0e300}}",
            "1:9: world.orbit: radius 1e+300 m and mu 3.986e+14 m^3/s^2 give a mean motion of 0 "
            "rad/s; change them so that it is between 1e-09 and 0.1 rad/s",
        ),
    ],
    ids=["control-period", "duration", "step-count", "seed", "orbit"],
)
def test_absurd_magnitudes_are_errors_that_say_what_to_change(tmp_path, world, expected):
    path = write(tmp_path, f"world: {world}\n")
    assert problems(path) == [f"{path}:{expected}"]


def test_the_largest_step_counts_and_seed_are_allowed(tmp_path):
    path = write(
        tmp_path,
        "world: {physics_step: 1.0e-3, control_period: 100, duration: 100000, seed: 2147483647}\n",
    )
    assert read_scenario(path).world.seed == 2**31 - 1


def test_a_tiny_physics_step_reports_both_step_counts(tmp_path):
    path = write(tmp_path, "world:\n  physics_step: 1.0e-9\n  control_period: 0.1\n")
    assert problems(path) == [
        f"{path}:1:1: world.duration: 600 s is more than 100,000,000 physics steps of 1e-09 s; "
        "shorten world.duration or lengthen world.physics_step",
        f"{path}:3:3: world.control_period: 0.1 s is more than 100,000 physics steps of 1e-09 s; "
        "shorten world.control_period or lengthen world.physics_step",
    ]


def test_an_integer_too_long_to_read_is_an_error(tmp_path):
    path = write(tmp_path, "world:\n  seed: " + "9" * 5000 + "\n")
    assert problems(path) == [
        f"{path}:2:9: an integer of more than 4300 digits; write a smaller number"
    ]


def test_a_file_over_a_megabyte_is_an_error(tmp_path):
    path = write(tmp_path, "beacons:\n  positions:\n" + "    - [1, 2, 3]\n" * 70_000)
    assert problems(path) == [
        f"{path}: the file is larger than 1,000,000 bytes; a scenario needs far less"
    ]


def test_aliases_expanding_to_a_gigantic_document_are_an_error(tmp_path):
    lines = ["a0: &a0 [1, 1, 1, 1, 1, 1, 1, 1, 1, 1]"]
    lines += [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 10)}]" for i in range(1, 7)]
    path = write(tmp_path, "\n".join(lines) + "\n")
    assert problems(path) == [
        f"{path}:6:45: the document holds more than 1,000,000 values (aliases expanded); "
        "a scenario needs far fewer"
    ]


def test_deep_nesting_is_an_error(tmp_path):
    path = write(
        tmp_path, "controller: {plugin: pd, params: {x: " + "[" * 3000 + "]" * 3000 + "}}\n"
    )
    assert problems(path) == [
        f"{path}:1:85: lists and mappings nest more than 50 levels deep (aliases expanded); "
        "a scenario needs far fewer"
    ]


def test_a_recursive_alias_is_an_error(tmp_path):
    path = write(tmp_path, "world:\n  orbit: &loop\n    radius: [*loop]\n")
    assert problems(path) == [
        f"{path}:3:14: alias *loop refers to a value that contains it; recursive data is not allowed"
    ]


@pytest.mark.parametrize(
    "text, expected",
    [
        (
            "mission:\n  targets:\n    - {motion: {type: static, position: [1, 2, 3]}}\n",
            ["3:7: mission.targets[0].id: required but missing"],
        ),
        (
            "world: 3\nrobot: [1, 2]\n",
            [
                "1:1: world: 3 is not allowed: Input should be a valid dictionary or instance of WorldSpec",
                "2:1: robot: [1, 2] is not allowed: Input should be a valid dictionary or instance of RobotSection",
            ],
        ),
        (
            "robot:\n  mass: heavy\n",
            [
                "2:3: robot.mass: 'heavy' is not allowed: Input should be a valid number, unable to parse string as a number (allowed: > 0 kg)"
            ],
        ),
        (
            "obstacles: {a: {b: {c: [[[{d: 1}]]]}}}\n",
            [
                "1:1: obstacles: {'a': {'b': {'c': [[[{'d': 1}]]]}}} is not allowed: Input should be a valid list"
            ],
        ),
    ],
    ids=["deleted-required-key", "sections-replaced", "wrong-type", "nested-junk"],
)
def test_wrong_types_missing_keys_and_nested_junk_stay_clean_errors(tmp_path, text, expected):
    path = write(tmp_path, text)
    assert problems(path) == [f"{path}:{line}" for line in expected]


def test_rules_across_keys_are_reported_with_field_errors(tmp_path):
    path = write(
        tmp_path,
        """\
world:
  physics_step: 0.03
  seed: -1
robot:
  mass: 5
  propellant_mass: 5
  capacity: 0
mission:
  targets:
    - {id: 1, motion: {type: cw, position: [1, 2, .nan]}}
    - {id: 1, radius: x, motion: {type: static, position: [1, 2, 3]}}
""",
    )
    assert problems(path) == [
        f"{path}:1:1: world.control_period: 0.1 s is not a whole multiple of physics_step (0.03 s)",
        f"{path}:3:3: world.seed: -1 is not allowed: Input should be greater than or equal to 0 (allowed: >= 0, <= 2147483647)",
        f"{path}:6:3: robot.propellant_mass: 5 kg must be less than robot.mass (5 kg)",
        f"{path}:7:3: robot.capacity: 0 is not allowed: Input should be greater than or equal to 1 (allowed: >= 1)",
        f"{path}:10:51: mission.targets[0].motion.position[2]: nan is not allowed: Input should be a finite number",
        f"{path}:11:8: mission.targets[1].id: id 1 is already used by mission.targets[0]",
        f"{path}:11:15: mission.targets[1].radius: 'x' is not allowed: Input should be a valid number, unable to parse string as a number (allowed: > 0 m)",
    ]


def test_a_rule_whose_own_values_are_invalid_is_left_to_the_schema(tmp_path):
    path = write(tmp_path, "world:\n  physics_step: -1\n  control_period: 0.25\n")
    assert problems(path) == [
        f"{path}:2:3: world.physics_step: -1 is not allowed: Input should be greater than 0 (allowed: > 0, <= 1 s)"
    ]


@pytest.mark.parametrize(
    "override, expected",
    [
        (
            "world.duration=.nan",
            "world.duration: nan is not allowed: Input should be a finite number",
        ),
        ("world.control_period=1.0e300", "world.control_period: 1e+300 s is more than 100,000"),
        ("robot.initial.position=[.inf, 0, 0]", "robot.initial.position[0]: inf is not allowed"),
        ("world.seed=&a [*a]", "alias *a refers to a value that contains it"),
        ("world=[" + "[" * 60 + "]" * 61, "nest more than 50 levels deep"),
        ("a" + ".a" * 60 + "=1", "the key path is more than 50 keys long"),
        ("name=\x01", "not valid YAML: character #x0001 is not allowed in YAML text"),
    ],
)
def test_junk_overrides_are_clean_errors(override, expected):
    result = dcsim("run", str(DEFAULT), "--set", override)
    assert result.exit_code == 2, result.output
    assert isinstance(result.exception, SystemExit)
    assert f"--set {override}: " in result.stderr
    assert expected in result.stderr


def test_validate_reports_every_file_when_some_fail(tmp_path):
    empty = write(tmp_path, "", "empty.yaml")
    binary = write(tmp_path, b"\x00\x01", "binary.yaml")
    nan = write(tmp_path, "world: {duration: .nan}\n", "nan.yaml")
    result = dcsim("validate", str(empty), str(DEFAULT), str(binary), str(nan))
    assert result.exit_code == 2
    assert result.stdout == f"ok {DEFAULT}\n"
    assert result.stderr.count("error: ") == 3
    assert f"{empty}:1:1: the file is empty" in result.stderr
    assert f"{binary}:1:1: the file holds NUL bytes" in result.stderr
    assert f"{nan}:1:9: world.duration: nan is not allowed" in result.stderr
    assert "Traceback" not in result.output


def test_run_names_its_directory_safely_after_any_scenario_name(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = dcsim("run", "--set", 'name="../a/b\\\\c"', "--set", "world.duration=0.1")
    assert result.exit_code == 0, result.output
    (run_dir,) = (tmp_path / "runs").iterdir()
    assert run_dir.name.startswith(".._a_b_c-")
