"""Messages of the debris mission's task planning: requests, plans, the drop point.

They follow the source thesis's topics (Plan, PlanTask). Vectors are read-only float
arrays in the world frame; times are scenario seconds.
"""

from __future__ import annotations

from numpy.typing import ArrayLike

from dcsim.geometry import Vector
from dcsim.messages.base import Message, array_field, message
from dcsim.messages.sensing import ObjectTrack
from dcsim.messages.state import StateEstimate
from dcsim.motion import MotionModel


@message
class DropPoint(Message):
    """Where collected targets are delivered.

    Attributes
    ----------
    motion : MotionModel
        The drop point's motion (static for a fixed point).
    tolerance : float
        Distance within which the collector counts as at the drop point, m.
    """

    motion: MotionModel
    tolerance: float

    def state_at(self, t: ArrayLike) -> tuple[Vector, Vector]:
        """Position and velocity of the drop point at time(s) ``t`` (s)."""
        return self.motion.state_at(t)


@message
class TaskRequest(Message):
    """What a task planner is asked to plan.

    Attributes
    ----------
    time : float
        Current time, s; every pickup must be later.
    robot : StateEstimate
        Where the robot believes it is.
    targets : tuple of ObjectTrack
        Targets currently tracked; only these may be planned.
    drop_point : DropPoint
        Where to deliver.
    capacity : int
        Targets the collector can carry at once.
    carried : int
        Targets already on board.
    max_speed : float
        Speed limit of the collector, m/s.
    max_acceleration : float
        Acceleration the collector can count on, m/s² (``inf`` for impulsive burns).
    time_budget : float
        Wall time the planner may spend, s.
    """

    time: float
    robot: StateEstimate
    targets: tuple[ObjectTrack, ...]
    drop_point: DropPoint
    capacity: int
    carried: int = 0
    max_speed: float = 1.0
    max_acceleration: float = float("inf")
    time_budget: float = 1.0


@message
class PlanTask(Message):
    """One pickup in a plan (the thesis's PlanTask message).

    Attributes
    ----------
    target_id : int
        Target to grab.
    pickup_time : float
        When to grab it, s.
    pickup_point : ndarray (3,)
        Where the target will be then, m.
    pickup_velocity : ndarray (3,)
        The target's velocity then, m/s.
    """

    target_id: int
    pickup_time: float
    pickup_point: Vector = array_field()
    pickup_velocity: Vector = array_field(default=(0.0, 0.0, 0.0))


@message
class DropVisit(Message):
    """A visit to the drop point inside a plan.

    Attributes
    ----------
    after_task : int
        Index (in ``Plan.tasks``) of the pickup after which the visit happens.
    time : float
        Planned arrival at the drop point, s.
    point : ndarray (3,)
        Where the drop point will be then, m.
    """

    after_task: int
    time: float
    point: Vector = array_field()


@message
class Plan(Message):
    """An ordered plan of pickups and drop visits (the thesis's Plan topic).

    Attributes
    ----------
    tasks : tuple of PlanTask
        Pickups in order, with strictly increasing pickup times.
    drop_visits : tuple of DropVisit
        Visits to the drop point, ordered; the last pickup is always followed by one.
    cost : float
        The planner's cost of the plan (see the planner's documentation for units).
    """

    tasks: tuple[PlanTask, ...] = ()
    drop_visits: tuple[DropVisit, ...] = ()
    cost: float = 0.0
