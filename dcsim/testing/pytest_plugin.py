"""The pytest plugin of the conformance suite (entry point ``pytest11: dcsim``).

``pytest --dcsim-plugin KIND:NAME`` (repeatable) runs every check of the kind against
the installed plugin, one test per check, named ``KIND:NAME::check``.
"""

from __future__ import annotations

from pathlib import Path

import pytest

OPTION = "--dcsim-plugin"
_SUITE = Path(__file__).with_name("conformance.py")


def pytest_addoption(parser: pytest.Parser) -> None:
    """Add ``--dcsim-plugin KIND:NAME``."""
    parser.getgroup("dcsim").addoption(
        OPTION,
        action="append",
        default=[],
        metavar="KIND:NAME",
        help="run the dcsim conformance suite against an installed plugin (repeatable), "
        "e.g. --dcsim-plugin controller:pd",
    )


def pytest_load_initial_conftests(
    early_config: pytest.Config, parser: pytest.Parser, args: list[str]
) -> None:
    """Collect the conformance suite whenever ``--dcsim-plugin`` is given."""
    if any(arg == OPTION or arg.startswith(OPTION + "=") for arg in args):
        args.append(str(_SUITE))
