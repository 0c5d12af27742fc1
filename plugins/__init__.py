"""dcsim's built-in plugins, declared in the kinds' entry-point groups (``dcsim.controllers``, ...).

One subpackage per kind (``localisers``, ``task_planners``, ``path_planners``,
``controllers``), each module imported only when its plugin is used. Each plugin module
uses dcsim's public API (:mod:`dcsim.api`) only and exposes its class through the
``dcsim_plugin_classes`` hook, exactly as a third-party package would. A plugin's own
bench or environment lives beside it (``path_planners/ant_colony/bench.py``,
``q_learning/bench.py``, ``q_learning/gym.py``) and reaches the command line through the
``dcsim_register_commands`` hook.
"""
