"""The run viewer: a self-contained HTML page that replays a run in 3-D (``dcsim view``).

Reading a run directory (:mod:`~dcsim.viewer.records`), the robot's pose and arm
(:mod:`~dcsim.viewer.robot`), the objects' poses (:mod:`~dcsim.viewer.objects`), solid
meshes of their shapes (:mod:`~dcsim.viewer.meshes`), the scene the page plays
(:mod:`~dcsim.viewer.scene`) and the page itself (:mod:`~dcsim.viewer.page`, with
``dcsim/templates/viewer/``).
"""

from dcsim.viewer.page import PAGE_NAME, write_view
from dcsim.viewer.records import ViewError

__all__ = ["PAGE_NAME", "ViewError", "write_view"]
