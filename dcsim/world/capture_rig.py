"""The world's capture hardware: the gripper, a tumbling body, their contact and the latch.

A world whose manipulator has a gripper and whose mission puts a tumbling body into it
has a :class:`CaptureRig`. After every physics step the rig reads the contact between
arm and body (PyBullet's contact points: normal and friction forces; the pads', the
palm's, and any other link's or the base's that strikes the body), hands the body
from its torque-free motion to PyBullet at the first touch
(:class:`~dcsim.world.tumbling_body.TumblingBody`), and keeps each control period's
peak contact force and contact impulse. A mission commands the pads and, once it judges
the grip held, latches: a fixed constraint between palm and body at their relative pose
then (as a real end effector rigidises after its snares or fingers have closed), and the
arm's joint brakes come on, so that the stack turns as one body while the base's
attitude control takes its angular momentum out. The latch's force is read from the
constraint and counts against the gripper's force limit as the contact force does.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from dcsim.messages import ObjectKind, ObjectTrack
from dcsim.scenario.model import GripperSpec, TumblingBodySpec
from dcsim.world.gripper import ARM_GROUP, TUMBLING_GROUP, Gripper, GripReading
from dcsim.world.manipulator import ManipulatorBody
from dcsim.world.pybullet_client import pb
from dcsim.world.tumbling_body import BodyState, TumblingBody


@dataclass
class ContactRecord:
    """The arm's contact with the body over one control period (the gripper's, and any
    other link's that strikes it).

    Attributes
    ----------
    peak_force : float
        Largest magnitude of the total force on the body (contact, or latch once
        latched) at any physics step of the period, N.
    impulse : ndarray (3,)
        Contact impulse given to the body over the period, world frame, N·s.
    last : GripReading or None
        The reading after the period's last physics step (None before any reading).
    struck : set of int
        The arm's links other than palm and pads (-1 the base) that pushed on the body
        at any physics step of the period.
    """

    peak_force: float = 0.0
    impulse: np.ndarray = field(default_factory=lambda: np.zeros(3))
    last: GripReading | None = None
    struck: set[int] = field(default_factory=set)


class CaptureRig:
    """The gripper and the tumbling body of a world, stepped with it.

    Parameters
    ----------
    client : int
        PyBullet client id.
    arm : ManipulatorBody
        The manipulator (its multibody has the gripper's links).
    gripper : GripperSpec
        The robot's gripper.
    target : TumblingBodySpec
        The mission's tumbling body.
    physics_step : float
        s.

    Attributes
    ----------
    gripper : Gripper
        The pads and their drives.
    target : TumblingBody
        The tumbling body.
    latched : bool
        Whether the latch holds the body.
    period : ContactRecord
        The latest control period's contact (reset at each period's start).
    """

    def __init__(
        self,
        client: int,
        arm: ManipulatorBody,
        gripper: GripperSpec,
        target: TumblingBodySpec,
        physics_step: float,
    ) -> None:
        self._client, self._robot, self._dt = client, arm.body, physics_step
        self._arm = arm
        self.gripper = Gripper(client, arm.body, gripper)
        self.target = TumblingBody(client, target, physics_step)
        self._target_shape = target.shape.build()  # its exact tracks' shape
        held = {self.gripper.palm, *self.gripper.pads}
        for link in range(-1, pb.getNumJoints(arm.body, physicsClientId=client)):
            if link not in held:
                pb.setCollisionFilterGroupMask(
                    arm.body, link, ARM_GROUP, TUMBLING_GROUP, physicsClientId=client
                )
        self.latched = False
        self._latch: int | None = None
        self.period = ContactRecord()

    def begin_period(self) -> None:
        """Start a new control period's contact record."""
        self.period = ContactRecord(last=self.period.last)

    def after_step(self) -> None:
        """Read the contact after a physics step and move the body on if it is free."""
        reading = self.gripper.contact(self.target.body)
        self.target.after_step(reading.points > 0)
        force = reading.force
        if self._latch is not None:
            force = force + self._latch_force()
        record = self.period
        record.peak_force = max(record.peak_force, float(np.linalg.norm(force)))
        record.impulse = record.impulse + self._dt * reading.force
        record.last = reading
        if reading.struck:
            record.struck |= reading.struck

    def _latch_force(self) -> np.ndarray:
        """The force the latch puts on the body now, world frame, N."""
        assert self._latch is not None
        # PyBullet gives the force on the parent (the palm), N, not an impulse: measured,
        # it times the step is the body's momentum change less the contact impulse
        forces = pb.getConstraintState(self._latch, physicsClientId=self._client)
        return -np.asarray(forces[:3])

    def latch(self) -> None:
        """Hold the body rigidly to the palm as they are now, and brake the arm's joints
        (once): the stack is then one body, as far as the brakes hold."""
        if self._latch is not None:
            return
        self._arm.brake()
        client, palm = self._client, self.gripper.palm
        link = pb.getLinkState(self._robot, palm, physicsClientId=client)
        body_position, body_attitude = pb.getBasePositionAndOrientation(
            self.target.body, physicsClientId=client
        )
        inverse = pb.invertTransform(link[0], link[1])
        local_position, local_attitude = pb.multiplyTransforms(
            inverse[0], inverse[1], body_position, body_attitude
        )
        self._latch = pb.createConstraint(
            self._robot,
            palm,
            self.target.body,
            -1,
            pb.JOINT_FIXED,
            [0, 0, 0],
            parentFramePosition=local_position,
            childFramePosition=[0, 0, 0],
            parentFrameOrientation=local_attitude,
            physicsClientId=client,
        )
        pb.changeConstraint(self._latch, maxForce=1e9, physicsClientId=client)
        self.latched = True

    def link_name(self, link: int) -> str:
        """The name of the arm's link ``link`` (``base`` for -1)."""
        if link < 0:
            return "base"
        info = pb.getJointInfo(self._robot, link, physicsClientId=self._client)
        return str(info[12].decode())

    def target_state(self) -> BodyState:
        """The tumbling body's true state now."""
        return self.target.state()

    def fixture_from_pads(self, target: BodyState | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Position (m) and velocity (m/s) of the bar's centre relative to the point
        between the pads, world frame: zero when the bar sits still in the grip.
        ``target`` is the body's state now, if already read."""
        centre, velocity = self.gripper.centre()
        state = self.target.state() if target is None else target
        return state.fixture - centre, state.fixture_velocity - velocity

    def target_track(self, time: float) -> ObjectTrack:
        """The tumbling body as ideal sensing reports it at ``time`` (s): its true pose,
        velocities, shape and inertia."""
        state = self.target.state()
        spec = self.target.spec
        return ObjectTrack(
            id=spec.id,
            kind=ObjectKind.TARGET,
            time=time,
            position=state.position,
            velocity=state.velocity,
            mass=spec.mass,
            shape=self._target_shape,
            attitude=state.attitude,
            angular_velocity=state.angular_velocity,
            inertia=self.target.inertia,
        )
