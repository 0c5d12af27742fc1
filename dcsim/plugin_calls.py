"""Calling plugins during a run: every exception a plugin raises becomes a recorded failure."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from dcsim.interfaces import Plugin


class PluginFailure(Exception):
    """A plugin raised during a run.

    Attributes
    ----------
    role : str
        The role of the plugin (``localiser``, ``controller``...).
    plugin : str
        The plugin's name.
    method : str
        The method that raised.
    error : BaseException
        What it raised.
    """

    def __init__(self, role: str, plugin: str, method: str, error: BaseException) -> None:
        self.role, self.plugin, self.method, self.error = role, plugin, method, error
        super().__init__(
            f"{role} plugin '{plugin}' raised in {method}(): {type(error).__name__}: {error}"
        )


def call_plugin(plugins: Mapping[str, Plugin], role: str, method: str, *args: Any) -> Any:
    """Call ``plugins[role].method(*args)``, wrapping any exception in :class:`PluginFailure`."""
    plugin = plugins[role]
    try:
        return getattr(plugin, method)(*args)
    except Exception as error:  # a plugin's own bug ends the run, recorded
        raise PluginFailure(role, plugin.name, method, error) from error
