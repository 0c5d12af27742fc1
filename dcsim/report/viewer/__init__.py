"""The run viewer: a self-contained HTML page that replays a run in 3-D (``dcsim view``).

Reading a run directory (:mod:`~dcsim.report.viewer.records`), the robot's pose and arm
(:mod:`~dcsim.report.viewer.robot`), the objects' poses (:mod:`~dcsim.report.viewer.objects`), solid
meshes of their shapes (:mod:`~dcsim.report.viewer.meshes`), the scene the page plays
(:mod:`~dcsim.report.viewer.scene`) and the page itself (:mod:`~dcsim.report.viewer.page`, with
``dcsim/templates/viewer/``).
"""

from dcsim.report.viewer.page import PAGE_NAME, write_view
from dcsim.report.viewer.records import ViewError

__all__ = ["PAGE_NAME", "ViewError", "write_view"]
