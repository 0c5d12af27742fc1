"""Space objects (targets and obstacles) as the world keeps them, and the field of them all."""

from __future__ import annotations

import enum
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from dcsim.messages import ObjectKind, Shape, ShapeKind
from dcsim.motion import MotionModel, MotionSet
from dcsim.scenario.model import Scenario
from dcsim.world.orbit.bounded import energy_matched_velocity
from dcsim.world.orbit.chief import orbit_period, orbit_potential, relative_dynamics
from dcsim.world.orbit.objects import ObjectOrbits, PropagatedMotion
from dcsim.world.orbit.relative import RelativeDynamics


class ObjectStatus(enum.IntEnum):
    """Where an object is in its life: free in space, carried by the robot, or removed
    from the world (the debris mission's delivered targets)."""

    FREE = 0
    CARRIED = 1
    REMOVED = 2


@dataclass(frozen=True)
class SpaceObject:
    """A target or an obstacle.

    Attributes
    ----------
    id : int
        Unique id.
    kind : ObjectKind
        Target or obstacle.
    shape : Shape
        Collision shape, centred on the object's position, its orientation fixed.
    mass : float
        Mass, kg.
    motion : MotionModel
        Motion followed exactly while the object is free.
    radius : float
        Radius of the shape's bounding sphere, m (computed once).
    """

    id: int
    kind: ObjectKind
    shape: Shape
    mass: float
    motion: MotionModel
    radius: float = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "radius", self.shape.bounding_radius)


_FREE = int(ObjectStatus.FREE)


def build_objects(
    scenario: Scenario, dynamics: RelativeDynamics | None = None
) -> list[SpaceObject]:
    """The mission's targets and the scenario's obstacles as world objects (targets
    first).

    In a ``two-body`` or ``j2`` world each motion spec gives only the object's state at
    t = 0; the objects then move under the world's orbit model (``dynamics``, built from
    the scenario's orbit if not given).
    """
    n = scenario.mean_motion
    specs = [
        (kind, spec)
        for kind, specs in (
            (ObjectKind.TARGET, scenario.mission.target_specs()),
            (ObjectKind.OBSTACLE, scenario.obstacles),
        )
        for spec in specs
    ]
    motions = [spec.motion.build(n) for _, spec in specs]
    orbit = scenario.world.orbit
    if scenario.world.frame == "lvlh" and orbit.model != "cw" and motions:
        world = scenario.world
        clock = (world.physics_step, round(world.control_period / world.physics_step))
        dynamics = dynamics or relative_dynamics(orbit)
        starts = [m.state_at(0.0) for m in motions]
        potential = orbit_potential(orbit)
        starts = [
            (p, energy_matched_velocity(dynamics, potential, p, v) if _bounded(spec) else v)
            for (p, v), (_, spec) in zip(starts, specs, strict=True)
        ]
        motions = _propagated(starts, dynamics, orbit_period(orbit), clock)
    return [
        SpaceObject(spec.id, kind, spec.build_shape(), spec.mass, motion)
        for (kind, spec), motion in zip(specs, motions, strict=True)
    ]


def _bounded(spec: Any) -> bool:
    """Whether an object's motion spec asks for a drift-free start."""
    return bool(getattr(spec.motion, "bounded", False))


def _propagated(
    starts: list[tuple[np.ndarray, np.ndarray]],
    dynamics: RelativeDynamics,
    period: float,
    clock: tuple[float, int],
) -> list[MotionModel]:
    """Motions under the world's orbit model from the objects' LVLH states at t = 0
    (``clock``: the world's physics step, s, and steps per control period)."""
    orbits = ObjectOrbits(
        dynamics,
        np.array([p for p, _ in starts]),
        np.array([v for _, v in starts]),
        period,
        clock,
    )
    return [PropagatedMotion(orbits, i) for i in range(len(starts))]


class ObjectField:
    """All space objects of a world, with vectorised access to their free motion.

    Attributes
    ----------
    objects : tuple of SpaceObject
        The objects, in scenario order (targets first).
    radii : ndarray (N,)
        Bounding-sphere radii, m.
    is_target : ndarray (N,) of bool
        Which objects are targets.
    is_sphere : ndarray (N,) of bool
        Which objects are spheres (their bounding sphere is their shape).
    status : ndarray (N,) of int
        :class:`ObjectStatus` of each object (read-only: change it with :meth:`set_status`).
    """

    def __init__(self, objects: Sequence[SpaceObject]) -> None:
        self.objects = tuple(objects)
        self.radii = np.array([o.radius for o in self.objects], dtype=float)
        self.is_target = np.array([o.kind is ObjectKind.TARGET for o in self.objects], dtype=bool)
        self.is_sphere = np.array(
            [o.shape.kind is ShapeKind.SPHERE for o in self.objects], dtype=bool
        )
        self._status = np.full(len(self.objects), ObjectStatus.FREE, dtype=int)
        self.status = _read_only(self._status.view())
        self._derived = _Derived()
        self.index = {o.id: i for i, o in enumerate(self.objects)}
        self._motions = MotionSet([o.motion for o in self.objects])
        self._cache: dict[float, tuple[np.ndarray, np.ndarray]] = {}

    def __len__(self) -> int:
        return len(self.objects)

    def free_states(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """Positions and velocities (N, 3) of every object as its motion model gives them
        (read-only arrays).

        Only the rows of free objects describe where the objects are; carried objects
        move with the collector. The two latest times are cached (the world asks for
        the start and the end of each control period).
        """
        if t not in self._cache:
            if len(self._cache) >= 2:
                self._cache.pop(min(self._cache))
            positions, velocities = self._motions.state_at(t)
            self._cache[t] = (_read_only(positions), _read_only(velocities))
        return self._cache[t]

    def set_status(self, index: int, status: ObjectStatus) -> None:
        """Make object ``index`` free, carried or delivered (a grab or a delivery)."""
        self._status[index] = status
        self._derived = _Derived()

    def free_mask(self) -> np.ndarray:
        """Boolean mask of the objects that are free (read-only)."""
        mask = self._derived.free
        if mask is None:
            mask = self._derived.free = _read_only(self.status == _FREE)
        return mask

    def free_indices(self) -> np.ndarray:
        """Indices of the objects that are free, ascending (read-only, kept until a status
        changes)."""
        indices = self._derived.indices
        if indices is None:
            indices = self._derived.indices = _read_only(np.flatnonzero(self.free_mask()))
        return indices

    def free_obstacles(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Indices of the free obstacles, their bounding radii (m) and whether each is a
        sphere (read-only arrays, kept until a status changes)."""
        found = self._derived.obstacles
        if found is None:
            indices = np.flatnonzero(self.free_mask() & ~self.is_target)
            found = self._derived.obstacles = (
                _read_only(indices),
                _read_only(self.radii[indices]),
                _read_only(self.is_sphere[indices]),
            )
        return found

    def count(self, status: ObjectStatus, targets_only: bool = True) -> int:
        """Number of objects (targets only, by default) with ``status``."""
        key = (int(status), targets_only)  # a plain int: numpy probes an enum at length
        found = self._derived.counts.get(key)
        if found is None:
            mask = self.status == key[0]
            found = self._derived.counts[key] = int(
                np.count_nonzero(mask & self.is_target if targets_only else mask)
            )
        return found


@dataclass
class _Derived:
    """What the objects' statuses determine, kept until a status changes.

    Attributes
    ----------
    free : ndarray of bool or None
        :meth:`ObjectField.free_mask`, once asked for.
    indices : ndarray of int or None
        :meth:`ObjectField.free_indices`, once asked for.
    obstacles : tuple of 3 ndarray or None
        :meth:`ObjectField.free_obstacles`, once asked for.
    counts : dict of (int, bool) to int
        :meth:`ObjectField.count` by status and whether only targets count.
    """

    free: np.ndarray | None = None
    indices: np.ndarray | None = None
    obstacles: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
    counts: dict[tuple[int, bool], int] = field(default_factory=dict)


def _read_only(array: np.ndarray) -> np.ndarray:
    array.setflags(write=False)
    return array
