"""The ``dcsim`` command, one module per command group: ``main`` holds the top group and
registers the others (``run``, ``plugins``, ``bench``, ``campaign``, ``fmu``, ``robot``);
``options`` the options several commands share, ``common`` the helpers they share, and
``plugin_commands`` the commands plugin packages add."""
