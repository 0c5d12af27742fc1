"""The robot as the world steps it: one interface for every robot body type.

The world drives a robot's base (thrust, torque, orbital forces at its centre of mass)
the same way whatever the robot is; what differs between a free flyer and a manipulator
is behind :class:`RobotBody`: the links that feel orbital forces, the joints and their
torques, how the base's mass changes, and the :class:`~dcsim.messages.RobotSpec` the
robot reports. The world picks the body type from the scenario's robot section.
"""

from __future__ import annotations

from typing import Any, Protocol

import numpy as np

from dcsim.messages import RobotSpec
from dcsim.scenario.model import ManipulatorSection, RobotSection


class RobotBody(Protocol):
    """A robot's PyBullet body as the world steps it.

    Attributes
    ----------
    body : int
        The PyBullet body id; its base (link -1) carries the thrust, the torque and the
        cargo.
    links : tuple of (int, float)
        PyBullet link index and mass (kg) of every link besides the base that has mass;
        each feels the orbital force at its own centre of mass. Empty for a rigid body.
    n_joints : int
        Number of actuated joints (0 for a rigid body).
    """

    body: int
    links: tuple[tuple[int, float], ...]

    @property
    def n_joints(self) -> int:
        """Number of actuated joints (0 for a rigid body)."""
        ...

    def joint_state(self) -> tuple[np.ndarray, np.ndarray]:
        """Joint angles (rad) and rates (rad/s), (n,) each (empty without joints)."""
        ...

    def clip_joint_torques(self, torques: np.ndarray) -> np.ndarray:
        """Commanded joint torques (n,) clipped to the limits, N·m."""
        ...

    def apply_joint_torques(self, torques: np.ndarray) -> None:
        """Set the joint torques (n,), N·m, for the next physics step."""
        ...

    def set_base_mass(self, mass: float) -> None:
        """Set the base's mass, kg (propellant burnt or cargo released)."""
        ...

    def spec(self, assembly_mass: float, base_mass: float, protrusion: float) -> RobotSpec:
        """The robot's spec now.

        Parameters
        ----------
        assembly_mass : float
            Mass of the robot and its cargo, kg.
        base_mass : float
            The base's mass, propellant included, kg.
        protrusion : float
            How far cargo reaches beyond the base's bounding sphere, m.
        """
        ...

    def end_effector(self, configuration: np.ndarray) -> np.ndarray:
        """End-effector position (3,) at ``configuration``, world frame, m.

        Raises
        ------
        ValueError
            For a robot without an end effector.
        """
        ...


def base_spec_fields(
    robot: RobotSection | ManipulatorSection,
    assembly_mass: float,
    inertia: np.ndarray,
    protrusion: float,
) -> dict[str, Any]:
    """The :class:`~dcsim.messages.RobotSpec` fields every robot has.

    Parameters
    ----------
    robot : RobotSection or ManipulatorSection
        The scenario's robot (radius and limits).
    assembly_mass : float
        Mass of the robot and its cargo, kg.
    inertia : ndarray (3, 3)
        The base's inertia about its centre of mass, body frame, kg·m².
    protrusion : float
        How far cargo reaches beyond the base's bounding sphere, m.
    """
    return {
        "mass": assembly_mass,
        "inertia": inertia,
        "radius": robot.radius + protrusion,
        "max_force": robot.max_force,
        "max_torque": robot.max_torque,
        "max_speed": robot.max_speed,
    }
