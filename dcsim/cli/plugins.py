"""``dcsim plugins`` and ``dcsim new-plugin``: the installed plugins, and a package of your own."""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import asdict
from pathlib import Path

import click

from dcsim.cli.common import plugin_registry
from dcsim.errors import PluginNotFoundError, did_you_mean
from dcsim.params import ParameterInfo, parameter_infos
from dcsim.registry.discovery import PluginRegistry, RegisteredPlugin
from dcsim.registry.interfaces import PLUGIN_KINDS


@click.command("plugins", short_help="List the registered plugins, or one's parameters.")
@click.argument("name", required=False)
@click.option(
    "--kind",
    type=click.Choice(list(PLUGIN_KINDS)),
    help="Only list plugins of this kind.",
)
@click.option("--json", "as_json", is_flag=True, help="Print a JSON list instead of a table.")
def plugins_command(name: str | None, kind: str | None, as_json: bool) -> None:
    """List installed plugins: kind, name and origin; or NAME's summary and parameters.

    The origin is the installed distribution (and version) that provides the plugin; the
    listing is read from the packages' metadata, without importing any plugin. With NAME,
    imports that plugin and prints its summary, robots and parameters (name, default,
    unit, bounds or allowed values, description), the keys of its scenario section's
    params; --kind picks one of two plugins of that name. Set DCSIM_LOAD_PLUGINS to a
    comma-separated list of distributions to restrict which external plugins load.
    """
    registry = plugin_registry()
    if name is not None:
        _print_parameters(_plugins_named(registry, name, kind), as_json)
        return
    entries = [e.as_dict() for e in registry.entries(kind)]
    if as_json:
        click.echo(json.dumps(entries, indent=2))
        return
    rows = [(e["kind"], e["name"], f"{e['distribution']} {e['version']}") for e in entries]
    _print_table(("KIND", "NAME", "ORIGIN"), rows)


def _plugins_named(registry: PluginRegistry, name: str, kind: str | None) -> list[RegisteredPlugin]:
    """The plugins called ``name`` (of ``kind``, if given), imported.

    Raises
    ------
    PluginNotFoundError
        Naming the closest names when there is none.
    PluginLoadError
        If one of them fails to import.
    """
    found = registry.find(name, kind)
    if found:
        return found
    if kind is not None:
        registry.get(kind, name)  # raises, with the names of that kind
    names = sorted({e.name for e in registry.entries()})
    raise PluginNotFoundError(
        f"no plugin named '{name}' (see dcsim plugins)" + did_you_mean(name, names)
    )


def _print_parameters(plugins: list[RegisteredPlugin], as_json: bool) -> None:
    """Each plugin's origin, robots and parameter table (or all of it as JSON)."""
    if as_json:
        entries = [
            {
                **plugin.as_dict(),
                "robots": list(plugin.cls.robots),
                "parameters": [asdict(info) for info in parameter_infos(plugin.cls.Params)],
            }
            for plugin in plugins
        ]
        click.echo(json.dumps(entries, indent=2, ensure_ascii=False))
        return
    for index, plugin in enumerate(plugins):
        click.echo(("\n" if index else "") + f"{plugin.kind} {plugin.name}: {plugin.cls.summary}")
        click.echo(f"origin: {plugin.origin}")
        click.echo(f"robots: {', '.join(plugin.cls.robots)}")
        rows = [
            (i.name, _default_text(i), i.unit, i.bounds, i.description)
            for i in parameter_infos(plugin.cls.Params)
        ]
        if not rows:
            click.echo("parameters: none")
            continue
        click.echo("")
        _print_table(("PARAMETER", "DEFAULT", "UNIT", "BOUNDS", "DESCRIPTION"), rows)


def _default_text(info: ParameterInfo) -> str:
    """A parameter's default as a scenario file would write it."""
    if info.required:
        return "required"
    if isinstance(info.default, str):
        return info.default
    return json.dumps(info.default, ensure_ascii=False)


def _print_table(header: tuple[str, ...], rows: Sequence[tuple[str, ...]]) -> None:
    """The header and rows as columns padded to their widest cell."""
    widths = [max(len(str(r[i])) for r in [header, *rows]) for i in range(len(header))]
    for row in [header, *rows]:
        click.echo(
            "  ".join(str(cell).ljust(w) for cell, w in zip(row, widths, strict=True)).rstrip()
        )


@click.command("new-plugin", short_help="Write a plugin or mission package of your own.")
@click.argument("kind", type=click.Choice([*PLUGIN_KINDS, "mission"]))
@click.argument("name")
@click.option(
    "--dir",
    "directory",
    type=click.Path(file_okay=False, path_type=Path),
    default=Path("."),
    show_default=True,
    help="Folder to create the package in.",
)
def new_plugin_command(kind: str, name: str, directory: Path) -> None:
    """Write an out-of-tree package: a plugin of KIND called NAME, or a mission.

    The package (DIR/dcsim-NAME) has a pyproject.toml with its entry point in KIND's
    group (dcsim.controllers, ...), the plugin class with its parameter model and a
    simple working algorithm, a test file
    that runs the conformance suite, and a README. KIND `mission` writes a mission
    instead (mission.type NAME, found through the dcsim.missions entry point: its
    settings and a mission that flies to a point and holds it), with an example
    scenario its tests fly through the mission conformance suite. Install it with
    `pip install -e DIR/dcsim-NAME` and run `pytest` inside it. A NAME an installed
    plugin of KIND (or an installed mission) already has is refused.
    """
    from dcsim.registry.scaffold import new_plugin

    root = new_plugin(kind, name, directory, plugin_registry())
    click.echo(f"wrote {root}")
    click.echo(f"next: pip install -e '{root}[test]' && (cd {root} && pytest)")
