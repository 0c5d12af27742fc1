"""The hold mission (``mission.type: hold``): keep a position and an attitude (station keeping).

The package holds the mission's scenario section (:mod:`.settings`) and the mission
(:mod:`.mission`).
"""

from dcsim.missions.hold.mission import HoldMission
from dcsim.missions.hold.settings import HoldMissionSection

__all__ = ["HoldMission", "HoldMissionSection"]
