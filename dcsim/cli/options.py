"""Options and arguments that several ``dcsim`` commands share, as click decorators.

Each decorator adds one option (or argument) to a command; where commands give the
same option different help, default or bounds, those are the decorator's parameters.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol, TypeVar

import click

if TYPE_CHECKING:
    from dcsim.campaign import ClusterOptions

F = TypeVar("F", bound=Callable[..., Any])
"""A command function, or the click command the decorators below have made of it."""


class Decorator(Protocol):
    """A decorator that adds an option or argument to a command, whatever its signature."""

    def __call__(self, command: F, /) -> F: ...


def scenario_argument(required: bool = True) -> Decorator:
    """``SCENARIO``: a scenario file, as ``scenario``.

    Parameters
    ----------
    required : bool
        Whether the command needs one; when not, the command flies the packaged
        scenario without it.
    """
    return click.argument(
        "scenario", required=required, type=click.Path(dir_okay=False, path_type=Path)
    )


def overrides_option(help: str) -> Decorator:
    """``--set KEY.PATH=VALUE`` (repeatable): scenario values to override, as ``overrides``.

    Parameters
    ----------
    help : str
        The option's help: what the overrides apply to.
    """
    return click.option("--set", "overrides", multiple=True, metavar="KEY.PATH=VALUE", help=help)


def out_dir_option(help: str, default: Path | None = None) -> Decorator:
    """``--out``: the directory a command writes, as ``out``.

    Parameters
    ----------
    help : str
        The option's help: what goes into the directory, and where without the option.
    default : Path or None
        The directory without the option (shown in the help), or None.
    """
    return click.option(
        "--out",
        type=click.Path(file_okay=False, path_type=Path),
        default=default,
        show_default=default is not None,
        help=help,
    )


def out_file_option(help: str) -> Decorator:
    """``-o``/``--out``: the file a command writes, required, as ``out``.

    Parameters
    ----------
    help : str
        The option's help: which file.
    """
    return click.option(
        "-o",
        "--out",
        required=True,
        type=click.Path(dir_okay=False, path_type=Path),
        help=help,
    )


def plot_option(help: str) -> Decorator:
    """``--plot FILE``: where to save a bench's plot, as ``plot_path`` (None: no plot).

    Parameters
    ----------
    help : str
        The option's help: what the plot shows.
    """
    return click.option(
        "--plot", "plot_path", type=click.Path(dir_okay=False, path_type=Path), help=help
    )


def fly_option(help: str) -> Decorator:
    """``--fly``: also fly a planner bench's plans through the transfer mission, as ``fly``.

    Parameters
    ----------
    help : str
        The option's help: which plans are flown.
    """
    return click.option("--fly", is_flag=True, help=help)


def duration_option(default: float) -> Decorator:
    """``--duration``: simulated seconds per measurement of a bench, at least 1 s.

    Parameters
    ----------
    default : float
        The duration without the option, s (shown in the help).
    """
    return click.option(
        "--duration",
        type=click.FloatRange(min=1.0),
        default=default,
        show_default=True,
        help="Simulated seconds per measurement.",
    )


def count_option(name: str, default: int, help: str, minimum: int = 1) -> Decorator:
    """An integer option (runs, seeds, instances, repeats ...) with its default shown.

    Parameters
    ----------
    name : str
        The option, e.g. ``--runs``.
    default : int
        Its value without the option.
    help : str
        The option's help.
    minimum : int
        The least value accepted.
    """
    return click.option(
        name, type=click.IntRange(min=minimum), default=default, show_default=True, help=help
    )


def positive_option(name: str, default: float, help: str) -> Decorator:
    """A number option above zero (a noise, a time, a step ...) with its default shown.

    Parameters
    ----------
    name : str
        The option, e.g. ``--sigma``.
    default : float
        Its value without the option, in the unit its help names.
    help : str
        The option's help, naming the unit.
    """
    return click.option(
        name,
        type=click.FloatRange(min=0, min_open=True),
        default=default,
        show_default=True,
        help=help,
    )


def cluster_options(command: F) -> F:
    """Add the options that choose where cases run (``--scheduler``, ``--connect-timeout``,
    ``--workers``, ``--worker-deaths``) to a command; :func:`cluster_choice` reads them."""
    options: list[Decorator] = [
        click.option(
            "--scheduler",
            metavar="tcp://HOST:PORT",
            help="Run on this existing Dask scheduler (its workers need dcsim and the "
            "campaign's plugins installed, and the campaign directory at the same path). "
            "Default: a local cluster.",
        ),
        click.option(
            "--connect-timeout",
            type=click.FloatRange(min=0.1, max=3600.0),
            metavar="SECONDS",
            help="Seconds to wait for the --scheduler before giving up. Default: 10 "
            "(dcsim.campaign.engine.CONNECT_TIMEOUT).",
        ),
        click.option(
            "--workers",
            type=click.IntRange(min=1, max=1024),
            help="Worker processes of the local cluster. Default: one per core.",
        ),
        click.option(
            "--worker-deaths",
            type=click.IntRange(min=1, max=100),
            default=3,
            show_default=True,
            help="Workers that may die running one case (killed, out of memory) before "
            "it is a failed case. Local cluster only.",
        ),
    ]
    for option in reversed(options):
        command = option(command)
    return command


def cluster_choice(
    scheduler: str | None,
    workers: int | None,
    worker_deaths: int,
    connect_timeout: float | None,
) -> ClusterOptions:
    """The cluster the options chose; ``--workers`` with ``--scheduler``, or
    ``--connect-timeout`` without it, is an error."""
    from dcsim.campaign import ClusterOptions

    if scheduler is not None and workers is not None:
        raise click.BadParameter(
            "--workers sizes the local cluster; an existing scheduler has its own workers",
            param_hint="--workers",
        )
    if scheduler is None and connect_timeout is not None:
        raise click.BadParameter(
            "--connect-timeout is for a cluster given by --scheduler; the local cluster "
            "is started here",
            param_hint="--connect-timeout",
        )
    return ClusterOptions(scheduler, workers, worker_deaths, connect_timeout)
