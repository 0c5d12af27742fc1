"""The world engine: a PyBullet world of a collector, space objects, beacons and a drop point.

:class:`World` is a steppable system with named inputs, outputs and parameters; the
runner, the tests and (later) the FMU all drive the same class.
"""

from dcsim.world.engine import GrabResult, ReleaseResult, World, WorldInputs
from dcsim.world.objects import ObjectStatus, SpaceObject

__all__ = ["GrabResult", "ObjectStatus", "ReleaseResult", "SpaceObject", "World", "WorldInputs"]
