"""The plugin conformance suite: is a sensor model, tracker, localiser, planner or
controller a good citizen?

Three ways to use it:

- From the command line, against any installed plugin::

      pytest --dcsim-plugin controller:pd

- In a plugin package's own tests, by subclassing the kind's contract class::

      from dcsim.testing import ControllerContract
      from my_package import MyController

      class TestMyController(ControllerContract):
          plugin = MyController

- From Python, for a report::

      from dcsim.testing import check_plugin
      for result in check_plugin("controller:pd"):
          print(result)

Every check is separately named and reported; a failure says what the plugin did and
what the contract expects. The checks and their contracts are listed in
docs/plugins.md.
"""

from __future__ import annotations

from dataclasses import dataclass

from dcsim.registry.discovery import PluginRegistry
from dcsim.registry.interfaces import PLUGIN_KINDS, Plugin
from dcsim.testing import kind_checks  # noqa: F401  (registers the kind-specific checks)
from dcsim.testing.contracts import METADATA_CHECK, Check, ContractViolation, checks_for


@dataclass(frozen=True)
class CheckResult:
    """Outcome of one check on one plugin.

    Attributes
    ----------
    check : str
        The check's name.
    passed : bool
        Whether the plugin kept the contract.
    message : str
        Why not (empty when passed).
    """

    check: str
    passed: bool
    message: str = ""

    def __str__(self) -> str:
        return f"{'PASS' if self.passed else 'FAIL'} {self.check}" + (
            f": {self.message}" if self.message else ""
        )


def resolve_plugin(
    plugin: type[Plugin] | str, registry: PluginRegistry | None = None
) -> type[Plugin]:
    """A plugin class from a class or from ``"KIND:NAME"`` (looked up among installed plugins)."""
    if isinstance(plugin, str):
        kind, _, name = plugin.partition(":")
        if not name:
            raise ValueError(
                f"expected KIND:NAME (kinds: {', '.join(PLUGIN_KINDS)}), got {plugin!r}"
            )
        return (registry or PluginRegistry.discover()).get(kind, name).cls
    return plugin


def check_plugin(
    plugin: type[Plugin] | str, registry: PluginRegistry | None = None
) -> list[CheckResult]:
    """Run every check of the plugin's kind; return one result per check.

    Parameters
    ----------
    plugin : type or str
        The plugin class, or ``"KIND:NAME"`` of an installed plugin.
    registry : PluginRegistry, optional
        Where to look names up; installed plugins if None.
    """
    plugin_class = resolve_plugin(plugin, registry)
    metadata = _run_check(METADATA_CHECK, plugin_class)
    if not metadata.passed:  # without a kind, name and parameters nothing else can run
        return [metadata]
    rest = [c for c in checks_for(plugin_class.kind, plugin_class) if c is not METADATA_CHECK]
    return [metadata] + [_run_check(check, plugin_class) for check in rest]


def _run_check(check: Check, plugin_class: type[Plugin]) -> CheckResult:
    try:
        check.run(plugin_class)
    except ContractViolation as violation:
        return CheckResult(check.name, False, str(violation))
    return CheckResult(check.name, True)


class _Contract:
    """Base of the contract test classes: one ``test_<check>`` method per check of the kind."""

    plugin: type[Plugin]
    kind: str

    def __init_subclass__(cls, **kwargs: object) -> None:
        super().__init_subclass__(**kwargs)
        if "kind" in cls.__dict__:
            for check in checks_for(cls.kind):
                setattr(cls, f"test_{check.name}", _test_method(check))


def _test_method(check: Check):
    def test(self: _Contract) -> None:
        if not check.applies(self.plugin):
            import pytest  # only where a contract class runs, under pytest

            pytest.skip(f"poses a problem for {', '.join(check.robots)} robots only")
        check.run(self.plugin)

    test.__name__ = f"test_{check.name}"
    test.__doc__ = check.contract
    return test


class SensorModelContract(_Contract):
    """Subclass as ``Test...`` with ``plugin = YourSensorModel`` to run the sensor contract."""

    kind = "sensor"


class TrackerContract(_Contract):
    """Subclass as ``Test...`` with ``plugin = YourTracker`` to run the tracker contract."""

    kind = "tracker"


class LocaliserContract(_Contract):
    """Subclass as ``Test...`` with ``plugin = YourLocaliser`` to run the localiser contract."""

    kind = "localiser"


class TaskPlannerContract(_Contract):
    """Subclass as ``Test...`` with ``plugin = YourPlanner`` to run the task-planner contract."""

    kind = "task_planner"


class PathPlannerContract(_Contract):
    """Subclass as ``Test...`` with ``plugin = YourPlanner`` to run the path-planner contract."""

    kind = "path_planner"


class ControllerContract(_Contract):
    """Subclass as ``Test...`` with ``plugin = YourController`` to run the controller contract."""

    kind = "controller"


__all__ = [
    "Check",
    "CheckResult",
    "ContractViolation",
    "ControllerContract",
    "LocaliserContract",
    "PathPlannerContract",
    "SensorModelContract",
    "TaskPlannerContract",
    "TrackerContract",
    "check_plugin",
    "checks_for",
    "resolve_plugin",
]
