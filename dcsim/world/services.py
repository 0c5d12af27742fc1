"""The world's mission services: grab a target, release the cargo at the drop point.

They follow the source thesis's Grab and Release services. A grabbed target is held by
a fixed constraint and moves with the collector until it is released at the drop point,
where it counts as delivered and leaves the world.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dcsim.messages import DropPoint
from dcsim.scenario.model import RobotSection
from dcsim.world.bodies import ObjectBodies, surface_gap
from dcsim.world.objects import ObjectField, ObjectStatus
from dcsim.world.pybullet_client import pb

_CONSTRAINT_FORCE = 1e9  # N; a grabbed target must not slip


@dataclass(frozen=True)
class GrabResult:
    """Outcome of a grab: success, and why not.

    Attributes
    ----------
    success : bool
        Whether the target is now held.
    target_id : int
        The target asked for.
    reason : str
        ``"grabbed"`` or why not.
    gap : float
        Surface gap between the collector and the target, m (nan if not measured).
    """

    success: bool
    target_id: int
    reason: str
    gap: float


@dataclass(frozen=True)
class ReleaseResult:
    """Outcome of a release: the targets delivered, and why none if so.

    Attributes
    ----------
    delivered : tuple of int
        Ids of the targets delivered (empty if refused).
    reason : str
        ``"delivered"`` or why not.
    """

    delivered: tuple[int, ...]
    reason: str


class Cargo:
    """The targets the collector holds, changed by the grab and release services.

    Parameters
    ----------
    client : int
        PyBullet client id.
    collector : int
        The collector's body id.
    field : ObjectField
        The world's objects (their status changes here).
    bodies : ObjectBodies
        The objects' bodies (a grabbed target's becomes dynamic).
    robot : RobotSection
        Grab distance, capacity and radius of the collector.

    Attributes
    ----------
    held : dict of int to (int, int)
        Object index of each carried target to its body and constraint ids.
    protrusion : float
        How far the cargo's bounding spheres reach beyond the collector's surface, m (0
        if none).
    changes : int
        Grabs and releases so far (each changes the robot's mass and shape).
    """

    def __init__(
        self,
        client: int,
        collector: int,
        field: ObjectField,
        bodies: ObjectBodies,
        robot: RobotSection,
    ) -> None:
        self._client = client
        self._collector = collector
        self._field = field
        self._bodies = bodies
        self._robot = robot
        self.held: dict[int, tuple[int, int]] = {}
        self.protrusion = 0.0
        self.changes = 0

    @property
    def mass(self) -> float:
        """Mass of the targets held, kg."""
        return sum(self._field.objects[i].mass for i in self.held)

    def spheres(self) -> list[tuple[np.ndarray, float]]:
        """Centre (m, world frame) and bounding-sphere radius (m) of every target held."""
        spheres = []
        for index, (body, _) in self.held.items():
            p, _ = pb.getBasePositionAndOrientation(body, physicsClientId=self._client)
            spheres.append((np.array(p), self._field.objects[index].radius))
        return spheres

    def grab(
        self, target_id: int, time: float, position: np.ndarray, attitude: np.ndarray
    ) -> GrabResult:
        """Try to grab target ``target_id`` (the thesis's Grab service).

        Succeeds when the target is free, the collector has room, and the gap between
        the two surfaces is at most ``robot.grab_distance``. The target is then attached
        by a fixed constraint and moves with the collector.

        Parameters
        ----------
        target_id : int
            The target's id.
        time : float
            Now, s.
        position, attitude : ndarray
            The collector's position (m) and attitude ``[x, y, z, w]`` now, world frame.
        """
        index = self._field.index.get(target_id)
        if index is None or not self._field.is_target[index]:
            return GrabResult(False, target_id, "no such target", float("nan"))
        if self._field.status[index] != ObjectStatus.FREE:
            return GrabResult(False, target_id, "target is not free", float("nan"))
        if len(self.held) >= self._robot.capacity:
            return GrabResult(
                False, target_id, f"capacity {self._robot.capacity} reached", float("nan")
            )
        reach = self._robot.grab_distance
        body = self._bodies.place(index, time)
        gap = surface_gap(self._client, self._collector, body, reach + 1.0)
        if gap > reach:
            return GrabResult(
                False, target_id, f"out of reach: gap {gap:.3f} m > {reach:g} m", float(gap)
            )
        self._attach(index, time, position, attitude)
        return GrabResult(True, target_id, "grabbed", float(gap))

    def release(self, position: np.ndarray, drop_point: DropPoint, time: float) -> ReleaseResult:
        """Release every target held if the collector is at the drop point.

        Released targets count as delivered and leave the world.

        Parameters
        ----------
        position : ndarray (3,)
            The collector's position now, world frame, m.
        drop_point : DropPoint
            Where, and within what tolerance, cargo is delivered.
        time : float
            Now, s.
        """
        if not self.held:
            return ReleaseResult((), "nothing carried")
        distance = float(np.linalg.norm(position - drop_point.state_at(time)[0]))
        if distance > drop_point.tolerance:
            return ReleaseResult(
                (),
                f"{distance:.3f} m from the drop point (tolerance {drop_point.tolerance:g} m)",
            )
        delivered = []
        for index, (body, constraint) in self.held.items():
            pb.removeConstraint(constraint, physicsClientId=self._client)
            pb.removeBody(body, physicsClientId=self._client)
            self._field.set_status(index, ObjectStatus.DELIVERED)
            delivered.append(self._field.objects[index].id)
        self.held.clear()
        self.protrusion = 0.0
        self.changes += 1
        return ReleaseResult(tuple(delivered), "delivered")

    def _attach(self, index: int, time: float, position: np.ndarray, attitude: np.ndarray) -> None:
        """Hold object ``index`` as it is now (position and orientation), fixed to the collector."""
        obj = self._field.objects[index]
        at, velocity = (a.copy() for a in obj.motion.state_at(time))
        body = self._bodies.make_dynamic(index, at, velocity)
        inverse = pb.invertTransform(position.tolist(), attitude.tolist())
        local_position, local_attitude = pb.multiplyTransforms(
            inverse[0], inverse[1], at.tolist(), obj.shape.orientation.tolist()
        )
        constraint = pb.createConstraint(
            self._collector,
            -1,
            body,
            -1,
            pb.JOINT_FIXED,
            [0, 0, 0],
            parentFramePosition=local_position,
            childFramePosition=[0, 0, 0],
            parentFrameOrientation=local_attitude,
            physicsClientId=self._client,
        )
        pb.changeConstraint(constraint, maxForce=_CONSTRAINT_FORCE, physicsClientId=self._client)
        self.held[index] = (body, constraint)
        self.protrusion = self._measure_protrusion(position)
        self.changes += 1
        self._field.set_status(index, ObjectStatus.CARRIED)

    def _measure_protrusion(self, centre: np.ndarray) -> float:
        radius = self._robot.radius
        return max(
            (np.linalg.norm(c - centre) + r - radius for c, r in self.spheres()), default=0.0
        )
