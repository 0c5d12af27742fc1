"""Scenario files: schema, loading with precise errors, overrides, and resolution."""

from dcsim.scenario.document import ScenarioDocument, format_key_path, parse_key_path
from dcsim.scenario.loader import (
    ScenarioSource,
    default_scenario_path,
    dump_scenario,
    packaged_scenario_path,
    read_scenario,
    resolve_plugins,
    scenario_document,
    validate,
)
from dcsim.scenario.model import Scenario

__all__ = [
    "Scenario",
    "ScenarioDocument",
    "ScenarioSource",
    "default_scenario_path",
    "packaged_scenario_path",
    "dump_scenario",
    "format_key_path",
    "read_scenario",
    "parse_key_path",
    "resolve_plugins",
    "scenario_document",
    "validate",
]
