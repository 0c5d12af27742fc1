"""dcsim's built-in plugins, registered through the ``dcsim`` entry-point group.

One subpackage per kind (``localisers``, ``task_planners``, ``path_planners``,
``controllers``). Each plugin module uses dcsim's public API (:mod:`dcsim.api`) only
and exposes its class through the ``dcsim_plugin_classes`` hook, exactly as a
third-party package would.
"""
