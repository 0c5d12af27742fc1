"""The free flyer in the PyBullet world: a rigid body driven at its centre of mass.

The debris collector of the source thesis: one rigid body with the scenario's mass and
the principal moments of inertia ``robot.inertia`` (by default a uniform sphere's of its
radius), no joints. Its mass is set every control period from the propellant left; the
given moments scale with it, as a uniform body's would (the sphere's do the same).
"""

from __future__ import annotations

import numpy as np

from dcsim.messages import RobotSpec, Shape, ShapeKind
from dcsim.scenario.model import RobotSection, point_to_cartesian
from dcsim.world.bodies import create_body
from dcsim.world.pybullet_client import pb
from dcsim.world.robot_body import base_spec_fields


class FreeFlyerBody:
    """A free flyer's rigid body, colliding as a sphere
    (a :class:`~dcsim.world.robot_body.RobotBody`).

    Parameters
    ----------
    client : int
        PyBullet client id.
    robot : RobotSection
        The scenario's robot; the body starts at its initial state.
    """

    links: tuple[tuple[int, float], ...] = ()
    n_joints = 0

    def __init__(self, client: int, robot: RobotSection) -> None:
        self._client = client
        self.robot = robot
        initial = robot.initial
        position = point_to_cartesian(initial.position)
        self.body = create_body(
            client, Shape(ShapeKind.SPHERE, radius=robot.radius), robot.mass, position, False
        )
        if robot.inertia is not None:
            self.set_base_mass(robot.mass)
        attitude = np.asarray(initial.attitude) / np.linalg.norm(initial.attitude)
        pb.resetBasePositionAndOrientation(
            self.body, position.tolist(), attitude.tolist(), physicsClientId=client
        )
        pb.resetBaseVelocity(
            self.body,
            list(initial.velocity),
            list(initial.angular_velocity),
            physicsClientId=client,
        )

    def joint_state(self) -> tuple[np.ndarray, np.ndarray]:
        """No joints: two empty arrays."""
        return np.zeros(0), np.zeros(0)

    def clip_joint_torques(self, torques: np.ndarray) -> np.ndarray:
        """No joints: joint torques are ignored (an empty array)."""
        return np.zeros(0)

    def apply_joint_torques(self, torques: np.ndarray) -> None:
        """No joints: nothing to apply."""

    def set_base_mass(self, mass: float) -> None:
        """Set the body's mass, kg, and scale its inertia with it: ``robot.inertia`` is the
        inertia at the initial mass ``robot.mass`` (without it PyBullet gives the sphere's,
        2/5 m r²)."""
        if self.robot.inertia is None:
            pb.changeDynamics(self.body, -1, mass=mass, physicsClientId=self._client)
            return
        # PyBullet recomputes the collision sphere's inertia when only the mass changes
        moments = np.array(self.robot.inertia) * (mass / self.robot.mass)
        pb.changeDynamics(
            self.body,
            -1,
            mass=mass,
            localInertiaDiagonal=moments.tolist(),
            physicsClientId=self._client,
        )

    def spec(self, assembly_mass: float, base_mass: float, protrusion: float) -> RobotSpec:
        """Mass with cargo, the base's inertia as PyBullet holds it (body frame), limits,
        and the bounding radius grown by the cargo's protrusion."""
        inertia = pb.getDynamicsInfo(self.body, -1, physicsClientId=self._client)[2]
        return RobotSpec(
            **base_spec_fields(self.robot, assembly_mass, np.diag(inertia), protrusion)
        )

    def end_effector(self, configuration: np.ndarray) -> np.ndarray:
        """A free flyer has no end effector.

        Raises
        ------
        ValueError
            Always.
        """
        raise ValueError("a free flyer has no end effector")
