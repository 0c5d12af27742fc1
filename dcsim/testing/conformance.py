"""The test module collected by ``pytest --dcsim-plugin KIND:NAME``: one test per check."""

from __future__ import annotations

import pytest

from dcsim.testing import checks_for, resolve_plugin
from dcsim.testing.pytest_plugin import OPTION


def pytest_generate_tests(metafunc: pytest.Metafunc) -> None:
    """Parametrise over every requested plugin and every check of its kind."""
    if "dcsim_check" not in metafunc.fixturenames:
        return
    cases, ids = [], []
    for spec in metafunc.config.getoption(OPTION.lstrip("-").replace("-", "_")):
        plugin_class = resolve_plugin(spec)
        for check in checks_for(plugin_class.kind, plugin_class):
            cases.append((plugin_class, check))
            ids.append(f"{spec}::{check.name}")
    metafunc.parametrize(("dcsim_plugin_class", "dcsim_check"), cases, ids=ids)


def test_contract(dcsim_plugin_class, dcsim_check) -> None:
    """The plugin keeps the contract of this check."""
    dcsim_check.run(dcsim_plugin_class)
