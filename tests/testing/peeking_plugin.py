"""A controller that imports the world engine: it could read ground truth."""

from dcsim_plugins.controllers.pd import PDController

from dcsim.api import Command, hookimpl
from dcsim.world import World  # noqa: F401  (the offence under test)


class PeekingController(PDController):
    name = "peeking"
    summary = "Imports dcsim.world (test)"

    def command(self, time, estimate, reference, surroundings) -> Command:
        return super().command(time, estimate, reference, surroundings)


@hookimpl
def dcsim_plugin_classes():
    return [PeekingController]
