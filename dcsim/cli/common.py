"""What the ``dcsim`` command groups share: the exit status of a user's error, the
plugin registry with its loading problems printed, progress lines on stderr, and the
checkout's campaign files that benches run by default."""

from __future__ import annotations

import warnings
from pathlib import Path

import click

from dcsim.errors import PluginLoadWarning
from dcsim.registry.discovery import PluginRegistry

EXIT_USER_ERROR = 2
"""Exit status of a command line that a user's error (a dcsim error) ended."""


def plugin_registry(load_all: bool = False) -> PluginRegistry:
    """Discover plugins (importing every one if ``load_all``), printing loading problems as
    warnings on stderr."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PluginLoadWarning)
        registry = PluginRegistry.discover()
        if load_all:
            registry.load_all()
    for message in registry.warnings:
        click.echo(f"warning: {message}", err=True)
    return registry


def progress(line: str) -> None:
    """Print a command's progress line on stderr (stdout keeps its results)."""
    click.echo(line, err=True)


def checkout_campaign(name: str) -> Path:
    """Campaign file ``name`` of this checkout's ``scenarios/campaigns`` (a bench's default).

    Raises
    ------
    click.BadParameter
        If dcsim is not run from a checkout that has it (an installed copy has no
        campaigns): the bench must then be given one.
    """
    path = Path(__file__).resolve().parents[2] / "scenarios" / "campaigns" / name
    if not path.exists():
        raise click.BadParameter(
            f"{name} is not here (dcsim runs from an installed copy): name a campaign file",
            param_hint="CAMPAIGN",
        )
    return path
