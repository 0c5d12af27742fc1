"""Scenario files: schema, precise errors, overrides, resolution and round trip."""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pytest
import yaml

from dcsim.api import ScenarioError, Shape, ShapeKind
from dcsim.registry.discovery import PluginRegistry
from dcsim.scenario import (
    ScenarioDocument,
    default_scenario_path,
    dump_scenario,
    format_key_path,
    loader,
    parse_key_path,
    read_scenario,
    validate,
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
        read_scenario(path, overrides, registry)
    return [p.describe(info.value.filename) for p in info.value.problems]


@pytest.mark.parametrize(
    "path",
    SCENARIOS,
    ids=lambda p: p.name,
)
def test_shipped_scenarios_resolve_and_round_trip(path, registry):
    scenario = read_scenario(path, registry=registry)
    again = ScenarioDocument.from_text(dump_scenario(scenario), "resolved.yaml")
    assert load_scenario_from(again, registry) == scenario


def load_scenario_from(doc, registry):
    from dcsim.scenario import resolve_plugins, validate

    return resolve_plugins(doc, validate(doc), registry)


def test_packaged_default_is_the_repository_default():
    assert default_scenario_path().read_text() == (REPO / "scenarios" / "default.yaml").read_text()
    assert read_scenario().name == "default"


def test_every_packaged_scenario_is_its_repository_copy():
    packaged = sorted(default_scenario_path().parent.glob("*.yaml"))
    assert len(packaged) >= 5
    for path in packaged:
        assert path.read_text() == (REPO / "scenarios" / path.name).read_text(), path.name


def test_resolution_fills_plugin_defaults(registry):
    scenario = read_scenario(registry=registry)
    assert scenario.controller.params == {
        "bandwidth": 0.2,
        "damping": 0.9,
        "attitude_bandwidth": 0.5,
        "attitude_damping": 0.9,
    }
    assert scenario.task_planner.plugin == "ga"
    assert scenario.task_planner.params["time_strategy"] == "mixed"
    assert scenario.task_planner.params["MIN_TIME_STEP"] == 1.0


def test_thesis_scenario_is_geocentric_near_150_km():
    scenario = read_scenario(REPO / "scenarios" / "thesis_debris_field.yaml")
    assert scenario.world.frame == "geocentric"
    assert scenario.beacons.report_nearest == 3
    motions = [o.motion for o in [*scenario.mission.targets, *scenario.obstacles]]
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
        mission:
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
        f"{path}:6:33: mission.targets[0].motion.r: -5 is not allowed: Input should be greater than or equal to 0 (allowed: >= 0 m)"
        in found
    )
    assert any(
        p.startswith(f"{path}:8:7: mission.targets[1].motion: ") and "'warp'" in p for p in found
    )
    assert any(
        p.startswith(f"{path}:10:3: robot.massive: unknown key (known keys: type, mass,")
        for p in found
    )
    assert len(found) == 3


def test_rules_across_sections(tmp_path):
    path = write(
        tmp_path,
        """\
        world: {frame: geocentric, physics_step: 0.03, control_period: 0.1}
        robot: {mass: 5, propellant_mass: 5, initial: {attitude: [0, 0, 0, 0]}}
        mission:
          targets:
            - {id: 4, motion: {type: cw, position: [1, 0, 0]}}
          drop_point: {position: [0, 0, 0], motion: {type: static, position: [1, 1, 1]}}
        obstacles:
          - {id: 4, motion: {type: static, position: [9, 9, 9]}}
        """,
    )
    found = problems(path)
    assert found == [
        f"{path}:1:48: world.control_period: 0.1 s is not a whole multiple of physics_step (0.03 s)",
        f"{path}:2:18: robot.propellant_mass: 5 kg must be less than robot.mass (5 kg)",
        f"{path}:2:48: robot.initial.attitude: the quaternion must not be zero",
        f"{path}:5:24: mission.targets[0].motion.type: 'cw' motion needs world.frame: lvlh",
        f"{path}:6:37: mission.drop_point.motion: give either position or motion, not both",
        f"{path}:8:6: obstacles[0].id: id 4 is already used by mission.targets[0]",
    ]


@pytest.mark.parametrize(
    ("inertia", "message"),
    [
        ("[1, 2, 4]", "each principal moment must be at most the sum of the other two"),
        ("[0, 1, 1]", "Input should be greater than 0"),
        ("[1, -2, 2]", "Input should be greater than 0"),
        ("[.inf, 1, 1]", "Input should be a finite number"),
        ("[1, 2]", "has too few items"),
        ("[[2, 0, 0], [0, 2, 0], [0, 0, 3]]", "a full inertia tensor is not supported"),
    ],
)
def test_a_free_flyer_inertia_no_rigid_body_has_is_refused_naming_the_key(
    tmp_path, inertia, message
):
    path = write(tmp_path, f"robot: {{mass: 50, inertia: {inertia}}}\n")
    (found,) = problems(path)
    assert found.startswith(f"{path}:1:") and "robot.inertia" in found and message in found


def test_a_free_flyer_inertia_is_kept_and_absent_by_default(tmp_path):
    assert read_scenario(write(tmp_path, "robot: {mass: 50}\n")).robot.inertia is None
    given = read_scenario(write(tmp_path, "robot: {mass: 50, inertia: [2, 3, 4.5]}\n"))
    assert given.robot.inertia == (2.0, 3.0, 4.5)


def test_object_shapes_build_and_fill_in_the_bounding_radius(tmp_path):
    path = write(
        tmp_path,
        """\
        obstacles:
          - {id: 1, radius: 0.7, motion: {type: static, position: [0, 0, 0]}}
          - {id: 2, shape: {type: box, half_extents: [1, 2, 2]}, motion: {type: static, position: [9, 0, 0]}}
          - id: 3
            shape: {type: cylinder, radius: 3, height: 8, orientation: [0, 1, 0, 1]}
            motion: {type: static, position: [0, 9, 0]}
          - {id: 4, radius: 2, shape: {type: sphere, radius: 2}, motion: {type: static, position: [0, 0, 9]}}
        """,
    )
    sphere, box, cylinder, given = read_scenario(path).obstacles
    assert sphere.shape is None and sphere.build_shape() == Shape(ShapeKind.SPHERE, radius=0.7)
    assert box.radius == 3.0  # |(1, 2, 2)|, filled in
    assert box.build_shape() == Shape(ShapeKind.BOX, half_extents=[1.0, 2.0, 2.0])
    assert cylinder.radius == 5.0  # hypot(3, 8 / 2)
    built = cylinder.build_shape()
    assert built.kind is ShapeKind.CYLINDER and (built.radius, built.height) == (3.0, 8.0)
    np.testing.assert_allclose(built.orientation, [0, 0.5**0.5, 0, 0.5**0.5])  # normalised
    assert given.radius == 2.0 and given.build_shape().kind is ShapeKind.SPHERE
    # Written back out, radius and shape both appear and agree.
    again = ScenarioDocument.from_text(dump_scenario(read_scenario(path)), "resolved.yaml")
    assert validate(again).obstacles == read_scenario(path).obstacles


def test_shape_errors_name_their_key_paths(tmp_path):
    path = write(
        tmp_path,
        """\
        mission:
          targets:
            - id: 1
              shape: {type: box, half_extents: [1, -2, 2], orientation: [0, 0, 0, 0]}
              motion: {type: static, position: [0, 0, 0]}
            - id: 2
              shape: {type: cone, radius: 1}
              motion: {type: static, position: [0, 0, 0]}
            - id: 3
              shape: {type: cylinder, radius: 1, half_extents: [1, 1, 1]}
              motion: {type: static, position: [0, 0, 0]}
            - id: 4
              shape: {type: sphere}
              motion: {type: static, position: [0, 0, 0]}
        """,
    )
    assert problems(path) == [
        f"{path}:4:44: mission.targets[0].shape.half_extents[1]: -2 is not allowed: Input should be greater than 0",
        f"{path}:4:52: mission.targets[0].shape.orientation: [0, 0, 0, 0] is not allowed: Value error, the quaternion must not be zero",
        f"{path}:7:7: mission.targets[1].shape: {{'type': 'cone', 'radius': 1}} is not allowed: Input tag 'cone' found using 'type' does not match any of the expected tags: 'sphere', 'box', 'cylinder'",
        f"{path}:10:7: mission.targets[2].shape.height: required but missing",
        f"{path}:10:42: mission.targets[2].shape.half_extents: unknown key (known keys: type, radius, height, orientation)",
        f"{path}:13:7: mission.targets[3].shape.radius: required but missing",
    ]


def test_radius_given_with_a_shape_must_agree_with_it(tmp_path):
    path = write(
        tmp_path,
        """\
        mission:
          targets:
            - {id: 1, radius: 2, shape: {type: box, half_extents: [1, 2, 2]}, motion: {type: static, position: [0, 0, 0]}}
        obstacles:
          - {id: 2, radius: 3, shape: {type: box, half_extents: [1, 2, 2]}, motion: {type: static, position: [0, 0, 0]}}
          - {id: 3, radius: 1.5, shape: {type: sphere, radius: 2}, motion: {type: static, position: [0, 0, 0]}}
        """,
    )
    assert problems(path) == [
        f"{path}:3:15: mission.targets[0].radius: 2 m disagrees with the shape's bounding radius (3 m); leave radius out when giving a shape",
        f"{path}:6:13: obstacles[1].radius: 1.5 m disagrees with the shape's bounding radius (2 m); leave radius out when giving a shape",
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
    scenario = read_scenario(write(tmp_path, "{}"))
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
    scenario = read_scenario(
        base,
        [
            "mission.targets[1].motion.position=[1, 2, 3]",
            "beacons.max_range=null",
            "world.seed=9",
            "controller.params.damping=2",
        ],
        registry,
    )
    assert scenario.mission.targets[1].motion.position == (1.0, 2.0, 3.0)
    assert scenario.beacons.max_range is None and scenario.world.seed == 9
    assert scenario.controller.params["damping"] == 2
    found = problems(base, ["robot.max_force=-2"])
    assert found == [
        "--set robot.max_force=-2: robot.max_force: -2 is not allowed: "
        "Input should be greater than 0 (allowed: > 0 N)"
    ]
    assert problems(base, ["mission.targets.mass=3"]) == [
        "--set mission.targets.mass=3: mission.targets: is a list: select an item with [index] "
        "first"
    ]


def test_a_key_the_mission_moved_is_refused_naming_its_new_place(tmp_path):
    path = write(
        tmp_path,
        """\
        targets:
          - {id: 1, motion: {type: static, position: [5, 0, 0]}}
        drop_point: {position: [0, 0, 0]}
        stop: {on_collision: true, on_all_delivered: false}
        """,
    )
    assert problems(path) == [
        f"{path}:1:1: targets: this key has moved: give it as mission.targets",
        f"{path}:3:1: drop_point: this key has moved: give it as mission.drop_point",
        f"{path}:4:28: stop.on_all_delivered: this key has moved: give it as "
        "mission.stop_on_all_delivered",
    ]


def test_unknown_keys_and_types_suggest_the_closest_known_one(tmp_path):
    path = write(
        tmp_path,
        """\
        world:
          duraton: 100
        robot:
          type: Manipulator
        mission:
          type: Reach
        """,
    )
    with pytest.raises(ScenarioError) as info:
        validate(ScenarioDocument.from_file(path))
    assert "did you mean 'reach'?" in str(info.value)
    found = problems(write(tmp_path, "world:\n  duraton: 100\nrobot:\n  type: Manipulator\n"))
    assert found[0].endswith(
        "world.duraton: unknown key (known keys: frame, orbit, physics_step, "
        "control_period, duration, seed); did you mean 'duration'?"
    )
    assert found[1].endswith(
        "unknown robot type 'Manipulator'; known: free-flyer, manipulator; "
        "did you mean 'manipulator'?"
    )


def test_a_plugin_name_in_the_wrong_case_is_suggested_in_the_right_one(tmp_path, registry):
    found = problems(write(tmp_path, "localiser:\n  plugin: EKF\n"), registry=registry)
    assert found == [
        f"{tmp_path / 'scenario.yaml'}:2:3: localiser.plugin: no localiser plugin named 'EKF' "
        "(available: ekf, sspf, trilateration, ukf); did you mean 'ekf'?"
    ]


def test_a_campaign_file_gets_one_error_saying_what_it_is(tmp_path):
    campaign = REPO / "scenarios" / "campaigns" / "default_dispersed.yaml"
    assert problems(campaign) == [
        f"{campaign}: this is a campaign file: run it with `dcsim campaign run {campaign}`"
    ]
    stray = tmp_path / "stray.yaml"  # a scenario's own sections and a stray key
    stray.write_text((REPO / "scenarios" / "default.yaml").read_text() + "scenario: x.yaml\n")
    (found,) = problems(stray)
    assert "scenario: unknown key" in found


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


def test_an_override_ending_in_plus_appends_to_a_list(tmp_path):
    base = REPO / "scenarios" / "default.yaml"
    item = "{id: 99, radius: 1.0, motion: {type: static, position: [50, 0, 0]}}"
    scenario = read_scenario(base, [f"mission.targets[+]={item}", "mission.targets[4].radius=2"])
    targets = scenario.mission.targets
    assert [t.id for t in targets][-1] == 99 and targets[4].radius == 2
    bare = write(tmp_path, "world:\n  seed: 1\n")
    assert len(read_scenario(bare, [f"obstacles[+]={item}"]).obstacles) == 1  # list created
    assert problems(base, ["mission.targets[+]={id: 98, radius: -1, motion: {type: static}}"])[
        0
    ] == (
        "--set mission.targets[+]={id: 98, radius: -1, motion: {type: static}}: "
        "mission.targets[4].radius: "
        "-1 is not allowed: Input should be greater than 0 (allowed: > 0 m)"
    )
    assert problems(base, ["world[+]=1"]) == [
        "--set world[+]=1: world: is not a list: [+] appends to a list"
    ]
    assert problems(base, ["mission.targets[+].id=3"]) == [
        "--set mission.targets[+].id=3: [+] must end the key path: give the whole item as the value"
    ]


def test_spherical_points_convert_to_cartesian(tmp_path):
    path = write(
        tmp_path,
        """\
        world: {frame: geocentric}
        robot: {initial: {position: {r: 2.0, polar_deg: 90, azimuth_deg: 90}}}
        """,
    )
    from dcsim.scenario.model import point_to_cartesian

    position = point_to_cartesian(read_scenario(path).robot.initial.position)
    np.testing.assert_allclose(position, [0.0, 2.0, 0.0], atol=1e-12)


def test_docs_key_reference_matches_the_schema():
    from dcsim.report.docgen import block
    from dcsim.scenario.reference import BEGIN, END, render_reference

    text = (REPO / "docs" / "scenarios.md").read_text()
    assert block(text, BEGIN, END) == render_reference(), (
        "docs/scenarios.md is stale: run `make docs`"
    )


def test_a_path_planners_own_clearance_is_refused_saying_where_the_margin_is(tmp_path, registry):
    path = write(tmp_path, "path_planner: {plugin: straight-line, params: {clearance: 0.5}}\n")
    (found,) = problems(path, registry=registry)
    assert found.startswith(f"{path}:1:")
    assert "path_planner.params.clearance: no longer a parameter: " in found
    assert "safety_margin" in found and "set mission.safety_distance instead" in found


def test_the_mission_section_is_read_as_its_mission_s_settings_class_or_refused():
    from dcsim.missions.debris.settings import DebrisMissionSection
    from dcsim.missions.transfer.settings import TransferMissionSection

    scenario = read_scenario(default_scenario_path())
    assert scenario.mission_as(DebrisMissionSection) is scenario.mission
    with pytest.raises(TypeError, match="not the TransferMissionSection"):
        scenario.mission_as(TransferMissionSection)


@pytest.mark.skipif(not yaml.__with_libyaml__, reason="PyYAML without libyaml dumps itself")
@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_the_resolved_scenario_is_written_as_pyyaml_s_own_dumper_writes_it(path):
    """libyaml's dumper, where there is one, gives PyYAML's text to the byte."""
    assert loader._DUMPER is yaml.CSafeDumper  # the fast one is the one in use
    scenario = read_scenario(path)
    data = scenario.model_dump(mode="json")
    expected = yaml.dump(data, Dumper=yaml.SafeDumper, sort_keys=False, allow_unicode=True)
    assert dump_scenario(scenario) == expected
