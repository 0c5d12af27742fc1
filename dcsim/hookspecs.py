"""Hook specifications: the points where plugin packages plug into dcsim.

A plugin package exposes a module (or a plugin class) through the ``dcsim``
entry-point group. Modules implement the hooks below, marked with
:data:`hookimpl`::

    from dcsim.api import hookimpl

    @hookimpl
    def dcsim_plugin_classes():
        return [MyController]
"""

from __future__ import annotations

import pluggy

from dcsim.interfaces import Plugin

PROJECT_NAME = "dcsim"
"""The pluggy project name and the entry-point group plugins are found in."""

hookspec = pluggy.HookspecMarker(PROJECT_NAME)
hookimpl = pluggy.HookimplMarker(PROJECT_NAME)
"""Decorator marking a function as an implementation of a dcsim hook."""


@hookspec
def dcsim_plugin_classes() -> list[type[Plugin]]:
    """Return the plugin classes this package provides.

    Each class derives from one of the four plugin kinds
    (:class:`~dcsim.interfaces.Localiser`, :class:`~dcsim.interfaces.TaskPlanner`,
    :class:`~dcsim.interfaces.PathPlanner`, :class:`~dcsim.interfaces.Controller`) and
    declares ``name``, ``summary`` and ``Params``.

    Returns
    -------
    list of type
        The plugin classes; their order does not matter.
    """
