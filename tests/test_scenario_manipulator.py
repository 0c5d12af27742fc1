"""The `manipulator` robot section: its keys, units, and errors located at their keys."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from dcsim.errors import ScenarioError
from dcsim.robots.dh import thesis_manipulator
from dcsim.scenario import read_scenario
from dcsim.scenario.model import ManipulatorSection, RobotSection
from tests.conftest import REPO

FIXTURE = REPO / "tests" / "world" / "data" / "thesis_manipulator.yaml"

ARM = """\
robot:
  type: manipulator
  mass: 100.0
  inertia: [10, 10, 10]
  links:
    - {a: 0.5, alpha_deg: 90, mass: 5.0, inertia: [0.1, 0.5, 0.5]}
    - {a: 0.5, alpha_deg: 0, mass: 5.0, inertia: [0.1, 0.5, 0.5]}
"""


def problems(tmp_path: Path, text: str) -> list[str]:
    path = tmp_path / "scenario.yaml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ScenarioError) as info:
        read_scenario(path)
    return [p.describe("s") for p in info.value.problems]


def test_the_fixture_is_the_thesis_robot_in_radians():
    robot = read_scenario(FIXTURE).robot
    assert isinstance(robot, ManipulatorSection)
    ours, thesis = robot.dh_robot(), thesis_manipulator()
    for name in ("a", "alpha", "d", "mass", "theta_offset", "torque_limit"):
        np.testing.assert_allclose(ours.column(name), thesis.column(name), rtol=0, atol=1e-15)
    np.testing.assert_array_equal(
        [k.inertia for k in ours.links], [k.inertia for k in thesis.links]
    )
    np.testing.assert_array_equal(ours.base.mount, thesis.base.mount)
    assert ours.base.mass == thesis.base.mass
    angles, rates = robot.initial_joints()
    assert angles[1] == pytest.approx(math.radians(30)) and not rates.any()


def test_a_robot_without_type_is_the_free_flyer():
    assert isinstance(read_scenario(REPO / "scenarios" / "default.yaml").robot, RobotSection)


def test_limits_in_degrees_become_radians(tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text(
        ARM.replace("mass: 5.0,", "mass: 5.0, position_limits_deg: [-90, 45], torque_limit: 3,", 1)
    )
    link = read_scenario(path).robot.dh_robot().links[0]
    assert link.joint_limits == pytest.approx((-math.pi / 2, math.pi / 4))
    assert link.torque_limit == 3.0


def test_bad_manipulator_keys_are_reported_at_their_lines(tmp_path):
    text = ARM.replace("inertia: [10, 10, 10]", "inertia: [1, 1, 5]").replace(
        "mass: 5.0,", "mass: 5.0, position_limits_deg: [10, -10], wrist: 1,", 1
    )
    text += "  initial:\n    joint_angles_deg: [0, 1, 2]\n"
    found = problems(tmp_path, text)
    assert found[0].startswith("s:4:3: robot.inertia:") and "sum of the other two" in found[0]
    assert found[1].startswith("s:6:") and "robot.links[0].position_limits_deg" in found[1]
    assert "robot.links[0].wrist: unknown key" in found[2]
    assert found[3].startswith("s:9:5:") and "robot.initial.joint_angles_deg: 3 values" in found[3]
    assert len(found) == 4


def test_unknown_robot_type_and_missing_dh_table(tmp_path):
    assert problems(tmp_path, "robot:\n  type: arm\n") == [
        "s:2:3: robot.type: unknown robot type 'arm'; known: free-flyer, manipulator"
    ]
    found = problems(tmp_path, "robot:\n  type: manipulator\n  mass: 10\n  inertia: [1, 1, 1]\n")
    assert len(found) == 1 and "robot.links" in found[0] and "s:1:1" in found[0]
