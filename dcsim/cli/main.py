"""The ``dcsim`` command line: its top group, and where each command group lives.

Every error a user can cause is printed as ``error: <message>`` with exit status 2 and
no traceback; ``dcsim --debug ...`` shows the traceback instead. The commands are in
the module of their group: :mod:`dcsim.cli.run` (``run``, ``validate``, ``view``),
:mod:`dcsim.cli.plugins` (``plugins``, ``new-plugin``), :mod:`dcsim.cli.bench`,
:mod:`dcsim.cli.campaign`, :mod:`dcsim.cli.fmu` and :mod:`dcsim.cli.robot`; the options
several commands share are in :mod:`dcsim.cli.options`. Installed plugin packages add
their own commands (``dcsim bench ant-colony`` is the ``ant-colony`` plugin's) through
the ``dcsim_register_commands`` hook (:mod:`dcsim.cli.plugin_commands`).
"""

from __future__ import annotations

import click

from dcsim import __version__
from dcsim.cli.bench import bench_group
from dcsim.cli.campaign import campaign_group
from dcsim.cli.common import EXIT_USER_ERROR
from dcsim.cli.fmu import fmu_group
from dcsim.cli.plugin_commands import PluginGroup
from dcsim.cli.plugins import new_plugin_command, plugins_command
from dcsim.cli.robot import robot_group
from dcsim.cli.run import run_command, validate_command, view_command
from dcsim.errors import DcsimError


class _Group(PluginGroup):
    """The ``dcsim`` group: it prints dcsim errors without a traceback."""

    hook_argument = "cli"

    def invoke(self, ctx: click.Context) -> object:
        try:
            return super().invoke(ctx)
        except DcsimError as exc:
            if ctx.meta.get("dcsim.debug"):
                raise
            click.echo(f"error: {exc}", err=True)
            ctx.exit(EXIT_USER_ERROR)


@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, "--version", "-V", prog_name="dcsim")
@click.option("--debug", is_flag=True, help="Show full tracebacks for errors.")
@click.pass_context
def cli(ctx: click.Context, debug: bool) -> None:
    """dcsim: simulate space debris collectors and free-flying space robots.

    Run a scenario with `dcsim run`, check scenario files with `dcsim validate`, and
    list the installed localisers, planners and controllers with `dcsim plugins`.
    """
    ctx.meta["dcsim.debug"] = debug


cli.add_command(run_command)
cli.add_command(validate_command)
cli.add_command(view_command)
cli.add_command(plugins_command)
cli.add_command(new_plugin_command)
cli.add_command(bench_group)
cli.add_command(campaign_group)
cli.add_command(fmu_group)
cli.add_command(robot_group)


def main() -> None:
    """Entry point of the ``dcsim`` console script."""
    cli(prog_name="dcsim")
