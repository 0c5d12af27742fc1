"""Assembling a run: a resolved scenario and one constructed plugin per role."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import yaml

from dcsim.errors import Problem, ScenarioError
from dcsim.registry.discovery import PluginRegistry, RegisteredPlugin
from dcsim.registry.interfaces import Plugin
from dcsim.run.seeding import component_rng
from dcsim.scenario import Scenario, ScenarioSource, read_scenario

Overrides = Sequence[str] | Mapping[str, Any]
"""``key.path=value`` texts as for ``dcsim run --set``, or a mapping of key paths to values."""

ScenarioInput = ScenarioSource | Scenario
"""A scenario file's path, its data as a mapping, a parsed document, a loaded
:class:`Scenario`, or None for the packaged default scenario."""


@dataclass(frozen=True)
class RunSetup:
    """Everything a run needs before the first step.

    Attributes
    ----------
    scenario : Scenario
        The resolved scenario (plugin parameters with defaults filled in).
    plugins : dict of str to Plugin
        The constructed plugin of each role the scenario's mission uses (``localiser``,
        ``task_planner``, ``path_planner``, ``controller``), each with its own random
        generator.
    sources : dict of str to RegisteredPlugin
        Where each role's plugin came from.
    registry : PluginRegistry
        The registry the plugins came from (its hooks observe the run).
    """

    scenario: Scenario
    plugins: dict[str, Plugin]
    sources: dict[str, RegisteredPlugin]
    registry: PluginRegistry

    @classmethod
    def from_scenario(cls, scenario: Scenario, registry: PluginRegistry) -> RunSetup:
        """Construct the plugins of a resolved scenario, each with its own generator.

        Raises
        ------
        PluginError
            If a plugin is unknown or its parameters are invalid.
        """
        from dcsim.missions import scenario_roles  # missions load the world engine

        sources = {
            role: registry.get(kind, getattr(scenario, role).plugin)
            for role, (kind, _) in scenario_roles(scenario).items()
        }
        plugins = {
            role: entry.cls(
                getattr(scenario, role).params, component_rng(scenario.world.seed, role)
            )
            for role, entry in sources.items()
        }
        return cls(scenario, plugins, sources, registry)

    def plugin_versions(self) -> dict[str, dict[str, str]]:
        """Name, distribution and version of each sensor's model (as
        ``sensors.<sensor>``), then of each role's plugin, for run summaries."""
        from dcsim.scenario.sensors import sensor_choices

        sources = {
            f"sensors.{slot}": self.registry.get("sensor", choice.model)
            for slot, choice in sensor_choices(self.scenario.sensors).items()
            if choice is not None
        }
        sources.update(self.sources)
        return {
            role: {
                "name": entry.name,
                "distribution": entry.origin.distribution,
                "version": entry.origin.version,
            }
            for role, entry in sources.items()
        }


def setup_run(
    scenario: ScenarioInput = None,
    overrides: Overrides = (),
    seed: int | None = None,
    registry: PluginRegistry | None = None,
) -> RunSetup:
    """Load and resolve a scenario and construct its plugins: what a run flies.

    Parameters
    ----------
    scenario : str, Path, mapping, ScenarioDocument or Scenario, optional
        Scenario file, the scenario's data as a mapping, a parsed document or a loaded
        scenario; the packaged default if None.
    overrides : sequence of str or mapping
        ``key.path=value`` overrides (:func:`override_texts`).
    seed : int, optional
        Replaces ``world.seed`` (same as the override ``world.seed=N``).
    registry : PluginRegistry, optional
        Registry to use; discovered from installed packages if None.

    Returns
    -------
    RunSetup
        The resolved scenario and its plugins.

    Raises
    ------
    ScenarioError
        If the scenario, an override or a plugin choice is invalid.
    """
    registry = registry if registry is not None else PluginRegistry.discover()
    source = scenario.model_dump(mode="json") if isinstance(scenario, Scenario) else scenario
    texts = override_texts(overrides)
    if seed is not None:
        texts = [*texts, f"world.seed={seed}"]
    return RunSetup.from_scenario(read_scenario(source, texts, registry), registry)


def override_texts(overrides: Overrides) -> list[str]:
    """Overrides as ``key.path=value`` texts (the form of ``dcsim run --set``).

    Parameters
    ----------
    overrides : sequence of str or mapping
        Texts, kept as they are (one text alone counts as one override), or a mapping
        of key paths to plain values (``{"world.duration": 30}``; numpy numbers and
        arrays count as plain), each value written as YAML.

    Raises
    ------
    ScenarioError
        If a mapped value is not plain data (numbers, text, booleans, None, lists,
        mappings).
    """
    if isinstance(overrides, str):
        return [overrides]
    if not isinstance(overrides, Mapping):
        return list(overrides)
    texts = []
    for key, value in overrides.items():
        try:
            text = yaml.safe_dump(_plain(value), default_flow_style=True, width=1 << 30)
        except yaml.YAMLError:
            message = f"{value!r} is not plain data (numbers, text, lists, mappings)"
            raise ScenarioError("overrides", [Problem(str(key), message)]) from None
        texts.append(f"{key}={text.strip().removesuffix('...').strip()}")
    return texts


def _plain(value: Any) -> Any:
    """``value`` with numpy scalars and arrays (a notebook's ``np.linspace`` values)
    turned into Python numbers and lists, at any depth."""
    if isinstance(value, np.generic | np.ndarray):
        return value.tolist()
    if isinstance(value, Mapping):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    return value
