"""The capture mission (``mission.type: capture``): a space manipulator grasps a tumbling
body's grapple fixture and detumbles it.

The package holds the mission's scenario section (:mod:`.settings`) and its rules
(:mod:`.rules`), the mission (:mod:`.mission`) and its picture (:mod:`.plots`).
"""

from dcsim.missions.capture.mission import CaptureMission
from dcsim.missions.capture.settings import CaptureMissionSection

__all__ = ["CaptureMission", "CaptureMissionSection"]
