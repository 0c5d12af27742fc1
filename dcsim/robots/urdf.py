"""URDF text of a DH space manipulator, so that other tools load the same robot.

The base is the root link (floating in PyBullet; give Pinocchio a free-flyer root joint),
its link frame at its centre of mass with the base's axes. URDF link ``link_i`` has the
frame of DH frame ``i − 1`` turned by joint ``i`` (a URDF joint turns its child *after*
the joint's origin, a DH joint *before* its constant transform), so joint ``i``'s origin
is the constant part of DH step ``i − 1`` followed by ``θ`` offset ``i``. A fixed joint
puts the link ``end_effector`` at DH frame ``n``. Every link carries an explicit
``<inertial>`` (PyBullet gives a link without one 1 kg, Pinocchio 0 kg); the end
effector's is zero. Load it in PyBullet with ``URDF_USE_INERTIA_FROM_FILE``.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dcsim.robots.dh import DHLink, DHRobot

#: URDF joint limits written for an unlimited joint, rad.
UNLIMITED_ANGLE = 1.0e9
#: URDF effort and velocity written for an unlimited joint (N·m, rad/s).
UNLIMITED_EFFORT = 1.0e9
#: Radius of the links' collision cylinders, m.
LINK_RADIUS = 0.05


def _rot_x(angle: float) -> NDArray[np.float64]:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _rot_z(angle: float) -> NDArray[np.float64]:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rpy(rotation: NDArray[np.float64]) -> tuple[float, float, float]:
    """URDF roll, pitch, yaw (rad) of a rotation matrix ``R = Rz(yaw) Ry(pitch) Rx(roll)``."""
    pitch = math.asin(-max(-1.0, min(1.0, rotation[2, 0])))
    if abs(rotation[2, 0]) < 1.0 - 1e-12:
        roll = math.atan2(rotation[2, 1], rotation[2, 2])
        yaw = math.atan2(rotation[1, 0], rotation[0, 0])
    else:  # gimbal lock: put all of the remaining turn in yaw
        roll = 0.0
        yaw = math.atan2(-rotation[0, 1], rotation[1, 1])
    return roll, pitch, yaw


def _numbers(values) -> str:
    return " ".join(repr(float(v)) for v in values)


def _origin(xyz, rotation: NDArray[np.float64]) -> str:
    return f'<origin xyz="{_numbers(xyz)}" rpy="{_numbers(rpy(rotation))}"/>'


def _inertial(mass: float, xyz, rotation, moments) -> str:
    ixx, iyy, izz = (float(m) for m in moments)
    return (
        f'<inertial>{_origin(xyz, rotation)}<mass value="{float(mass)!r}"/>'
        f'<inertia ixx="{ixx!r}" ixy="0" ixz="0" iyy="{iyy!r}" iyz="0" izz="{izz!r}"/>'
        "</inertial>"
    )


def _segment_geometry(link: DHLink) -> str:
    """A collision and visual cylinder along link ``i``'s DH segment (in URDF link i)."""
    length = math.hypot(link.a, link.d)
    if length <= 0.0:
        return ""
    tilt = math.atan2(link.a, link.d)  # about y, from z to the segment (a, 0, d)
    c, s = math.cos(tilt), math.sin(tilt)
    rotation = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    origin = _origin((0.5 * link.a, 0.0, 0.5 * link.d), rotation)
    shape = f'<geometry><cylinder radius="{LINK_RADIUS!r}" length="{length!r}"/></geometry>'
    return f"<visual>{origin}{shape}</visual><collision>{origin}{shape}</collision>"


def box_link(name: str, mass: float, size: ArrayLike, moments: ArrayLike) -> str:
    """A URDF link: a box of edge lengths ``size`` (m) centred on the link's frame, with
    ``mass`` (kg) and principal ``moments`` (kg·m²) along the frame's axes."""
    box = f'<geometry><box size="{_numbers(size)}"/></geometry>'
    inertial = _inertial(mass, (0, 0, 0), np.eye(3), moments)
    shapes = f"<visual>{box}</visual><collision>{box}</collision>"
    return f'<link name="{name}">{inertial}{shapes}</link>'


def _base(robot: DHRobot) -> str:
    base = robot.base
    return box_link("base", base.mass, base.size, base.inertia)


def _arm_link(index: int, link: DHLink) -> str:
    com = (0.5 * link.a, 0.0, 0.5 * link.d)
    inertial = _inertial(link.mass, com, _rot_x(link.alpha), link.inertia)
    return f'<link name="link_{index}">{inertial}{_segment_geometry(link)}</link>'


def _joint(index: int, parent: str, xyz, rotation, link: DHLink) -> str:
    lower, upper = (max(-UNLIMITED_ANGLE, min(UNLIMITED_ANGLE, v)) for v in link.joint_limits)
    effort = min(link.torque_limit, UNLIMITED_EFFORT)
    return (
        f'<joint name="joint_{index}" type="revolute"><parent link="{parent}"/>'
        f'<child link="link_{index}"/>{_origin(xyz, rotation)}<axis xyz="0 0 1"/>'
        f'<limit lower="{lower!r}" upper="{upper!r}" effort="{effort!r}" '
        f'velocity="{UNLIMITED_EFFORT!r}"/><dynamics damping="0" friction="0"/></joint>'
    )


def urdf_text(robot: DHRobot) -> str:
    """URDF of ``robot``: the base, one revolute joint and link per DH row, the end effector.

    Parameters
    ----------
    robot : DHRobot
        The manipulator.

    Returns
    -------
    str
        URDF XML. Links ``base``, ``link_1`` … ``link_n``, ``end_effector``; joints
        ``joint_1`` … ``joint_n`` (revolute about their ``z``; limits beyond
        ±:data:`UNLIMITED_ANGLE` are clipped to it) and ``end_effector_joint`` (fixed).
    """
    parts = [f'<?xml version="1.0"?>\n<robot name="{robot.name}">', _base(robot)]
    xyz: ArrayLike = robot.base.mount
    parent, fixed = "base", np.eye(3)
    for index, link in enumerate(robot.links, start=1):
        parts.append(_arm_link(index, link))
        parts.append(_joint(index, parent, xyz, fixed @ _rot_z(link.theta_offset), link))
        parent, xyz, fixed = f"link_{index}", (link.a, 0.0, link.d), _rot_x(link.alpha)
    zero = _inertial(0.0, (0, 0, 0), np.eye(3), (0.0, 0.0, 0.0))
    parts.append(f'<link name="end_effector">{zero}</link>')
    parts.append(
        f'<joint name="end_effector_joint" type="fixed"><parent link="{parent}"/>'
        f'<child link="end_effector"/>{_origin(xyz, fixed)}</joint>'
    )
    parts.append("</robot>\n")
    return "\n".join(parts)
