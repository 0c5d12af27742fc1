"""``python -m dcsim``: the same as the ``dcsim`` command."""

from dcsim.cli.main import main

main()
