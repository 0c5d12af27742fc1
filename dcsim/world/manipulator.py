"""The space manipulator in the PyBullet world: a floating-base multibody from dcsim's URDF.

The URDF is the one :func:`dcsim.robots.urdf.urdf_text` writes from the scenario's DH
description, loaded with the file's inertias (``URDF_USE_INERTIA_FROM_FILE``); the base
and every link have no damping and the joints' velocity motors are off, so joint
torques are the only joint actuation (../shared/PITFALLS.md). A gripper, when the robot
has one, adds its palm and pads (:mod:`~dcsim.world.gripper`). PyBullet's base position
is the base's centre of mass, which is where the URDF puts the base link's origin: the
base state read back is the model's (``q``'s base part). Collision response is off, as
for every body of the world.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from dcsim.messages import RobotSpec
from dcsim.robots.manipulator import ManipulatorModel
from dcsim.scenario.model import ManipulatorSection, point_to_cartesian
from dcsim.world.gripper import gripper_urdf
from dcsim.world.pybullet_client import MAX_SPEED, load_urdf, pb
from dcsim.world.robot_body import base_spec_fields


class ManipulatorBody:
    """The manipulator's multibody and its joints (a :class:`~dcsim.world.robot_body.RobotBody`).

    Parameters
    ----------
    client : int
        PyBullet client id.
    robot : ManipulatorSection
        The scenario's robot; the body starts at its initial state.

    Attributes
    ----------
    body : int
        The multibody's id (its base is index -1).
    joints : list of int
        PyBullet joint indices of the revolute joints, from the base outwards.
    links : tuple of (int, float)
        PyBullet link index and mass (kg) of every arm link with mass.
    torque_limits : ndarray (n,)
        Largest joint torque magnitudes, N·m (``inf``: unlimited).
    position_limits : ndarray (n, 2)
        Lower and upper joint angle limits, rad.
    model : ManipulatorModel
        The arm's kinematics and dynamics with its initial base mass.
    """

    def __init__(self, client: int, robot: ManipulatorSection) -> None:
        self._client = client
        self.section = robot
        self.robot = robot.dh_robot()
        self.model = ManipulatorModel(self.robot)
        self.body = load_urdf(client, self._urdf(robot))
        count = pb.getNumJoints(self.body, physicsClientId=client)
        self.joints = [
            j
            for j in range(count)
            if pb.getJointInfo(self.body, j, physicsClientId=client)[2] == pb.JOINT_REVOLUTE
        ]
        self.torque_limits = self.robot.column("torque_limit")
        self.position_limits = np.array([link.joint_limits for link in self.robot.links])
        for link in (-1, *range(count)):
            pb.changeDynamics(
                self.body,
                link,
                linearDamping=0,
                angularDamping=0,
                maxJointVelocity=MAX_SPEED,
                physicsClientId=client,
            )
            pb.setCollisionFilterGroupMask(self.body, link, 0, 0, physicsClientId=client)
        pb.setJointMotorControlArray(
            self.body,
            self.joints,
            pb.VELOCITY_CONTROL,
            forces=[0.0] * len(self.joints),
            physicsClientId=client,
        )
        self._reset(robot)
        self.links = self._link_masses()
        self._base_mass = robot.mass

    def _urdf(self, robot: ManipulatorSection) -> str:
        """The model's URDF, with the gripper's links when the robot has one."""
        text = self.model.urdf()
        if robot.gripper is None:
            return text
        end = text.rindex("</robot>")
        return f"{text[:end]}{gripper_urdf(robot.gripper)}\n{text[end:]}"

    def _reset(self, robot: ManipulatorSection) -> None:
        """Put the body at the scenario's initial state."""
        initial, client = robot.initial, self._client
        attitude = np.asarray(initial.attitude) / np.linalg.norm(initial.attitude)
        position = point_to_cartesian(initial.position)
        pb.resetBasePositionAndOrientation(
            self.body, position.tolist(), attitude.tolist(), physicsClientId=client
        )
        angles, rates = robot.initial_joints()
        for joint, angle, rate in zip(self.joints, angles, rates, strict=True):
            pb.resetJointState(self.body, joint, float(angle), float(rate), physicsClientId=client)
        velocity, angular = list(initial.velocity), list(initial.angular_velocity)
        pb.resetBaseVelocity(self.body, velocity, angular, physicsClientId=client)

    @property
    def n_joints(self) -> int:
        """Number of joints."""
        return len(self.joints)

    def clip_joint_torques(self, torques: np.ndarray) -> np.ndarray:
        """Joint torques (n,) clipped to the limits, N·m (zeros when none are given).

        Raises
        ------
        ValueError
            If ``torques`` has neither zero nor ``n`` values.
        """
        torques = np.asarray(torques, dtype=float).reshape(-1)
        if torques.size == 0:
            return np.zeros(self.n_joints)
        if torques.size != self.n_joints:
            raise ValueError(f"{torques.size} joint torques for {self.n_joints} joints")
        return np.clip(torques, -self.torque_limits, self.torque_limits)

    def apply_joint_torques(self, torques: np.ndarray) -> None:
        """Set the joint torques for the next physics step (PyBullet clears them after it)."""
        pb.setJointMotorControlArray(
            self.body,
            self.joints,
            pb.TORQUE_CONTROL,
            forces=torques.tolist(),
            physicsClientId=self._client,
        )

    def brake(self) -> None:
        """Lock every joint with its brake: a velocity motor held at rest that gives at
        most the joint's torque limit (a joint loaded beyond it slips). Joint torques
        applied afterwards add to the brakes' own."""
        limits = np.minimum(self.torque_limits, MAX_SPEED)
        pb.setJointMotorControlArray(
            self.body,
            self.joints,
            pb.VELOCITY_CONTROL,
            targetVelocities=[0.0] * self.n_joints,
            forces=limits.tolist(),
            physicsClientId=self._client,
        )

    def joint_state(self) -> tuple[np.ndarray, np.ndarray]:
        """Joint angles (rad) and rates (rad/s), (n,) each."""
        states = pb.getJointStates(self.body, self.joints, physicsClientId=self._client)
        return np.array([s[0] for s in states]), np.array([s[1] for s in states])

    def _link_masses(self) -> tuple[tuple[int, float], ...]:
        """PyBullet link index and mass of every link with mass (the arm's links)."""
        client = self._client
        found = []
        for link in range(pb.getNumJoints(self.body, physicsClientId=client)):
            mass = pb.getDynamicsInfo(self.body, link, physicsClientId=client)[0]
            if mass > 0:
                found.append((link, mass))
        return tuple(found)

    def set_base_mass(self, mass: float) -> None:
        """Change the base's mass (propellant used), kg, keeping the file's inertia.

        PyBullet is called only when the mass differs from the one it holds.
        """
        if mass == self._base_mass:
            return
        pb.changeDynamics(
            self.body,
            -1,
            mass=mass,
            localInertiaDiagonal=self.robot.base.inertia.tolist(),
            physicsClientId=self._client,
        )
        self._base_mass = mass

    def spec(self, assembly_mass: float, base_mass: float, protrusion: float) -> RobotSpec:
        """Total mass, the base's inertia, limits, joint limits and the model.

        The model (:class:`~dcsim.robots.manipulator.ManipulatorModel`) has the base's
        mass ``base_mass`` (propellant used so far).
        """
        inertia = pb.getDynamicsInfo(self.body, -1, physicsClientId=self._client)[2]
        model = self.model
        if model.robot.base.mass != base_mass:
            base = dataclasses.replace(model.robot.base, mass=base_mass)
            model = ManipulatorModel(dataclasses.replace(model.robot, base=base))
        return RobotSpec(
            **base_spec_fields(self.section, assembly_mass, np.diag(inertia), protrusion),
            joint_position_limits=self.position_limits,
            joint_torque_limits=self.torque_limits,
            model=model,
        )

    def end_effector(self, configuration: np.ndarray) -> np.ndarray:
        """End-effector position (origin of DH frame n) at ``configuration``, world frame, m."""
        return self.model.forward_kinematics(configuration).end_effector
