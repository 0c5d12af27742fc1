"""The typed robot model: the manipulator's model satisfies it, messages check it."""

from __future__ import annotations

import numpy as np
import pytest
from dcsim_plugins.controllers.computed_torque import ComputedTorqueController
from dcsim_plugins.path_planners.end_effector_line import EndEffectorLinePlanner

from dcsim.api import (
    GoalRegion,
    ManipulatorModel,
    NoPath,
    PathProblem,
    PluginError,
    RobotModel,
    RobotSpec,
    RobotState,
    thesis_manipulator,
)
from dcsim.testing.problems import reach_problem


class KinematicsOnly:
    """A model with forward kinematics and nothing else."""

    n_joints = 6

    def forward_kinematics(self, q):
        return np.zeros(3)


def test_the_manipulator_model_is_a_robot_model():
    model = ManipulatorModel(thesis_manipulator())
    assert isinstance(model, RobotModel)
    assert model.reach == pytest.approx(3.0)  # the thesis's arm: 0.7 + 4 × 0.4 + 0.7 m


def test_a_scenario_robots_model_is_a_robot_model():
    model = reach_problem().model
    assert model is not None and isinstance(model, RobotModel)


def test_a_model_missing_members_is_refused_naming_them():
    with pytest.raises(TypeError, match=r"RobotSpec.model must be None or a dcsim.api.RobotModel"):
        RobotSpec(mass=1.0, inertia=np.eye(3), model=KinematicsOnly())
    with pytest.raises(TypeError, match=r"lacks reach, inverse_kinematics, det_jjt, dynamics$"):
        PathProblem(RobotState(0.0, np.zeros(3)), GoalRegion(np.ones(3)), model=KinematicsOnly())


def test_model_based_plugins_refuse_a_free_flyer():
    with pytest.raises(PluginError, match="needs a manipulator's model"):
        ComputedTorqueController().reset(RobotSpec(mass=1.0, inertia=np.eye(3)))
    free = PathProblem(RobotState(0.0, np.zeros(3)), GoalRegion(np.ones(3)))
    answer = EndEffectorLinePlanner().plan(free)
    assert answer == NoPath("the problem carries no manipulator model: this planner moves an arm")
