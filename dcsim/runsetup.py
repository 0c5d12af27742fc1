"""Assembling a run: a resolved scenario and one constructed plugin per role."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from dcsim.interfaces import Plugin
from dcsim.registry import PluginRegistry, RegisteredPlugin
from dcsim.scenario import Scenario, ScenarioSource, load_scenario
from dcsim.seeding import component_rng


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

    def plugin_versions(self) -> dict[str, dict[str, str]]:
        """Name, distribution and version of each role's plugin (for run summaries)."""
        return {
            role: {
                "name": entry.name,
                "distribution": entry.origin.distribution,
                "version": entry.origin.version,
            }
            for role, entry in self.sources.items()
        }


def prepare_run(
    path: ScenarioSource = None,
    overrides: Sequence[str] = (),
    seed: int | None = None,
    registry: PluginRegistry | None = None,
) -> RunSetup:
    """Load and resolve a scenario and construct its plugins.

    Parameters
    ----------
    path : str, Path or mapping, optional
        Scenario file, or the scenario's data as a mapping; the packaged default if None.
    overrides : sequence of str
        ``key.path=value`` overrides.
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
    if seed is not None:
        overrides = [*overrides, f"world.seed={seed}"]
    return build_run(load_scenario(path, overrides, registry), registry)


def build_run(scenario: Scenario, registry: PluginRegistry) -> RunSetup:
    """Construct the plugins of a validated scenario, each with its own generator.

    Raises
    ------
    PluginError
        If a plugin is unknown or its parameters are invalid.
    """
    from dcsim.missions import scenario_roles  # missions load the world engine

    sources = {
        role: registry.get(role, getattr(scenario, role).plugin)
        for role in scenario_roles(scenario)
    }
    plugins = {
        role: entry.cls(getattr(scenario, role).params, component_rng(scenario.world.seed, role))
        for role, entry in sources.items()
    }
    return RunSetup(scenario, plugins, sources, registry)
