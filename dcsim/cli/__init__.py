"""The ``dcsim`` command: ``main`` holds the command group and its commands,
``campaign`` the campaign commands, ``plugin_commands`` the commands plugins add."""
