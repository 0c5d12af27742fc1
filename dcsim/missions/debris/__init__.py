"""The debris mission (``mission.type: debris``): the debris collector thesis's collection.

The collector localises, plans the pickup of every target with its task planner, flies
to each with its path planner and controller, grabs it and delivers its cargo to the
drop point. The package holds the mission's scenario section (:mod:`.settings`), its
rules across keys (:mod:`.rules`), the executer (:mod:`.mission`) and its pictures
(:mod:`.plots`).
"""

from dcsim.missions.debris.mission import DebrisMission
from dcsim.missions.debris.settings import DebrisMissionSection

__all__ = ["DebrisMission", "DebrisMissionSection"]
