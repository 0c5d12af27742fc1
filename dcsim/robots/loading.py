"""A scenario file's robot model and reach problem, for scripts, benches and the
``dcsim robot`` commands."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from dcsim.errors import DcsimError, RobotTypeError
from dcsim.messages import PathProblem, RobotState
from dcsim.robots.manipulator import ManipulatorModel
from dcsim.scenario import read_scenario
from dcsim.scenario.model import ManipulatorSection, point_to_cartesian


def load_robot_model(path: str | Path, overrides: Sequence[str] = ()) -> ManipulatorModel:
    """The model of the manipulator described by scenario file ``path``.

    Only the file's schema is checked (plugins are not looked up), so the robot of any
    valid scenario loads.

    Parameters
    ----------
    path : str or Path
        Scenario file with ``robot.type: manipulator``.
    overrides : sequence of str
        ``key.path=value`` overrides, as for ``dcsim run --set``.

    Returns
    -------
    ManipulatorModel
        ``forward_kinematics(q)``, ``jacobian(q)``, ``mass_matrix(q)``,
        ``coriolis_matrix(q, qd)`` and more, with ``q = [base position (3), base
        quaternion x, y, z, w (4), joint angles (n)]`` and ``qd = [v_base (3), ω_base (3),
        θ̇ (n)]``, world frame, base quantities at its centre of mass.

    Raises
    ------
    ScenarioError
        If the file is not a valid scenario.
    RobotTypeError
        If its robot is not a manipulator.
    """
    robot = read_scenario(path, overrides).robot
    if not isinstance(robot, ManipulatorSection):
        raise RobotTypeError(
            f"{path}: robot.type is '{robot.type}', which has no arm model; "
            "give a scenario with robot.type: manipulator"
        )
    return ManipulatorModel(robot.dh_robot())


def load_reach_problem(
    path: str | Path, end_effector: ArrayLike | None = None, overrides: Sequence[str] = ()
) -> PathProblem:
    """The path problem a reach scenario's mission poses at its start.

    Parameters
    ----------
    path : str or Path
        Scenario file with ``robot.type: manipulator`` and ``mission.type: reach``.
    end_effector : array_like (3,) or None
        Start the end effector here instead (world frame, m): the joints are moved by
        inverse kinematics with the base held, from the scenario's initial angles.
    overrides : sequence of str
        ``key.path=value`` overrides, as for ``dcsim run --set``.

    Raises
    ------
    ScenarioError
        If the file is not a valid scenario.
    RobotTypeError
        If its robot is not a manipulator.
    DcsimError
        If its mission is not a reach, or the end effector cannot start at
        ``end_effector``.
    """
    from dcsim.missions.reach.mission import reach_problem  # the missions load the world engine

    scenario = read_scenario(path, overrides)
    model = load_robot_model(path, overrides)
    if scenario.mission.type != "reach":
        raise DcsimError(f"{path}: mission.type is '{scenario.mission.type}', not 'reach'")
    assert isinstance(scenario.robot, ManipulatorSection)  # load_robot_model refused others
    angles, rates = scenario.robot.initial_joints()
    initial = scenario.robot.initial
    attitude = np.asarray(initial.attitude, dtype=float)
    q = np.concatenate(
        [point_to_cartesian(initial.position), attitude / np.linalg.norm(attitude), angles]
    )
    if end_effector is not None:
        solved = model.inverse_kinematics(end_effector, q)
        if not solved.converged:
            raise DcsimError(
                f"{path}: the end effector cannot start at {np.asarray(end_effector).tolist()} "
                f"({solved.status}, {solved.error:.3g} m away)"
            )
        q, rates = solved.q, np.zeros_like(rates)
    start = RobotState(
        time=0.0,
        position=q[:3],
        attitude=q[3:7],
        velocity=np.array(initial.velocity),
        angular_velocity=np.array(initial.angular_velocity),
        joint_positions=q[7:],
        joint_velocities=rates,
    )
    return reach_problem(scenario, start, model)
