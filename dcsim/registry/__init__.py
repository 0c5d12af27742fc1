"""The plugin system: kinds, hooks, discovery, checked calls and the scaffold.

``interfaces`` holds the four plugin kinds' base classes, ``hookspecs`` the pluggy hook
specifications, ``discovery`` the :class:`~dcsim.registry.discovery.PluginRegistry`
that finds plugins through entry points, ``calls`` and ``answers`` the checks around
every call of a plugin and what it returns, and ``scaffold`` the ``dcsim new-plugin``
templates' writer.
"""
