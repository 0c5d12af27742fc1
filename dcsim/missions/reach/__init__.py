"""The reach mission (``mission.type: reach``): a space manipulator's end effector to a target.

The space manipulator thesis's experiment: a path planner gives the end effector's
path, the mission turns it into joint references, and a controller tracks them with the
base under full or partial control. The package holds the mission's scenario section
(:mod:`.settings`), the mission (:mod:`.mission`) and its pictures (:mod:`.plots`).
"""

from dcsim.missions.reach.mission import ReachMission
from dcsim.missions.reach.settings import ReachMissionSection

__all__ = ["ReachMission", "ReachMissionSection"]
