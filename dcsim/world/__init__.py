"""The world engine: a PyBullet world of a robot, space objects and beacons.

:class:`World` is a steppable system with named inputs, outputs and parameters; the
runner, the tests and the FMU all drive the same class. Its pieces live in one module
each: ``engine`` (the :class:`World`: stepping, collisions, state and outputs),
``robot_body`` (the interface every robot body type has), ``free_flyer`` and
``manipulator`` (the two body types), ``bodies`` (the objects' PyBullet bodies),
``environment`` (Clohessy–Wiltshire forces, propellant), ``sensors`` (ranges, tracks,
attitude), ``payload`` (objects held by the robot) and ``objects`` (the targets and
obstacles).
"""

from dcsim.world.engine import World, WorldInputs
from dcsim.world.objects import ObjectStatus, SpaceObject

__all__ = ["ObjectStatus", "SpaceObject", "World", "WorldInputs"]
