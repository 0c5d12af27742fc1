"""What each plugin kind hands back, and the check every answer passes at the boundary.

A sensor model's ``measure()`` gives its sensor's readings (:data:`SENSOR_READINGS`), a
tracker's ``update()`` a tuple of :class:`~dcsim.messages.ObjectTrack`, a localiser's
``estimate()`` gives a :class:`~dcsim.messages.StateEstimate`, a task
planner's ``plan()`` a :class:`~dcsim.messages.Plan`, a path planner's ``plan()`` a
:class:`~dcsim.messages.Trajectory` or a :class:`~dcsim.messages.NoPath` with a reason,
and a controller's ``command()`` a :class:`~dcsim.messages.Command`. Messages check
their own shapes when they are built; what is left to check is the type, the numbers
(every one finite), the things a message cannot know alone (how many joints the robot
has) and a trajectory's clock. The runner checks every answer this way
(:func:`dcsim.registry.calls.call_plugin`), and so does the conformance suite, so a
plugin that breaks its contract is named where it happens instead of one tick later in
another plugin.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, fields, is_dataclass
from typing import Any, NamedTuple, cast

import numpy as np

from dcsim.messages import (
    AttitudeReading,
    BeaconRange,
    Command,
    Detection,
    NoPath,
    ObjectTrack,
    Plan,
    RateReading,
    StateEstimate,
    Trajectory,
)


@dataclass(frozen=True)
class Answer:
    """What one kind's answering method must hand back.

    Attributes
    ----------
    method : str
        The method whose answer is checked (the kind's other methods answer None).
    types : tuple of type
        The message types it may return.
    expected : str
        The contract in words, for messages.
    """

    method: str
    types: tuple[type, ...]
    expected: str


ANSWERS: dict[str, Answer] = {
    "sensor": Answer(
        "measure",
        (tuple, AttitudeReading, RateReading, type(None)),
        "the readings its sensor gives (dcsim.api.SENSOR_SLOTS) with finite numbers",
    ),
    "tracker": Answer("update", (tuple,), "a tuple of ObjectTrack with finite numbers"),
    "localiser": Answer("estimate", (StateEstimate,), "a StateEstimate with finite numbers"),
    "task_planner": Answer("plan", (Plan,), "a Plan with finite times and points"),
    "path_planner": Answer(
        "plan",
        (Trajectory, NoPath),
        "a Trajectory (at least two samples, strictly increasing times, finite numbers) "
        "or a NoPath with a reason",
    ),
    "controller": Answer(
        "command",
        (Command,),
        "a Command with finite numbers and joint torques, thruster on-times and wheel "
        "torques each none or one per actuator",
    ),
}
"""The answer each plugin kind owes, by kind."""


SENSOR_READINGS: dict[str, tuple[type, bool]] = {
    "beacon_ranges": (BeaconRange, True),
    "star_tracker": (AttitudeReading, False),
    "gyros": (RateReading, False),
    "objects": (Detection, True),
}
"""What a sensor model of each slot gives: the reading's type, and whether it gives a
tuple of them (else one, or None between readings)."""


class ActuatorCounts(NamedTuple):
    """How many joints, thrusters and reaction wheels a robot has: a command gives one
    joint torque, thruster on-time or wheel torque per actuator of that kind, or none."""

    joints: int = 0
    thrusters: int = 0
    wheels: int = 0


def output_problem(
    kind: str,
    method: str,
    output: Any,
    actuators: ActuatorCounts | None = None,
    measures: str | None = None,
) -> str | None:
    """What is wrong with a plugin's answer, in words, or None when nothing is.

    Parameters
    ----------
    kind : str
        The plugin's kind (``localiser``, ``task_planner``, ``path_planner``,
        ``controller``).
    method : str
        The method that answered; any other than the kind's :data:`ANSWERS` method
        (``reset``, ``predict``, ``update``) answers nothing that is checked.
    output : object
        What it returned.
    actuators : ActuatorCounts, optional
        The robot's joints, thrusters and wheels, when known: a command gives one value
        per actuator of a kind, or none.
    measures : str, optional
        A sensor model's slot (its ``measures``), which says what it gives.

    Returns
    -------
    str or None
        E.g. ``"returned ndarray"`` or ``"returned non-finite numbers: force [nan 0 0]"``.
    """
    answer = ANSWERS.get(kind)
    if answer is None or answer.method != method:
        return None
    if not isinstance(output, answer.types):
        return f"returned {type(output).__name__}"
    if kind == "sensor":
        return _reading_problem(output, measures)
    if kind == "tracker":
        return _items_problem(cast(tuple[Any, ...], output), ObjectTrack)
    if isinstance(output, NoPath):
        return None if str(output.reason).strip() else "returned a NoPath without a reason"
    if type(output) is Command:
        return command_problem(output, actuators)
    problem = _non_finite(output)
    if problem is not None:
        return problem
    if isinstance(output, Command) and actuators is not None:
        return _command_shape_problem(output, actuators)
    if isinstance(output, Trajectory) and (
        len(output.times) < 2 or np.any(np.diff(output.times) <= 0)
    ):
        return "returned a trajectory whose times do not increase strictly over two samples or more"
    return None


def _reading_problem(output: Any, measures: str | None) -> str | None:
    """What is wrong with a sensor model's reading for its slot, or None."""
    if measures not in SENSOR_READINGS:
        return f"measures {measures!r}, which is not a sensor slot"
    reading, many = SENSOR_READINGS[measures]
    if many:
        return (
            _items_problem(output, reading)
            if isinstance(output, tuple)
            else (f"returned {type(output).__name__}")
        )
    if output is None:
        return None
    if not isinstance(output, reading):
        return f"returned {type(output).__name__}"
    return _non_finite(output)


def _items_problem(items: tuple[Any, ...], item_type: type) -> str | None:
    """What is wrong with a tuple of messages of ``item_type``, or None."""
    for index, item in enumerate(items):
        if not isinstance(item, item_type):
            return f"returned a tuple holding a {type(item).__name__} at [{index}]"
    if _all_finite(items):
        return None
    for index, item in enumerate(items):  # name the first non-finite number
        problem = _non_finite(item)
        if problem is not None:
            return f"{problem} in [{index}]"
    return None


_NUMBERS = (int, float)


def _all_finite(items: tuple[Any, ...]) -> bool:
    """Whether every number the messages hold is finite, tested in one pass over all of
    them (a tracker answers a track per object every tick): their arrays joined and
    tested, their scalars and the numbers of messages in their tuples summed (NaN and
    ±inf survive a sum; one that overflows says False, and the exact walk,
    :func:`_first_non_finite`, then finds nothing wrong)."""
    total = 0.0
    arrays = []
    for item in items:
        for value in item.__dict__.values():
            kind = type(value)
            if kind is np.ndarray:
                arrays.append(value)
            elif kind is float or kind is int:
                total += value
            elif kind is tuple:
                total += sum(_sum_of_numbers(v) for v in value if is_dataclass(v))
            elif isinstance(value, _NUMBERS) and kind is not bool:
                total += value
    if not math.isfinite(total):
        return False
    return not arrays or bool(np.isfinite(np.concatenate(arrays, axis=None)).all())


def _non_finite(message: Any) -> str | None:
    """The first non-finite number of a message, in words, or None: its numbers tested
    all at once (:func:`_all_finite`), and walked one by one only to name the bad one."""
    if _all_finite((message,)):
        return None
    return _first_non_finite(message)


def _first_non_finite(message: Any) -> str | None:
    """The first non-finite number of a message in field order, in words, or None: the
    exact walk, one number at a time."""
    for name, value in _numbers(message):
        if not _finite(value):
            return f"returned non-finite numbers: {name} {_show(value)}"
    return None


def command_problem(command: Command, actuators: ActuatorCounts | None = None) -> str | None:
    """What is wrong with a command, in words, or None when nothing is.

    Parameters
    ----------
    command : Command
        A controller's answer, or a command given to the run from outside.
    actuators : ActuatorCounts, optional
        The robot's joints, thrusters and wheels: the command gives one value per
        actuator of a kind, or none.

    Returns
    -------
    str or None
        E.g. ``"returned non-finite numbers: force [nan 0 0]"`` or ``"returned 2 joint
        torques for a robot with 6 joints"``.
    """
    values = (
        command.force,
        command.torque,
        command.joint_torques,
        command.thruster_on_times,
        command.wheel_torques,
    )
    if not np.isfinite(np.concatenate(values)).all():
        return _first_non_finite(command)
    return None if actuators is None else _command_shape_problem(command, actuators)


def _command_shape_problem(command: Command, actuators: ActuatorCounts) -> str | None:
    """What a command gives for actuators the robot lacks, or None."""
    for values, count, what, whose in (
        (command.joint_torques, actuators.joints, "joint torques", "joints"),
        (command.thruster_on_times, actuators.thrusters, "thruster on-times", "thrusters"),
        (command.wheel_torques, actuators.wheels, "wheel torques", "reaction wheels"),
    ):
        if len(values) not in (0, count):
            return f"returned {len(values)} {what} for a robot with {count} {whose}"
    return None


def _numbers(message: object, prefix: str = "") -> Iterator[tuple[str, Any]]:
    """Every number a message holds, by field path: floats, arrays, and those of the
    messages in its tuples (a plan's tasks and drop visits)."""
    for name in _field_names(type(message)):
        value = getattr(message, name)
        if isinstance(value, tuple):
            for index, item in enumerate(value):
                if is_dataclass(item):
                    yield from _numbers(item, f"{prefix}{name}[{index}].")
        elif isinstance(value, (float, np.ndarray)) or (
            isinstance(value, int) and not isinstance(value, bool)
        ):
            yield f"{prefix}{name}", value


def _sum_of_numbers(message: Any) -> float:
    """The sum of every number a message holds: finite when they all are (the quick test
    made on every answer; a sum that overflows sends it to the exact one)."""
    total = 0.0
    for _, value in _numbers(message):
        total += sum(value.ravel().tolist()) if isinstance(value, np.ndarray) else value
    return total


_FIELD_NAMES: dict[type, tuple[str, ...]] = {}


def _field_names(cls: type) -> tuple[str, ...]:
    """The field names of a message class (once per class: answers are checked every tick)."""
    names = _FIELD_NAMES.get(cls)
    if names is None:
        names = _FIELD_NAMES[cls] = tuple(f.name for f in fields(cls))
    return names


def _finite(value: float | np.ndarray) -> bool:
    if isinstance(value, np.ndarray):
        return bool(np.isfinite(value).all())
    return math.isfinite(value)


def _show(value: float | np.ndarray) -> str:
    """A short rendering of a value for a message."""
    if isinstance(value, np.ndarray) and value.size > 6:
        bad = int(value.size - np.isfinite(value).sum())
        return f"(shape {value.shape}, {bad} non-finite)"
    return str(value.tolist() if isinstance(value, np.ndarray) else value)
