"""``python -m dcsim``: the same as the ``dcsim`` command."""

from dcsim.cli import main

main()
