"""The transfer mission (``mission.type: transfer``): a free flyer to a goal region.

From its initial state the robot flies a path planner's trajectory into the goal region
among obstacles of any shape, with a controller tracking it. The package holds the
mission's scenario section (:mod:`.settings`), the mission (:mod:`.mission`) and its
pictures (:mod:`.plots`).
"""

from dcsim.missions.transfer.mission import TransferMission
from dcsim.missions.transfer.settings import TransferMissionSection

__all__ = ["TransferMission", "TransferMissionSection"]
