"""dcsim's built-in plugins, registered through the ``dcsim`` entry-point group.

Each module implements one plugin with dcsim's public API (:mod:`dcsim.api`) only, and
exposes it through the ``dcsim_plugin_classes`` hook, exactly as a third-party
package would.
"""
