"""Calling plugins during a run: every exception a plugin raises, and every answer that
breaks its kind's contract (:mod:`dcsim.registry.answers`), becomes a recorded failure
that names the plugin."""

from __future__ import annotations

import traceback
from collections.abc import Mapping
from typing import Any

from dcsim.registry.answers import ANSWERS, ActuatorCounts, output_problem
from dcsim.registry.interfaces import Plugin


class PluginFailure(Exception):
    """A plugin raised, or answered with something its kind may not return, during a run.

    Attributes
    ----------
    role : str
        The role of the plugin (``localiser``, ``controller``...).
    plugin : str
        The plugin's name.
    method : str
        The method that raised or answered.
    error : BaseException or None
        What it raised; None when it answered wrongly.
    problem : str
        What is wrong, in words: the exception (``RuntimeError: boom``) or the answer
        (``returned ndarray; expected a Command with finite force...``).
    time : float or None
        Scenario time of the control tick it happened in, s (set by the runner).
    """

    def __init__(
        self,
        role: str,
        plugin: str,
        method: str,
        error: BaseException | None = None,
        problem: str = "",
    ) -> None:
        self.role, self.plugin, self.method, self.error = role, plugin, method, error
        self.problem = problem or f"{type(error).__name__}: {error}"
        self.time: float | None = None
        super().__init__()

    def __str__(self) -> str:
        verb = "raised in" if self.error is not None else "broke its contract in"
        when = "" if self.time is None else f" at t = {self.time:g} s"
        return f"{self.role} plugin '{self.plugin}' {verb} {self.method}(){when}: {self.problem}"

    @property
    def traceback(self) -> str | None:
        """The plugin's own traceback, formatted, when it raised: from the plugin's
        method down (the frame of :func:`call_plugin` that called it left out)."""
        if self.error is None:
            return None
        frames = self.error.__traceback__
        if frames is not None and frames.tb_next is not None:
            frames = frames.tb_next
        return "".join(traceback.format_exception(type(self.error), self.error, frames))


def call_plugin(
    plugins: Mapping[str, Plugin],
    role: str,
    method: str,
    *args: Any,
    actuators: ActuatorCounts | None = None,
) -> Any:
    """Call ``plugins[role].method(*args)`` and check its answer.

    Parameters
    ----------
    plugins : mapping of str to Plugin
        The run's plugins by role.
    role, method : str
        Whose method to call.
    *args
        Its arguments.
    actuators : ActuatorCounts, optional
        The robot's joints, thrusters and wheels, which a controller's command must match.

    Raises
    ------
    PluginFailure
        If the plugin raised, or answered with a value its kind may not return
        (:func:`dcsim.registry.answers.output_problem`).
    """
    plugin = plugins[role]
    try:
        answer = getattr(plugin, method)(*args)
    except Exception as error:  # a plugin's own bug ends the run, recorded
        raise PluginFailure(role, plugin.name, method, error) from error
    problem = output_problem(
        plugin.kind, method, answer, actuators, getattr(plugin, "measures", None)
    )
    if problem is not None:
        expected = ANSWERS[plugin.kind].expected
        raise PluginFailure(role, plugin.name, method, problem=f"{problem}; expected {expected}")
    return answer
