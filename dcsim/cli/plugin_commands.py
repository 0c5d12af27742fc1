"""Commands that plugin packages add to the ``dcsim`` command line.

A package implements :func:`~dcsim.registry.hookspecs.dcsim_register_commands` and adds click
commands to the groups it is given; dcsim's built-in plugins add their own benches
(``dcsim bench ant-colony``, ``dcsim bench q-learning``) the same way. Each
implementation gets groups of its own, so that a name already taken (by dcsim or by a
package met earlier, in the order of the entry points' names) or an implementation
that raises is reported and skipped instead of silently replacing a command.
:class:`PluginGroup` is the click group that serves them beside dcsim's own.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping
from dataclasses import dataclass, field

import click

from dcsim.cli.common import plugin_registry
from dcsim.registry.discovery import PluginRegistry

GROUPS = ("cli", "bench")
"""The hook's arguments: the groups a package can add commands to (``dcsim NAME``,
``dcsim bench NAME``)."""


@dataclass(frozen=True)
class PluginCommands:
    """The commands plugin packages add, by group.

    Attributes
    ----------
    commands : dict
        Hook argument (``cli``, ``bench``) to command name to the click command.
    warnings : list of str
        Commands refused and why.
    """

    commands: dict[str, dict[str, click.Command]] = field(
        default_factory=lambda: {group: {} for group in GROUPS}
    )
    warnings: list[str] = field(default_factory=list)


def _command_line(group: str, name: str) -> str:
    return f"dcsim {name}" if group == "cli" else f"dcsim {group} {name}"


def plugin_commands(
    registry: PluginRegistry, taken: Mapping[str, Collection[str]]
) -> PluginCommands:
    """Call every package's ``dcsim_register_commands`` and gather what they add.

    Parameters
    ----------
    registry : PluginRegistry
        The registry whose hook modules are asked.
    taken : mapping
        Hook argument to the names dcsim's own commands hold in that group.

    Returns
    -------
    PluginCommands
        The commands accepted, and a warning for every one refused.
    """
    found = PluginCommands()
    hooks = registry.hook.dcsim_register_commands.get_hookimpls()
    for impl in sorted(hooks, key=lambda impl: impl.plugin_name):
        staged = {group: click.Group(group) for group in GROUPS}
        try:
            impl.function(**{argument: staged[argument] for argument in impl.argnames})
        except Exception as exc:  # a third party's hook raised
            found.warnings.append(
                f"plugin package '{impl.plugin_name}' failed while adding its commands, "
                f"which were skipped: {type(exc).__name__}: {exc}"
            )
            continue
        for group, stage in staged.items():
            for name, command in stage.commands.items():
                if name in taken.get(group, ()) or name in found.commands[group]:
                    found.warnings.append(
                        f"'{_command_line(group, name)}' of plugin package "
                        f"'{impl.plugin_name}' was skipped: that command already exists"
                    )
                else:
                    found.commands[group][name] = command
    return found


class PluginGroup(click.Group):
    """A click group that also holds the commands plugin packages add to it.

    The packages are asked only when a command is not one of dcsim's own, or when the
    commands are listed, once per command line.
    """

    hook_argument = "bench"
    """The argument of ``dcsim_register_commands`` that stands for this group."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        """dcsim's own commands and the plugin packages', sorted."""
        return sorted({*self.commands, *_added_commands(ctx, self.hook_argument)})

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        """dcsim's own command of that name, else a plugin package's."""
        own = self.commands.get(cmd_name)
        return own if own is not None else _added_commands(ctx, self.hook_argument).get(cmd_name)


def _added_commands(ctx: click.Context, group: str) -> dict[str, click.Command]:
    """The commands plugin packages add to ``group`` (a hook argument), asked once per
    command line; refused ones are printed as warnings on stderr.

    Only ``bench`` imports the plugins declared in the kinds' entry-point groups, to ask
    them for their benches; the other groups ask the ``dcsim`` group's modules, which
    discovery imports anyway, so that ``dcsim --help`` imports no plugin. The names
    taken are those of dcsim's own commands in the plugin groups of the command line:
    its root group and the groups directly under it.
    """
    root = ctx.find_root()
    key = f"dcsim.plugin_commands.{group}"
    if key not in root.meta:
        groups = [root.command, *getattr(root.command, "commands", {}).values()]
        taken = {g.hook_argument: g.commands for g in groups if isinstance(g, PluginGroup)}
        found = plugin_commands(plugin_registry(load_all=group == "bench"), taken)
        for message in found.warnings:
            click.echo(f"warning: {message}", err=True)
        root.meta[key] = found.commands[group]
    commands: dict[str, click.Command] = root.meta[key]
    return commands
