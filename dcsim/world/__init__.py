"""The world engine: a PyBullet world of a collector, space objects, beacons and a drop point.

:class:`World` is a steppable system with named inputs, outputs and parameters; the
runner, the tests and the FMU all drive the same class. Its pieces live in one module
each: ``engine`` (the :class:`World`: stepping, collisions, state and outputs),
``bodies`` (PyBullet bodies), ``environment`` (Clohessy–Wiltshire forces, propellant),
``sensors`` (ranges, tracks, attitude), ``services`` (grab and release) and ``objects``
(the targets and obstacles).
"""

from dcsim.world.engine import World, WorldInputs
from dcsim.world.objects import ObjectStatus, SpaceObject
from dcsim.world.services import GrabResult, ReleaseResult

__all__ = ["GrabResult", "ObjectStatus", "ReleaseResult", "SpaceObject", "World", "WorldInputs"]
