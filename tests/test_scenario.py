"""Scenario files: schema, precise errors, overrides, resolution and round trip."""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pytest

from dcsim.api import ScenarioError
from dcsim.registry import PluginRegistry
from dcsim.scenario import (
    ScenarioDocument,
    default_scenario_path,
    dump_scenario,
    format_key_path,
    load_scenario,
    parse_key_path,
)
from dcsim.scenario.model import SphericalMotionSpec
from tests.conftest import REPO

SCENARIOS = sorted((REPO / "scenarios").glob("*.yaml"))


@pytest.fixture(scope="module")
def registry():
    return PluginRegistry.discover()


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "scenario.yaml"
    path.write_text(textwrap.dedent(text))
    return path


def problems(path, overrides=(), registry=None) -> list[str]:
    with pytest.raises(ScenarioError) as info:
        load_scenario(path, overrides, registry)
    return [p.describe(info.value.filename) for p in info.value.problems]


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.name)
def test_shipped_scenarios_resolve_and_round_trip(path, registry):
    scenario = load_scenario(path, registry=registry)
    again = ScenarioDocument.from_text(dump_scenario(scenario), "resolved.yaml")
    assert load_scenario_from(again, registry) == scenario


def load_scenario_from(doc, registry):
    from dcsim.scenario import resolve_plugins, validate

    return resolve_plugins(doc, validate(doc), registry)


def test_packaged_default_is_the_repository_default():
    assert default_scenario_path().read_text() == (REPO / "scenarios" / "default.yaml").read_text()
    assert load_scenario().name == "default"


def test_resolution_fills_plugin_defaults(registry):
    scenario = load_scenario(registry=registry)
    assert scenario.controller.params == {"bandwidth": 0.2, "damping": 0.9}
    assert scenario.task_planner.plugin == "ga"
    assert scenario.task_planner.params["time_strategy"] == "mixed"
    assert scenario.task_planner.params["MIN_TIME_STEP"] == 1.0


def test_thesis_scenario_is_geocentric_near_150_km():
    scenario = load_scenario(REPO / "scenarios" / "thesis_debris_field.yaml")
    assert scenario.world.frame == "geocentric"
    assert scenario.beacons.report_nearest == 3
    motions = [o.motion for o in [*scenario.targets, *scenario.obstacles]]
    assert all(isinstance(m, SphericalMotionSpec) for m in motions)
    assert all(145_000 <= m.r <= 155_000 for m in motions)
    rates = [abs(r) for m in motions for r in (m.alpha_deg_s, m.beta_deg_s)]
    assert 0 < max(rates) < 0.01


def test_errors_name_file_line_column_and_key_path(tmp_path):
    path = write(
        tmp_path,
        """\
        world:
          frame: lvlh
        targets:
          - id: 1
            motion: {type: spherical, r: -5, polar_deg: 10, azimuth_deg: 0}
          - id: 2
            motion: {type: warp}
        robot:
          massive: 3
        """,
    )
    found = problems(path)
    assert (
        f"{path}:5:31: targets[0].motion.r: -5 is not allowed: Input should be greater than or equal to 0 (allowed: >= 0 m)"
        in found
    )
    assert any(p.startswith(f"{path}:7:5: targets[1].motion: ") and "'warp'" in p for p in found)
    assert any(
        p.startswith(f"{path}:9:3: robot.massive: unknown key (known keys: mass,") for p in found
    )
    assert len(found) == 3


def test_rules_across_sections(tmp_path):
    path = write(
        tmp_path,
        """\
        world: {frame: geocentric, physics_step: 0.03, control_period: 0.1}
        robot: {mass: 5, propellant_mass: 5, initial: {attitude: [0, 0, 0, 0]}}
        targets:
          - {id: 4, motion: {type: cw, position: [1, 0, 0]}}
        obstacles:
          - {id: 4, motion: {type: static, position: [9, 9, 9]}}
        drop_point: {position: [0, 0, 0], motion: {type: static, position: [1, 1, 1]}}
        """,
    )
    found = problems(path)
    assert found == [
        f"{path}:1:48: world.control_period: 0.1 s is not a whole multiple of physics_step (0.03 s)",
        f"{path}:2:18: robot.propellant_mass: 5 kg must be less than robot.mass (5 kg)",
        f"{path}:2:48: robot.initial.attitude: the quaternion must not be zero",
        f"{path}:4:22: targets[0].motion.type: 'cw' motion needs world.frame: lvlh",
        f"{path}:6:6: obstacles[0].id: id 4 is already used by targets[0]",
        f"{path}:7:35: drop_point.motion: give either position or motion, not both",
    ]


def test_yaml_syntax_error_and_duplicate_keys(tmp_path):
    path = write(tmp_path, "world:\n  seed: [1,\n")
    assert problems(path)[0].startswith(f"{path}:3:1: not valid YAML")
    path = write(tmp_path, "world:\n  seed: 1\n  seed: 2\n")
    assert problems(path) == [f"{path}:3:3: world.seed: key given twice"]
    path = write(tmp_path, "- 1\n- 2\n")
    assert "the top level must be a mapping" in problems(path)[0]


def test_empty_file_is_an_error_and_an_empty_mapping_the_defaults(tmp_path):
    path = write(tmp_path, "# nothing yet\n")
    assert problems(path) == [f"{path}:1:1: the file is empty; a scenario is a mapping of sections"]
    scenario = load_scenario(write(tmp_path, "{}"))
    assert scenario.name == "unnamed" and scenario.world.frame == "lvlh"


def test_plugin_choice_errors_point_at_the_file(tmp_path, registry):
    path = write(
        tmp_path,
        """\
        controller:
          plugin: pd
          params: {bandwidth: 0, damping: 0.7}
        localiser: {plugin: trilaterate}
        """,
    )
    found = problems(path, registry=registry)
    assert (
        f"{path}:3:12: controller.params.bandwidth: 0 is not allowed: Input should be greater than 0 (allowed: > 0 rad/s)"
        in found
    )
    assert any(
        p.startswith(f"{path}:4:13: localiser.plugin: no localiser plugin named 'trilaterate'")
        for p in found
    )
    assert any("did you mean 'trilateration'?" in p for p in found)


def test_overrides_apply_and_are_validated(tmp_path, registry):
    base = REPO / "scenarios" / "default.yaml"
    scenario = load_scenario(
        base,
        [
            "targets[1].motion.position=[1, 2, 3]",
            "beacons.max_range=null",
            "world.seed=9",
            "controller.params.damping=2",
        ],
        registry,
    )
    assert scenario.targets[1].motion.position == (1.0, 2.0, 3.0)
    assert scenario.beacons.max_range is None and scenario.world.seed == 9
    assert scenario.controller.params["damping"] == 2
    found = problems(base, ["robot.max_force=-2"])
    assert found == [
        "--set robot.max_force=-2: robot.max_force: -2 is not allowed: "
        "Input should be greater than 0 (allowed: > 0 N)"
    ]
    assert problems(base, ["targets.mass=3"]) == [
        "--set targets.mass=3: targets: is a list: select an item with [index] first"
    ]


@pytest.mark.parametrize(
    "text, path",
    [
        ("targets[3].motion.r", ("targets", 3, "motion", "r")),
        ("world.seed", ("world", "seed")),
        ("beacons.positions[0][2]", ("beacons", "positions", 0, 2)),
    ],
)
def test_key_paths_parse_and_format(text, path):
    assert parse_key_path(text) == path
    assert format_key_path(path) == text


@pytest.mark.parametrize("bad", ["", "[0].a", "a..b", "a.[0]", "a b"])
def test_malformed_key_paths_are_rejected(bad):
    with pytest.raises(ValueError):
        parse_key_path(bad)


def test_spherical_points_convert_to_cartesian(tmp_path):
    path = write(
        tmp_path,
        """\
        world: {frame: geocentric}
        robot: {initial: {position: {r: 2.0, polar_deg: 90, azimuth_deg: 90}}}
        """,
    )
    from dcsim.scenario.model import point_to_cartesian

    position = point_to_cartesian(load_scenario(path).robot.initial.position)
    np.testing.assert_allclose(position, [0.0, 2.0, 0.0], atol=1e-12)


def test_docs_key_reference_matches_the_schema():
    from dcsim.docgen import block
    from dcsim.scenario.reference import BEGIN, END, render_reference

    text = (REPO / "docs" / "scenarios.md").read_text()
    assert block(text, BEGIN, END) == render_reference(), (
        "docs/scenarios.md is stale: run `make docs`"
    )
