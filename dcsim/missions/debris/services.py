"""The debris mission's services: grab a target, release the cargo at the drop point.

They follow the source thesis's Grab and Release services, built on the world's payload
(:meth:`~dcsim.missions.base.MissionWorld.attach` and
:meth:`~dcsim.missions.base.MissionWorld.remove_payload`): a grabbed target is held by a
fixed constraint and moves with the collector until it is released at the drop point,
where it counts as delivered and leaves the world.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dcsim.messages import DropPoint
from dcsim.missions.base import MissionWorld
from dcsim.world.objects import ObjectStatus

_GAP_SEARCH = 1.0
"""How far beyond the grab distance a refused grab still measures the gap, m."""


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
        Surface gap between the collector and the target, m (nan if not measured; inf if
        farther than the grab distance plus 1 m).
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


def grab(world: MissionWorld, target_id: int, capacity: int, grab_distance: float) -> GrabResult:
    """Try to grab target ``target_id`` (the thesis's Grab service).

    Succeeds when the target is free, the collector holds fewer than ``capacity``
    targets, and the gap between the two surfaces is at most ``grab_distance`` (m). The
    target is then held rigidly and moves with the collector.
    """
    field = world.field
    index = field.index.get(target_id)
    if index is None or not field.is_target[index]:
        return GrabResult(False, target_id, "no such target", float("nan"))
    if field.status[index] != ObjectStatus.FREE:
        return GrabResult(False, target_id, "target is not free", float("nan"))
    if len(world.carried_ids()) >= capacity:
        return GrabResult(False, target_id, f"capacity {capacity} reached", float("nan"))
    gap = world.surface_gap(target_id, grab_distance + _GAP_SEARCH)
    if gap > grab_distance:
        return GrabResult(
            False, target_id, f"out of reach: gap {gap:.3f} m > {grab_distance:g} m", float(gap)
        )
    world.attach(target_id)
    return GrabResult(True, target_id, "grabbed", float(gap))


def release(world: MissionWorld, drop_point: DropPoint) -> ReleaseResult:
    """Release every carried target if the collector is at the drop point (the thesis's
    Release service).

    Released targets count as delivered and leave the world.

    Parameters
    ----------
    world : MissionWorld
        The world.
    drop_point : DropPoint
        Where, and within what tolerance, cargo is delivered.
    """
    if not world.carried_ids():
        return ReleaseResult((), "nothing carried")
    state = world.robot_state()
    distance = float(np.linalg.norm(state.position - drop_point.state_at(state.time)[0]))
    if distance > drop_point.tolerance:
        return ReleaseResult(
            (),
            f"{distance:.3f} m from the drop point (tolerance {drop_point.tolerance:g} m)",
        )
    return ReleaseResult(world.remove_payload(), "delivered")
