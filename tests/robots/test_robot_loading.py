"""A scenario's manipulator from Python (`load_robot_model`) and as a URDF file (`dcsim
robot urdf`); robot types a mission or a plugin cannot fly are refused before the run."""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner

from dcsim.api import RobotTypeError, load_robot_model, thesis_manipulator
from dcsim.cli.main import cli
from dcsim.errors import ScenarioError
from dcsim.run.setup import setup_run
from dcsim.world.pybullet_client import connect_direct, pb
from tests.conftest import REPO

FIXTURE = REPO / "tests" / "world" / "data" / "thesis_manipulator.yaml"


def test_load_robot_model_is_the_thesis_robot():
    model = load_robot_model(FIXTURE)
    thesis = load_robot_model(FIXTURE).__class__(thesis_manipulator())
    rng = np.random.default_rng(3)
    attitude = rng.normal(size=4)
    q = np.r_[rng.normal(size=3), attitude / np.linalg.norm(attitude), rng.normal(size=6)]
    qd = rng.normal(size=12)
    np.testing.assert_allclose(model.forward_kinematics(q), thesis.forward_kinematics(q))
    np.testing.assert_allclose(model.mass_matrix(q), thesis.mass_matrix(q), atol=1e-12)
    np.testing.assert_allclose(model.coriolis_matrix(q, qd), thesis.coriolis_matrix(q, qd))
    assert model.jacobian(q).shape == (6, 12)


def test_a_free_flyer_has_no_robot_model():
    with pytest.raises(RobotTypeError, match="robot.type is 'free-flyer'"):
        load_robot_model(REPO / "scenarios" / "default.yaml")


def test_robot_urdf_command_writes_the_worlds_urdf(tmp_path):
    out = tmp_path / "arm.urdf"
    result = CliRunner().invoke(cli, ["robot", "urdf", str(FIXTURE), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert out.read_text() == load_robot_model(FIXTURE).urdf()
    client = connect_direct()
    try:
        body = pb.loadURDF(str(out), flags=pb.URDF_USE_INERTIA_FROM_FILE, physicsClientId=client)
        assert pb.getNumJoints(body, physicsClientId=client) == 7  # six joints, the end effector
    finally:
        pb.disconnect(physicsClientId=client)


def test_robot_urdf_command_refuses_a_free_flyer(tmp_path):
    out = tmp_path / "x.urdf"
    result = CliRunner().invoke(
        cli, ["robot", "urdf", str(REPO / "scenarios" / "default.yaml"), "-o", str(out)]
    )
    assert result.exit_code == 2 and not out.exists()
    assert "robot.type is 'free-flyer'" in result.output and "Traceback" not in result.output


def test_a_mission_and_plugins_that_cannot_fly_a_manipulator_are_refused():
    with pytest.raises(ScenarioError) as info:
        setup_run(FIXTURE)
    messages = [p.describe("s") for p in info.value.problems]
    assert any(
        "mission.type: mission type 'debris' does not support robot type 'manipulator'" in m
        for m in messages
    )
    assert any(
        "controller plugin 'pd' does not support robot type 'manipulator'" in m for m in messages
    )
