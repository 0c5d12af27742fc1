"""Hook specifications: the points where plugin packages plug into dcsim.

A plugin package exposes a module (or a plugin class) through an entry point in its
plugin's kind's group (``dcsim.controllers``, ...; imported when the plugin is used) or
in the ``dcsim`` group (imported whenever the registry is built; see
:mod:`dcsim.registry.discovery`). Modules implement the hooks below, marked with
:data:`hookimpl`: :func:`dcsim_plugin_classes` provides plugin classes, and the
lifecycle hooks :func:`dcsim_run_start`, :func:`dcsim_run_step`,
:func:`dcsim_run_event` and :func:`dcsim_run_end` let a package observe runs (a
telemetry writer, a live report), and :func:`dcsim_register_commands` adds commands to
the ``dcsim`` command line (a plugin's own bench)::

    from dcsim.api import hookimpl

    @hookimpl
    def dcsim_plugin_classes():
        return [MyController]
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pluggy

from dcsim.registry.interfaces import Plugin

if TYPE_CHECKING:
    import click

    from dcsim.scenario.model import Scenario

PROJECT_NAME = "dcsim"
"""The pluggy project name, the entry-point group of hook modules, and the prefix of the
kinds' groups plugins are declared in."""

hookspec = pluggy.HookspecMarker(PROJECT_NAME)
hookimpl = pluggy.HookimplMarker(PROJECT_NAME)
"""Decorator marking a function as an implementation of a dcsim hook."""


@dataclass(frozen=True)
class RunInfo:
    """What lifecycle hooks are told about the run they observe.

    Attributes
    ----------
    scenario : Scenario
        The resolved scenario.
    seed : int
        The run's seed.
    out_dir : Path or None
        The run directory, or None when the run writes no files.
    """

    scenario: Scenario
    seed: int
    out_dir: Path | None


@hookspec
def dcsim_plugin_classes() -> list[type[Plugin]]:
    """Return the plugin classes this package provides.

    Each class derives from one of the four plugin kinds
    (:class:`~dcsim.registry.interfaces.Localiser`,
    :class:`~dcsim.registry.interfaces.TaskPlanner`,
    :class:`~dcsim.registry.interfaces.PathPlanner`,
    :class:`~dcsim.registry.interfaces.Controller`) and declares ``name``, ``summary`` and
    ``Params``.

    Returns
    -------
    list of type
        The plugin classes; their order does not matter.
    """
    raise NotImplementedError  # a specification: pluggy calls the implementations


@hookspec
def dcsim_register_commands(cli: click.Group, bench: click.Group) -> None:
    """Add commands to the ``dcsim`` command line.

    Called once when a ``dcsim`` command line needs a command it does not hold itself
    (``dcsim --help``, ``dcsim bench NAME``). Add click commands or groups to either
    group; the implementation may take only the arguments it uses. A module declared in a
    kind's entry-point group is asked for ``bench`` commands only (``dcsim bench``
    imports every such module to ask it); top-level commands come from modules of the
    ``dcsim`` group, the only ones ``dcsim --help`` asks::

        @hookimpl
        def dcsim_register_commands(bench):
            bench.add_command(my_bench_command)      # dcsim bench my-planner

    A name dcsim's own commands or another package already use is refused with a
    warning, and so is every command of an implementation that raises.

    Parameters
    ----------
    cli : click.Group
        Commands added here run as ``dcsim NAME``.
    bench : click.Group
        Commands added here run as ``dcsim bench NAME``.
    """


@hookspec
def dcsim_run_start(run: RunInfo) -> None:
    """Called once before the first control tick of a run.

    Parameters
    ----------
    run : RunInfo
        The run's resolved scenario, seed and output directory.
    """


@hookspec
def dcsim_run_step(run: RunInfo, row: Mapping[str, Any]) -> None:
    """Called after every control tick with that tick's telemetry row.

    Parameters
    ----------
    run : RunInfo
        The run.
    row : mapping
        Column name to value, as written to ``telemetry.csv`` (true and estimated
        state, mode, fuel, delta-v, nearest-obstacle distance, command), the names
        without the header's unit suffix (``x`` for ``x_m``); SI units.
    """


@hookspec
def dcsim_run_event(run: RunInfo, event: Mapping[str, Any]) -> None:
    """Called for every event (mode change, plan, grab, release, collision...).

    Parameters
    ----------
    run : RunInfo
        The run.
    event : mapping
        The event as written to ``events.jsonl``: ``t`` (s), ``event`` (its name)
        and the event's own fields.
    """


@hookspec
def dcsim_run_end(run: RunInfo, summary: Mapping[str, Any]) -> None:
    """Called once when a run ends, however it ends, with its summary.

    Parameters
    ----------
    run : RunInfo
        The run.
    summary : mapping
        The content of ``summary.json``.
    """
