"""Commands that plugin packages add through ``dcsim_register_commands``: a third party's
bench appears in ``dcsim bench`` like the built-in plugins' own, a name dcsim already
uses is refused, and a package is asked only when a command is not dcsim's own."""

from __future__ import annotations

from types import ModuleType

import click

from dcsim.cli.plugin_commands import plugin_commands
from dcsim.registry.discovery import PluginOrigin, PluginRegistry
from tests.conftest import make_distribution

HELLO = """
    import click
    from dcsim.api import hookimpl

    @click.command("hello", short_help="Greets the bench.")
    @click.option("--name", default="world", show_default=True)
    def hello(name):
        "Say hello to NAME."
        click.echo(f"hello, {name}")

    @click.command("hello-world", short_help="Greets from the top.")
    def hello_world():
        "Say hello from dcsim hello-world."
        click.echo("hello from the top")

    @hookimpl
    def dcsim_register_commands(cli, bench):
        bench.add_command(hello)
        cli.add_command(hello_world)
"""

GREEDY = """
    import click
    from dcsim.api import hookimpl

    @hookimpl
    def dcsim_register_commands(cli):
        @cli.command("run")
        def run():
            "Not dcsim's run."
            click.echo("hijacked")
"""

BROKEN = """
    from dcsim.api import hookimpl

    @hookimpl
    def dcsim_register_commands(bench):
        raise RuntimeError("no commands today")
"""


def test_a_third_party_package_adds_a_bench_and_a_top_level_command(dcsim_cli, tmp_path):
    site = make_distribution(
        tmp_path / "site", "dcsim-hello", "0.1", {"dcsim_hello": HELLO}, {"hello": "dcsim_hello"}
    )
    listed = dcsim_cli("bench", "--help", extra_path=[site])
    assert listed.returncode == 0, listed.stderr
    assert "  hello          Greets the bench." in listed.stdout
    assert "  ant-colony " in listed.stdout and "  q-learning " in listed.stdout
    greeted = dcsim_cli("bench", "hello", "--name", "Ada", extra_path=[site])
    assert (greeted.returncode, greeted.stdout, greeted.stderr) == (0, "hello, Ada\n", "")
    top = dcsim_cli("--help", extra_path=[site])
    assert "  hello-world  Greets from the top." in top.stdout
    assert dcsim_cli("hello-world", extra_path=[site]).stdout == "hello from the top\n"


def test_a_taken_name_and_a_raising_hook_are_warnings_and_dcsims_commands_stay(dcsim_cli, tmp_path):
    site = make_distribution(
        tmp_path / "site",
        "dcsim-greedy",
        "0.1",
        {"dcsim_greedy": GREEDY, "dcsim_broken": BROKEN},
        {"greedy": "dcsim_greedy", "broken": "dcsim_broken"},
    )
    listed = dcsim_cli("--help", extra_path=[site])
    assert listed.returncode == 0, listed.stderr
    assert (
        "warning: 'dcsim run' of plugin package 'greedy = dcsim_greedy' was skipped: that "
        "command already exists" in listed.stderr
    )
    assert (
        "warning: plugin package 'broken = dcsim_broken' failed while adding its commands, "
        "which were skipped: RuntimeError: no commands today" in listed.stderr
    )
    assert "Run a scenario and record it" in listed.stdout
    # dcsim's own commands do not ask the packages at all
    validated = dcsim_cli("validate", "--help", extra_path=[site])
    assert validated.returncode == 0 and validated.stderr == ""


def _module(name: str, register) -> ModuleType:
    from dcsim.api import hookimpl

    module = ModuleType(name)
    module.dcsim_register_commands = hookimpl(register)
    return module


def test_the_first_package_by_entry_point_keeps_a_name_two_packages_add():
    def first(bench):
        bench.add_command(click.Command("same", help="first"))

    def second(bench):
        bench.add_command(click.Command("same", help="second"))
        bench.add_command(click.Command("other", help="second's other"))

    registry = PluginRegistry()
    for name, register in (("b-second", second), ("a-first", first)):
        registry.register_module(_module(name, register), PluginOrigin("test", "0", name))
    found = plugin_commands(registry, {"cli": ["run"], "bench": ["world"]})
    assert {name: c.help for name, c in found.commands["bench"].items()} == {
        "same": "first",
        "other": "second's other",
    }
    assert found.commands["cli"] == {}
    assert found.warnings == [
        "'dcsim bench same' of plugin package 'b-second' was skipped: that command already exists"
    ]
