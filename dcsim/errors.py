"""Error classes for mistakes a user can make.

Every error a user can cause (a bad scenario file, an unknown plugin name, an invalid
parameter, a broken plugin package) is raised as a subclass of :class:`DcsimError`
whose message says what to change. The command line prints such errors as
``error: <message>`` and exits with status 2; anything else is a bug in dcsim or in a
plugin and keeps its traceback.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable
from dataclasses import dataclass


class DcsimError(Exception):
    """Base class of every error a user can cause and fix."""


def did_you_mean(word: str, names: Iterable[str]) -> str:
    """The hint an error gives for a name that is not known: the closest known name.

    Case is ignored in the comparison, so ``EKF`` finds ``ekf``.

    Parameters
    ----------
    word : str
        The name given.
    names : iterable of str
        The names known there.

    Returns
    -------
    str
        ``"; did you mean 'ekf'?"``, or an empty string when no name is close.
    """
    folded: dict[str, str] = {}
    for name in names:
        folded.setdefault(name.casefold(), name)
    close = difflib.get_close_matches(word.casefold(), list(folded), n=1)
    return f"; did you mean '{folded[close[0]]}'?" if close else ""


@dataclass(frozen=True)
class Problem:
    """One problem found while validating a document.

    Parameters
    ----------
    path : str
        Key path of the offending value, e.g. ``mission.targets[3].motion.r``.
    message : str
        What is wrong and what is allowed.
    line, column : int or None
        1-based position in the source file, when the parser knows it.
    source : str or None
        Where the value came from when it was not the file itself, e.g.
        ``--set world.seed=3``.
    """

    path: str
    message: str
    line: int | None = None
    column: int | None = None
    source: str | None = None

    def describe(self, filename: str) -> str:
        """Return the problem as one line: ``file:line:col: path: message``."""
        if self.source is not None:
            where = self.source
        elif self.line is not None:
            where = f"{filename}:{self.line}:{self.column}"
        else:
            where = filename
        path = f"{self.path}: " if self.path else ""
        return f"{where}: {path}{self.message}"


class ScenarioError(DcsimError):
    """A scenario file (or an override of it) does not describe a valid scenario.

    Parameters
    ----------
    filename : str
        The scenario file's name as the user gave it.
    problems : list of Problem
        Every problem found, in document order.
    """

    document = "scenario"
    """What kind of document the file is, for the message's first line."""

    def __init__(self, filename: str, problems: list[Problem]) -> None:
        self.filename = filename
        self.problems = list(problems)
        lines = [p.describe(filename) for p in self.problems]
        count = f"{len(lines)} problem{'s' if len(lines) != 1 else ''}"
        head = f"{filename}: invalid {self.document} ({count})"
        super().__init__("\n".join([head, *("  " + line for line in lines)]))


class CampaignError(ScenarioError):
    """A campaign file does not describe a valid campaign (same form as a scenario's)."""

    document = "campaign"


class RobotTypeError(DcsimError):
    """A scenario's robot is not of the type a command or a call needs."""


class PluginError(DcsimError):
    """Base class of errors about plugins and the plugin registry."""


class PluginNotFoundError(PluginError):
    """No registered plugin of the requested kind has the requested name."""


class DuplicatePluginError(PluginError):
    """Two plugins registered the same kind and name."""


class PluginInterfaceError(PluginError):
    """A plugin class does not satisfy its kind's interface."""


class PluginLoadError(PluginError):
    """A plugin's module failed to import, or failed to give the plugin's class, when the
    plugin was used."""


class PluginParameterError(PluginError):
    """Parameters given to a plugin are invalid.

    Parameters
    ----------
    plugin : str
        The plugin's name.
    problems : list of Problem
        One entry per invalid parameter; ``path`` is the parameter name.
    """

    def __init__(self, plugin: str, problems: list[Problem]) -> None:
        self.plugin = plugin
        self.problems = list(problems)
        lines = [f"{p.path}: {p.message}" if p.path else p.message for p in self.problems]
        super().__init__(f"invalid parameters for plugin '{plugin}': " + "; ".join(lines))


class PluginLoadWarning(UserWarning):
    """A plugin package could not be loaded; every other plugin still is."""


class CwValidityWarning(UserWarning):
    """A ``cw`` run flew far enough from the chief, for long enough, that the
    Clohessy–Wiltshire linearisation may be off by more than ``world.orbit.cw_tolerance``."""


class PlannerModelWarning(UserWarning):
    """A planner plans with other orbital dynamics than the world moves bodies by (its
    ``orbit_models`` do not include ``world.orbit.model``)."""


class PlanOutlastsRunWarning(UserWarning):
    """A plan made during a run ends after ``world.duration``: the run will stop before
    the plan is flown to its end."""
