"""The mission conformance suite: does a mission keep the seam's contract?

A mission is checked on a scenario that flies it (its package ships one): the checks
fly it through dcsim's runner, as ``dcsim run`` does, and look at what it declares and
what it records. From a mission package's own tests::

    from dcsim.testing.missions import MissionContract
    from my_package import PatrolMission

    class TestPatrol(MissionContract):
        mission = PatrolMission
        scenario = "tests/scenario.yaml"   # or the scenario's data as a mapping

From Python: :func:`check_mission`. The checks are listed in docs/plugins.md.
"""

from __future__ import annotations

import copy
import tempfile
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

from dcsim.errors import ScenarioError
from dcsim.missions import Mission, RoleKind, mission_types, register_mission
from dcsim.registry.discovery import PluginRegistry
from dcsim.registry.interfaces import PLUGIN_KINDS
from dcsim.run.loop import Runner
from dcsim.run.recording import read_telemetry
from dcsim.run.setup import RunSetup, setup_run
from dcsim.scenario.loader import ROBOT_TYPES, scenario_document
from dcsim.scenario.model import MissionSettings
from dcsim.testing.contracts import ContractViolation, fail

ScenarioSource = str | Path | Mapping[str, Any]
"""A scenario file, or a scenario's data as a mapping."""


@dataclass(frozen=True)
class MissionCheck:
    """One named check of the mission contract.

    Attributes
    ----------
    name : str
        Its name (the test method is ``test_<name>``).
    contract : str
        The contract in words.
    function : callable
        ``function(mission_class, scenario)``; raises :class:`ContractViolation`.
    """

    name: str
    contract: str
    function: Callable[[type[Mission], ScenarioSource], None]

    def run(self, mission: type[Mission], scenario: ScenarioSource) -> None:
        """Run the check, prefixing a violation with the mission and the contract."""
        _selectable(mission)
        try:
            self.function(mission, scenario)
        except ContractViolation as violation:
            raise ContractViolation(
                f"mission '{getattr(mission, 'type', mission.__name__)}' breaks "
                f"'{self.name}': {violation}\n  contract: {self.contract}"
            ) from None


MISSION_CHECKS: list[MissionCheck] = []
"""Every check of the mission contract, in the order they run."""


def mission_check(name: str, contract: str) -> Callable:
    """Register a mission check under ``name`` with its ``contract`` in words."""

    def register(function: Callable) -> Callable:
        MISSION_CHECKS.append(MissionCheck(name, contract, function))
        return function

    return register


def _selectable(mission: type[Mission]) -> None:
    """Make ``mission`` the scenario's ``mission.type`` in this process, as installing
    its distribution would (a class not yet installed, under test)."""
    name = getattr(mission, "type", None)  # a class under test may lack it
    if name is None or mission_types().get(name) is not mission:
        try:
            register_mission(mission)
        except (ValueError, AttributeError) as error:
            fail(f"cannot be selected by its type: {error}")


def _document(scenario: ScenarioSource) -> dict[str, Any]:
    """The scenario's data, a copy the checks may change."""
    return copy.deepcopy(scenario_document(scenario).data)


@cache
def _registry() -> PluginRegistry:
    """The installed plugins, discovered once for every check."""
    return PluginRegistry.discover()


def _setup(scenario: ScenarioSource) -> RunSetup:
    """The scenario's run set-up: validated, its plugins made (afresh for each flight)."""
    try:
        return setup_run(_document(scenario), registry=_registry())
    except ScenarioError as error:
        fail(f"its scenario does not validate: {error}")


def _fly(setup: RunSetup, out: Path) -> dict[str, Any]:
    """Fly a run set-up into run directory ``out``; return its summary."""
    try:
        return Runner(setup, out).run()
    except Exception as error:  # the mission's own bug: name it
        fail(f"raised {type(error).__name__}: {error} while flying its scenario")


@mission_check(
    "declares_its_seam",
    "`type` is a lower-case name its settings' `type` defaults to, `summary` one line, "
    "`Settings` a MissionSettings subclass, `roles` plugin kinds or roles its `role_kinds` "
    "give a plugin kind, a known robot type and a scenario key (in its Settings' "
    "`role_defaults`, whose every key is a role), `modes` at least one name, `units` only "
    "for its `columns`, `robots` known robot types",
)
def check_declarations(mission: type[Mission], scenario: ScenarioSource) -> None:
    settings = getattr(mission, "Settings", None)
    if not (isinstance(settings, type) and issubclass(settings, MissionSettings)):
        fail(f"Settings is {settings!r}, not a subclass of dcsim.api.MissionSettings")
    default = settings.model_fields["type"].default
    if default != mission.type:
        fail(f"its Settings' type defaults to {default!r}, not to its type {mission.type!r}")
    summary = getattr(mission, "summary", "")
    if not isinstance(summary, str) or not summary.strip() or "\n" in summary:
        fail(f"summary must be one line of text, got {summary!r}")
    role_kinds = mission.role_kinds
    unknown_roles = set(mission.roles) - set(PLUGIN_KINDS) - set(role_kinds)
    if unknown_roles:
        fail(
            f"roles {sorted(unknown_roles)} are neither plugin kinds ({', '.join(PLUGIN_KINDS)}) "
            "nor named in its role_kinds"
        )
    _check_role_kinds(mission, role_kinds)
    if not mission.modes or not all(isinstance(m, str) for m in mission.modes):
        fail(f"modes must be a non-empty tuple of names, got {mission.modes!r}")
    unknown_robots = set(mission.robots) - set(ROBOT_TYPES)
    if unknown_robots:
        fail(f"robots {sorted(unknown_robots)} are not robot types ({', '.join(ROBOT_TYPES)})")
    validated = _setup(scenario).scenario
    columns = mission.telemetry_columns(validated)
    stray = set(mission.telemetry_units(validated)) - set(columns)
    if stray:
        fail(f"units are given for {sorted(stray)}, which are not among its columns {columns}")


def _check_role_kinds(mission: type[Mission], role_kinds: Mapping[str, RoleKind]) -> None:
    """Each role of ``role_kinds`` names a plugin kind and a robot type and has a
    scenario key (a ``role_defaults`` entry); every ``role_defaults`` key is a role."""
    unknown_kinds = {
        role: kind for role, (kind, _) in role_kinds.items() if kind not in PLUGIN_KINDS
    }
    if unknown_kinds:
        fail(f"role_kinds {unknown_kinds} name no plugin kind ({', '.join(PLUGIN_KINDS)})")
    unknown_robots = {
        role: robot
        for role, (_, robot) in role_kinds.items()
        if robot is not None and robot not in ROBOT_TYPES
    }
    if unknown_robots:
        fail(f"role_kinds {unknown_robots} name no robot type ({', '.join(ROBOT_TYPES)})")
    keyless = sorted(set(role_kinds) - set(mission.Settings.role_defaults))
    if keyless:
        fail(
            f"roles {keyless} of its role_kinds have no scenario key: give each a default "
            "plugin (or None) in its Settings' role_defaults"
        )
    strays = sorted(set(mission.Settings.role_defaults) - set(PLUGIN_KINDS) - set(role_kinds))
    if strays:
        fail(f"role_defaults {strays} are neither plugin kinds nor named in its role_kinds")


@mission_check(
    "validates_its_section",
    "a key its settings do not have, given in the scenario's `mission` section, is refused "
    "with a scenario error naming `mission.<key>`",
)
def check_section_validation(mission: type[Mission], scenario: ScenarioSource) -> None:
    data = _document(scenario)
    data.setdefault("mission", {})["no_such_key_xyz"] = 1
    try:
        setup_run(data, registry=_registry())
    except ScenarioError as error:
        if "mission.no_such_key_xyz" not in str(error):
            fail(f"an unknown mission key was refused without being named: {error}")
        return
    fail("an unknown key in the mission section was accepted")


@mission_check(
    "flies_its_scenario",
    "its scenario flies through the runner without failing; every telemetry row holds "
    "its columns and one of its modes; the summary holds its `summary_names` and a "
    "`goal_met` of true, false or null; the run's pictures are drawn",
)
def check_flight(mission: type[Mission], scenario: ScenarioSource) -> None:
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / "run"
        setup = _setup(scenario)
        summary = _fly(setup, out)
        if summary["status"] == "failed":
            fail(f"the run failed: {summary['reason']}")
        telemetry = read_telemetry(out / "telemetry.csv")
        validated = setup.scenario
        missing = [c for c in mission.telemetry_columns(validated) if c not in telemetry]
        if missing:
            fail(f"its columns {missing} are not in the telemetry")
        strange = sorted({str(m) for m in telemetry["mode"]} - set(mission.modes))
        if strange:
            fail(f"the telemetry records modes {strange} that are not among {mission.modes}")
        absent = [name for name in mission.summary_names if name not in summary]
        if absent:
            fail(f"the summary lacks its declared fields {absent}")
        if summary["goal_met"] not in (True, False, None):
            fail(f"goal_met is {summary['goal_met']!r}, not true, false or null")
        if not any((out / "plots").glob("*.png")):
            fail("no picture was drawn into plots/")


@mission_check(
    "deterministic",
    "the same scenario and seed flown twice give byte-identical telemetry and events",
)
def check_determinism(mission: type[Mission], scenario: ScenarioSource) -> None:
    with tempfile.TemporaryDirectory() as folder:
        runs = [Path(folder) / name for name in ("first", "second")]
        for out in runs:
            _fly(_setup(scenario), out)
        for name in ("telemetry.csv", "events.jsonl"):
            if (runs[0] / name).read_bytes() != (runs[1] / name).read_bytes():
                fail(f"{name} differs between two flights of the same scenario and seed")


def check_mission(mission: type[Mission], scenario: ScenarioSource) -> list[Any]:
    """Run every mission check; return one :class:`~dcsim.testing.CheckResult` each.

    Parameters
    ----------
    mission : type of Mission
        The mission class.
    scenario : str, Path or mapping
        A scenario that flies it (a file, or its data).
    """
    from dcsim.testing import CheckResult

    results = []
    for check in MISSION_CHECKS:
        try:
            check.run(mission, scenario)
        except ContractViolation as violation:
            results.append(CheckResult(check.name, False, str(violation)))
        else:
            results.append(CheckResult(check.name, True))
    return results


class MissionContract:
    """Subclass as ``Test...`` with ``mission = YourMission`` and ``scenario = ...`` (a
    scenario file or its data) to run the mission contract, one test per check."""

    mission: type[Mission]
    scenario: ScenarioSource

    def __init_subclass__(cls, **kwargs: object) -> None:
        super().__init_subclass__(**kwargs)
        for check in MISSION_CHECKS:
            setattr(cls, f"test_{check.name}", _test_method(check))


def _test_method(check: MissionCheck) -> Callable[[MissionContract], None]:
    def test(self: MissionContract) -> None:
        check.run(self.mission, self.scenario)

    test.__name__ = f"test_{check.name}"
    test.__doc__ = check.contract
    return test
