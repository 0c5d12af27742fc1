"""A scenario file's robot model, for scripts and the ``dcsim robot`` commands."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from dcsim.errors import RobotTypeError
from dcsim.robots.manipulator import ManipulatorModel
from dcsim.scenario import load_scenario
from dcsim.scenario.model import ManipulatorSection


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
    robot = load_scenario(path, overrides).robot
    if not isinstance(robot, ManipulatorSection):
        raise RobotTypeError(
            f"{path}: robot.type is '{robot.type}', which has no arm model; "
            "give a scenario with robot.type: manipulator"
        )
    return ManipulatorModel(robot.dh_robot())
