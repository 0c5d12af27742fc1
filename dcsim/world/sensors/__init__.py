"""The robot's sensors: the world's sensing (:class:`Sensing`) and the built-in sensor
models, one module each (``beacon_ranges``, ``star_tracker``, ``gyros``,
``object_sensor``), registered in the ``dcsim.sensors`` entry-point group as a third
party's are."""

from dcsim.world.sensors.sensing import Sensing, build_sensor_models

__all__ = ["Sensing", "build_sensor_models"]
