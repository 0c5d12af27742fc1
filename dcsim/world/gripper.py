"""The manipulator's gripper: a palm and two pads that close on a grapple bar with contact.

The gripper is part of the arm's multibody: :func:`gripper_urdf` adds a ``palm`` link,
fixed to the ``end_effector`` link (DH frame n), and two pad links on prismatic joints
that slide along y_n towards each other. Each pad's drive is a PyBullet position motor
with the gripper's grip force as its force limit and a speed that closes the opening in
the closing time; what holds a bar is PyBullet's contact with friction between pads and
bar, nothing else. Palm and pads collide only with a tumbling body (collision group
:data:`GRIPPER_GROUP`); in a capture the arm's other links and its base do too
(:data:`ARM_GROUP`, set by the capture rig), so that an arm swinging into the body
strikes it, and a reading names them.

The arm's model (:class:`~dcsim.robots.manipulator.ManipulatorModel`, what controllers
are told) is the DH arm without the gripper; the gripper's few kilograms are a load the
controller does not know about.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dcsim.messages import Shape, ShapeKind
from dcsim.robots.urdf import box_link
from dcsim.scenario.model import GripperSpec
from dcsim.world.pybullet_client import pb

GRIPPER_GROUP = 2
"""Collision group of the palm and the pads."""
TUMBLING_GROUP = 4
"""Collision group of a tumbling body (it collides with the arm and its gripper only)."""
ARM_GROUP = 8
"""Collision group of a capturing arm's base and links other than palm and pads."""


def _box_link(name: str, mass: float, size: tuple[float, float, float]) -> str:
    """A URDF link: a uniform box of ``size`` (m) and ``mass`` (kg) centred on its frame."""
    moments = Shape(ShapeKind.BOX, half_extents=0.5 * np.array(size)).moments_of_inertia(mass)
    return box_link(name, mass, size, moments)


def gripper_urdf(spec: GripperSpec) -> str:
    """URDF links and joints of the gripper, to go inside the arm's ``<robot>``.

    Parameters
    ----------
    spec : GripperSpec
        The scenario's gripper.

    Returns
    -------
    str
        Links ``palm``, ``pad_left`` (+y_n side) and ``pad_right`` (−y_n side); joints
        ``palm_joint`` (fixed to ``end_effector``) and ``pad_left_joint``,
        ``pad_right_joint`` (prismatic, 0 when open, positive closing, up to half the
        opening).
    """
    palm_x = 0.5 * spec.palm_size[0]
    pad_x = spec.reach - palm_x
    pad_y = 0.5 * (spec.opening + spec.pad_size[1])
    travel = 0.5 * spec.opening
    parts = [
        _box_link("palm", spec.palm_mass, spec.palm_size),
        '<joint name="palm_joint" type="fixed"><parent link="end_effector"/>'
        f'<child link="palm"/><origin xyz="{palm_x!r} 0 0" rpy="0 0 0"/></joint>',
    ]
    for name, side in (("pad_left", 1.0), ("pad_right", -1.0)):
        parts.append(_box_link(name, spec.pad_mass, spec.pad_size))
        parts.append(
            f'<joint name="{name}_joint" type="prismatic"><parent link="palm"/>'
            f'<child link="{name}"/><origin xyz="{pad_x!r} {side * pad_y!r} 0" rpy="0 0 0"/>'
            f'<axis xyz="0 {-side!r} 0"/><limit lower="0" upper="{travel!r}" '
            f'effort="{spec.grip_force!r}" velocity="1000"/>'
            '<dynamics damping="0" friction="0"/></joint>'
        )
    return "\n".join(parts)


@dataclass(frozen=True)
class GripReading:
    """The arm's contact with a body at one physics step: the pads', the palm's and any
    other link's that strikes it.

    Attributes
    ----------
    normal : ndarray (2,)
        Total normal contact force on the left and the right pad, N.
    force : ndarray (3,)
        Total contact force (normal and friction) the arm puts on the body, world frame,
        N (the pads' while nothing else touches it).
    points : int
        Number of contact points between the arm (gripper, links, base) and the body
        that push (a positive normal force).
    struck : frozenset of int
        The arm's links other than palm and pads (-1 the base) pushing on the body.
    """

    normal: np.ndarray
    force: np.ndarray
    points: int
    struck: frozenset[int] = frozenset()


class Gripper:
    """The gripper's links in the arm's multibody, its pad drives and its contact readings.

    Parameters
    ----------
    client : int
        PyBullet client id.
    body : int
        The arm's multibody (loaded with :func:`gripper_urdf`'s links).
    spec : GripperSpec
        The scenario's gripper.

    Attributes
    ----------
    palm : int
        PyBullet link index of the palm.
    pads : tuple of int
        Link indices of the left and the right pad (also their joints' indices).
    closed : bool
        Whether the pads are commanded closed.
    """

    def __init__(self, client: int, body: int, spec: GripperSpec) -> None:
        self._client, self._body, self.spec = client, body, spec
        names = {
            pb.getJointInfo(body, j, physicsClientId=client)[12].decode(): j
            for j in range(pb.getNumJoints(body, physicsClientId=client))
        }
        self.palm = names["palm"]
        self.pads = (names["pad_left"], names["pad_right"])
        for link in (self.palm, *self.pads):
            pb.setCollisionFilterGroupMask(
                body, link, GRIPPER_GROUP, TUMBLING_GROUP, physicsClientId=client
            )
            pb.changeDynamics(body, link, lateralFriction=spec.friction, physicsClientId=client)
        # the pads move together (a parallel gripper's fingers are geared to one drive)
        gear = pb.createConstraint(
            body,
            self.pads[0],
            body,
            self.pads[1],
            pb.JOINT_GEAR,
            [0, 1, 0],
            [0, 0, 0],
            [0, 0, 0],
            physicsClientId=client,
        )
        pb.changeConstraint(gear, gearRatio=-1.0, maxForce=1e6, physicsClientId=client)
        self.closed = False
        self._drive(0.0)

    def command(self, closed: bool) -> None:
        """Close the pads (True) or open them (False), at the closing speed."""
        if closed != self.closed:
            self.closed = closed
            self._drive(0.5 * self.spec.opening if closed else 0.0)

    def _drive(self, target: float) -> None:
        """Send both pad drives towards joint position ``target`` (m)."""
        spec = self.spec
        speed = 0.5 * spec.opening / spec.closing_time
        for pad in self.pads:
            pb.setJointMotorControl2(
                self._body,
                pad,
                pb.POSITION_CONTROL,
                targetPosition=target,
                force=spec.grip_force,
                maxVelocity=speed,
                physicsClientId=self._client,
            )

    def centre(self) -> tuple[np.ndarray, np.ndarray]:
        """Position (m) and velocity (m/s) of the point between the pads' centres (where a
        held bar's centre sits), world frame."""
        link = pb.getLinkState(
            self._body, self.palm, computeLinkVelocity=1, physicsClientId=self._client
        )
        rotation = np.reshape(pb.getMatrixFromQuaternion(link[1]), (3, 3))
        lever = (self.spec.reach - 0.5 * self.spec.palm_size[0]) * rotation[:, 0]
        return np.asarray(link[0]) + lever, np.asarray(link[6]) + np.cross(link[7], lever)

    def pad_positions(self) -> np.ndarray:
        """How far each pad has closed from open, m (2,)."""
        states = pb.getJointStates(self._body, list(self.pads), physicsClientId=self._client)
        return np.array([s[0] for s in states])

    def contact(self, other: int) -> GripReading:
        """The arm's contact with body ``other`` now (after the last physics step): the
        pads' and the palm's, and any other link's that strikes it."""
        points = pb.getContactPoints(self._body, other, physicsClientId=self._client)
        normal = np.zeros(2)
        force = np.zeros(3)
        pushing = 0
        struck: set[int] = set()
        for point in points:
            if point[9] <= 0.0:  # within the contact margin, not touching
                continue
            pushing += 1
            # PyBullet's normal (index 7) points from the other body to the gripper; its
            # friction forces along the lateral directions (indices 10-13) are the ones on
            # the other body (measured: so summed, the impulse is the body's momentum
            # change to 1e-15)
            force += (
                point[10] * np.asarray(point[11])
                + point[12] * np.asarray(point[13])
                - point[9] * np.asarray(point[7])
            )
            if point[3] in self.pads:
                normal[self.pads.index(point[3])] += point[9]
            elif point[3] != self.palm:
                struck.add(point[3])
        return GripReading(normal=normal, force=force, points=pushing, struck=frozenset(struck))
