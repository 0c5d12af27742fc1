"""Where each target and obstacle is at the viewer's frames, and whether it is shown.

A free object is where its motion model puts it (the world moves it exactly so). A
grabbed target is held as it was at the grab, fixed to the robot's base (the world's
grab service attaches it so): it moves and turns with the base until it is delivered,
when it leaves the world. Grabs and deliveries come from the run's event log. A
capture's tumbling body is where its telemetry columns put it (``target_x`` … and
``target_qx`` …), latched or not.
"""

from __future__ import annotations

import enum
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from dcsim.messages import ObjectKind
from dcsim.motion import MotionSet, StaticMotion
from dcsim.report.viewer.robot import RobotPath
from dcsim.scenario.model import Scenario
from dcsim.world.objects import SpaceObject, build_objects


class Status(enum.IntEnum):
    """An object's state at a frame, as the page shows it."""

    FREE = 0
    CARRIED = 1
    DELIVERED = 2


@dataclass(frozen=True)
class ObjectTrack:
    """One object over the viewer's frames.

    Attributes
    ----------
    object : SpaceObject
        The object: id, kind, shape (its fixed orientation applied to the shape).
    positions : ndarray (F, 3)
        Centre at each frame, m, world frame.
    turns : ndarray (F, 4) or None
        Rotation of the object at each frame (``[x, y, z, w]``): since its grab for a
        grabbed target (identity while free), its attitude for a tumbling body; None for
        an object never grabbed.
    status : ndarray (F,) of int
        :class:`Status` at each frame.
    """

    object: SpaceObject
    positions: np.ndarray
    turns: np.ndarray | None
    status: np.ndarray


@dataclass(frozen=True)
class Handling:
    """When targets were grabbed and delivered, from the event log.

    Attributes
    ----------
    grabbed : dict of int to float
        Target id to the time of its successful grab, s.
    delivered : dict of int to float
        Target id to the time of its delivery, s.
    """

    grabbed: dict[int, float]
    delivered: dict[int, float]

    @classmethod
    def from_events(cls, events: Sequence[Mapping[str, Any]]) -> Handling:
        """Successful ``grab`` events and the targets of ``release`` events."""
        grabbed = {
            int(e["target"]): float(e["t"])
            for e in events
            if e["event"] == "grab" and e.get("success") and "target" in e
        }
        delivered = {
            int(target): float(e["t"])
            for e in events
            if e["event"] == "release"
            for target in e.get("delivered") or ()
        }
        return cls(grabbed, delivered)

    def counts(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Targets captured and delivered by each of ``times`` (s), (F,) each."""
        captured = np.searchsorted(np.sort(list(self.grabbed.values())), times, side="right")
        delivered = np.searchsorted(np.sort(list(self.delivered.values())), times, side="right")
        return captured, delivered


def object_tracks(
    scenario: Scenario,
    times: np.ndarray,
    robot: RobotPath,
    handling: Handling,
    telemetry: Mapping[str, np.ndarray],
) -> list[ObjectTrack]:
    """Every target and obstacle at ``times``, targets first (a capture's tumbling body
    first of all).

    Parameters
    ----------
    scenario : Scenario
        The run's scenario: the objects, their shapes and motion models.
    times : ndarray (F,)
        The frames' times, s.
    robot : RobotPath
        The robot's base at every telemetry row (a carried target follows it).
    handling : Handling
        Grab and delivery times.
    telemetry : mapping of str to ndarray
        The run's telemetry (a tumbling body's pose).
    """
    tumbling = _tumbling_track(scenario, times, robot, telemetry)
    objects = build_objects(scenario)
    if not objects:
        return tumbling
    motions = MotionSet([o.motion for o in objects])
    free = np.stack([motions.state_at(float(t))[0] for t in times], axis=1)  # (N, F, 3)
    return tumbling + [
        _track(obj, times, positions, robot, handling)
        for obj, positions in zip(objects, free, strict=True)
    ]


def _tumbling_track(
    scenario: Scenario,
    times: np.ndarray,
    robot: RobotPath,
    telemetry: Mapping[str, np.ndarray],
) -> list[ObjectTrack]:
    """A capture's tumbling body at ``times`` from its pose columns (none without): its
    attitude as its ``turns``, never delivered."""
    spec = scenario.mission.tumbling_body()
    if spec is None or "target_x" not in telemetry:
        return []
    rows = robot.row_at(times)
    position = np.column_stack([telemetry[f"target_{a}"] for a in "xyz"])[rows]
    attitude = np.column_stack([telemetry[f"target_q{a}"] for a in "xyzw"])[rows]
    status = np.full(len(times), Status.FREE, dtype=int)
    body = SpaceObject(
        spec.id, ObjectKind.TARGET, spec.shape.build(), spec.mass, StaticMotion(spec.position)
    )
    return [ObjectTrack(body, position, attitude, status)]


def _track(
    obj: SpaceObject, times: np.ndarray, free: np.ndarray, robot: RobotPath, handling: Handling
) -> ObjectTrack:
    grabbed = handling.grabbed.get(obj.id, np.inf)
    delivered = handling.delivered.get(obj.id, np.inf)
    status = np.full(len(times), Status.FREE, dtype=int)
    status[times >= grabbed] = Status.CARRIED
    status[times >= delivered] = Status.DELIVERED
    if not np.isfinite(grabbed):
        return ObjectTrack(obj, free, None, status)
    positions, turns = _carried(obj, grabbed, times, robot)
    held = times >= grabbed
    turns[~held] = _IDENTITY
    return ObjectTrack(obj, np.where(held[:, None], positions, free), turns, status)


def _carried(
    obj: SpaceObject, grabbed: float, times: np.ndarray, robot: RobotPath
) -> tuple[np.ndarray, np.ndarray]:
    """Centre and rotation since the grab at ``times`` of ``obj`` held by the base from
    ``grabbed`` (s) on, as it was then."""
    at_grab = robot.row_at(np.array([grabbed]))
    base_at_grab = robot.rotations(at_grab)[0]
    offset = base_at_grab.inv().apply(obj.motion.position_at(grabbed) - robot.positions[at_grab][0])
    rows = robot.row_at(times)
    base = robot.rotations(rows)
    positions = robot.positions[rows] + base.apply(offset)
    turns = (base * base_at_grab.inv()).as_quat()
    return positions, np.atleast_2d(turns)


_IDENTITY = np.array([0.0, 0.0, 0.0, 1.0])
