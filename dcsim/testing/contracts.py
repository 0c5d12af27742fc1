"""The plugin contracts, one check each.

A check is a function taking the plugin class and raising :class:`ContractViolation`
with a message that says what the plugin did and what the contract expects. Checks are
registered per kind with :func:`contract`; :func:`checks_for` lists those that apply to
a kind, in a stable order.
"""

from __future__ import annotations

import ast
import copy
import dataclasses
import inspect
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, NoReturn, TypeVar

import numpy as np

from dcsim.errors import PluginInterfaceError, PluginParameterError
from dcsim.messages import (
    Reference,
    StateEstimate,
    Surroundings,
    Trajectory,
)
from dcsim.registry.answers import ANSWERS, ActuatorCounts, output_problem
from dcsim.registry.discovery import check_plugin_class
from dcsim.registry.interfaces import (
    PLUGIN_KINDS,
    Controller,
    Localiser,
    Plugin,
    SensorModel,
    Tracker,
)
from dcsim.testing import problems

SEED = 1234
"""Seed of the generator every plugin under test is constructed with."""

LOCALISER_ERROR_BOUND = 1.0
"""Largest position error (m) a localiser may have at the end of the standard problem."""

TIME_SLACK = 0.2
"""Wall time (s) allowed beyond a time budget (and 20 % of it) for returning."""

P = TypeVar("P", bound=Plugin)


class ContractViolation(AssertionError):
    """A plugin broke a contract; the message says how and what was expected."""


@dataclass(frozen=True)
class Check:
    """One contract check.

    Attributes
    ----------
    name : str
        Identifier, used as the test name (``deterministic``, ``converges``...).
    kinds : tuple of str
        Plugin kinds it applies to.
    contract : str
        The contract in words.
    function : callable
        ``function(plugin_class)``; raises :class:`ContractViolation`.
    robots : tuple of str
        Robot types whose problems the check poses; empty: any.
    """

    name: str
    kinds: tuple[str, ...]
    contract: str
    function: Callable[[type[Plugin]], None]
    robots: tuple[str, ...] = ()

    def applies(self, plugin_class: type[Plugin]) -> bool:
        """Whether the check poses a problem of a robot the plugin supports (a check that
        names no robot applies to every plugin of its kinds)."""
        return not self.robots or bool(set(self.robots) & set(_robots(plugin_class)))

    def run(self, plugin_class: type[Plugin]) -> None:
        """Run the check, prefixing any violation with the plugin and the contract; a
        check for robots the plugin does not support has nothing to check."""
        if not self.applies(plugin_class):
            return
        try:
            self.function(plugin_class)
        except ContractViolation as violation:
            raise ContractViolation(
                f"{_label(plugin_class)} breaks '{self.name}': {violation}\n"
                f"  contract: {self.contract}"
            ) from None


_CHECKS: list[Check] = []


def contract(
    name: str,
    text: str,
    kinds: tuple[str, ...] = tuple(PLUGIN_KINDS),
    robots: tuple[str, ...] = (),
) -> Callable:
    """Register the decorated function as the check ``name`` for ``kinds`` (and, if
    given, only for plugins supporting one of ``robots``)."""

    def register(function: Callable[[type[Plugin]], None]) -> Callable[[type[Plugin]], None]:
        _CHECKS.append(Check(name, kinds, text, function, robots))
        return function

    return register


def checks_for(kind: str, plugin_class: type[Plugin] | None = None) -> list[Check]:
    """Every check that applies to plugins of ``kind`` (and to ``plugin_class``'s robots,
    if given)."""
    return [
        c for c in _CHECKS if kind in c.kinds and (plugin_class is None or c.applies(plugin_class))
    ]


def _robots(plugin_class: type[Plugin]) -> tuple[str, ...]:
    return tuple(getattr(plugin_class, "robots", ("free-flyer",)))


def problem_robot(plugin_class: type[Plugin] | None) -> str:
    """The robot type the standard controller ticks and path problems are posed for: the
    free flyer, unless the plugin supports manipulators only."""
    if plugin_class is not None and "free-flyer" not in _robots(plugin_class):
        if "manipulator" in _robots(plugin_class):
            return "manipulator"
    return "free-flyer"


def _label(plugin_class: type) -> str:
    kind = getattr(plugin_class, "kind", "?")
    return f"{kind} plugin '{getattr(plugin_class, 'name', plugin_class.__name__)}'"


def make(plugin_class: type[P], params: Any = None, seed: int = SEED) -> P:
    """A plugin instance with ``params`` (defaults if None) and a generator seeded with ``seed``."""
    return plugin_class(params, np.random.default_rng(seed))


def not_derived(plugin_class: type[Plugin], base: type) -> NoReturn:
    """Fail a check that drives a plugin through the interface of ``base``, its kind's
    class, which ``plugin_class`` does not derive from."""
    fail(f"{_label(plugin_class)} does not derive from {base.__name__}")


def fail(message: str) -> NoReturn:
    """Raise a :class:`ContractViolation` saying what the plugin did."""
    raise ContractViolation(message)


# --------------------------------------------------------------------- exercises
# For each kind: the standard inputs, and how to feed them to a plugin.


def _localiser_inputs(empty: bool) -> list:
    problem = problems.beacon_problem(steps=40)
    steps = [(s.motion, s.dt, [] if empty else list(s.ranges)) for s in problem.steps]
    return [problem.prior, problem.start_time, steps]


def _feed_localiser(plugin: Localiser, inputs: list) -> list:
    prior, start, steps = inputs
    plugin.reset(prior, start)
    outputs = []
    for motion, dt, ranges in steps:
        plugin.predict(motion, dt)
        plugin.update(ranges)
        outputs.append(plugin.estimate())
    return outputs


def _controller_inputs(empty: bool, plugin_class: type[Plugin] | None) -> list:
    if problem_robot(plugin_class) == "manipulator":
        return problems.manipulator_ticks(empty)
    rng = np.random.default_rng(3)
    obstacles = () if empty else problems.path_problem().obstacles
    ticks = []
    for k in range(20):
        t = 0.1 * k
        estimate = StateEstimate(
            time=t, position=rng.normal(0, 10, 3), velocity=rng.normal(0, 0.2, 3), converged=True
        )
        reference = Reference(time=t, position=rng.normal(0, 10, 3), velocity=rng.normal(0, 0.1, 3))
        ticks.append((t, estimate, reference, Surroundings(obstacles)))
    return [problems.ROBOT, ticks]


def _feed_controller(plugin: Controller, inputs: list) -> list:
    robot, ticks = inputs
    plugin.reset(robot)
    return [plugin.command(*tick) for tick in ticks]


def _path_inputs(empty: bool, plugin_class: type[Plugin] | None) -> list:
    if problem_robot(plugin_class) == "manipulator":
        return [problems.reach_problem()]
    problem = problems.path_problem()
    if plugin_class is not None:
        problem = problems.posed(plugin_class, problem)
    if empty:
        problem = dataclasses.replace(problem, obstacles=(), bounds=None)
    return [problem]


def _feed_sensor(plugin: SensorModel, inputs: list) -> list:
    setup, truths = inputs
    plugin.reset(setup)
    return [plugin.measure(truth) for truth in truths]


def _tracker_inputs(empty: bool) -> list:
    problem = problems.tracker_problem(empty=empty)
    ticks = [(tick.time, tick.detections, tick.robot) for tick in problem.ticks]
    return [problem.frame, problem.start_time, ticks]


def _feed_tracker(plugin: Tracker, inputs: list) -> list:
    frame, start, ticks = inputs
    plugin.reset(frame, start)
    return [plugin.update(*tick) for tick in ticks]


_INPUTS: dict[str, Callable[[bool, Any], list]] = {
    "sensor": lambda empty, _: [problems.sensor_setup(empty), problems.sensed_truths(empty=empty)],
    "tracker": lambda empty, _: _tracker_inputs(empty),
    "localiser": lambda empty, _: _localiser_inputs(empty),
    "task_planner": lambda empty, _: [problems.task_request(targets=0 if empty else 6)],
    "path_planner": _path_inputs,
    "controller": _controller_inputs,
}
_FEEDS: dict[str, Callable[[Any, list], list]] = {
    "sensor": _feed_sensor,
    "tracker": _feed_tracker,
    "localiser": _feed_localiser,
    "task_planner": lambda plugin, inputs: [plugin.plan(request) for request in inputs],
    "path_planner": lambda plugin, inputs: [plugin.plan(problem) for problem in inputs],
    "controller": _feed_controller,
}


def standard_inputs(
    kind: str, empty: bool = False, plugin_class: type[Plugin] | None = None
) -> list:
    """The standard inputs of a kind (``empty``: no beacons, targets or obstacles), as
    posed to ``plugin_class`` if given (:func:`dcsim.testing.problems.posed`)."""
    return _INPUTS[kind](empty, plugin_class)


def feed(plugin: Plugin, inputs: list) -> list:
    """Feed standard inputs to a plugin; return its outputs in order."""
    return _FEEDS[plugin.kind](plugin, inputs)


def _same(a: Any, b: Any) -> bool:
    """Deep equality of messages, arrays, tuples, lists, dicts, floats (NaN equal to NaN)
    and plain objects (by their attributes)."""
    if isinstance(a, (list, tuple)):
        return (
            type(a) is type(b)
            and len(a) == len(b)
            and all(_same(x, y) for x, y in zip(a, b, strict=True))
        )
    if isinstance(a, np.ndarray):
        return (
            isinstance(b, np.ndarray)
            and a.shape == b.shape
            and np.array_equal(a, b, equal_nan=True)
        )
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    if dataclasses.is_dataclass(a) and type(a) is type(b):
        return all(_same(getattr(a, f.name), getattr(b, f.name)) for f in dataclasses.fields(a))
    if isinstance(a, dict):
        return isinstance(b, dict) and a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if type(a) is type(b) and type(a).__eq__ is object.__eq__ and hasattr(a, "__dict__"):
        # an object without its own equality (a robot's model): equal state, not identity
        return _same(vars(a), vars(b))
    return bool(a == b)


def _flatten(items: list) -> list:
    """The leaves of nested input lists, for pointing at the one that differs."""
    out = []
    for item in items:
        out.extend(_flatten(item) if isinstance(item, list) else [item])
    return out


def _first_difference(first: list, second: list) -> int:
    return next(i for i, (x, y) in enumerate(zip(first, second, strict=True)) if not _same(x, y))


def run_plugin(plugin_class: type[Plugin], inputs: list, what: str) -> list:
    """Feed ``inputs`` to a fresh instance and return its answers.

    An exception, or an answer of the wrong type or with a non-finite number
    (:func:`checked_answer`), becomes a violation naming ``what``.
    """
    try:
        outputs = feed(make(plugin_class), inputs)
    except Exception as error:  # a plugin's own failure: name it, with the problem posed
        raise ContractViolation(f"raised {type(error).__name__}: {error} on {what}") from error
    measures = getattr(plugin_class, "measures", None)
    for index, output in enumerate(outputs):
        checked_answer(plugin_class.kind, output, f"{what} (answer {index})", measures=measures)
    return outputs


def checked_answer(
    kind: str,
    output: Any,
    what: str,
    actuators: ActuatorCounts | None = None,
    measures: str | None = None,
) -> Any:
    """``output`` when it is an answer a plugin of ``kind`` may give (the check a run makes
    at the plugin boundary, :func:`dcsim.registry.answers.output_problem`; ``measures``:
    a sensor model's slot); otherwise a violation saying what was wrong on ``what`` and
    what was expected."""
    answer = ANSWERS[kind]
    problem = output_problem(kind, answer.method, output, actuators, measures)
    if problem is not None:
        fail(f"{problem} on {what}; expected {answer.expected}")
    return output


# --------------------------------------------------------------------- every kind


@contract(
    "declares_metadata",
    "the class derives from its kind, sets `name` and a one-line `summary`, "
    "and has a `Params` model",
)
def check_metadata(plugin_class: type[Plugin]) -> None:
    try:
        check_plugin_class(plugin_class)
    except PluginInterfaceError as error:
        fail(str(error))


METADATA_CHECK = next(c for c in _CHECKS if c.function is check_metadata)
"""The check every other check relies on."""


@contract(
    "parameters_round_trip",
    "the default parameters dumped to plain data validate back to an equal model",
)
def check_round_trip(plugin_class: type[Plugin]) -> None:
    defaults = plugin_class.Params.parse(plugin_class.name, None)
    dumped = defaults.model_dump(mode="json")
    again = plugin_class.Params.parse(plugin_class.name, dumped)
    if again != defaults:
        fail(f"{dumped} validated to {again.model_dump()}, not to the defaults it came from")


@contract(
    "constructs_with_defaults",
    "the class constructs with no parameters (all defaults) and a seeded generator",
)
def check_construction(plugin_class: type[Plugin]) -> None:
    try:
        make(plugin_class)
    except Exception as error:  # a plugin's own constructor failing
        fail(f"construction with defaults raised {type(error).__name__}: {error}")


def _invalid_parameter_sets(plugin_class: type[Plugin]) -> list[dict[str, Any]]:
    """An unknown parameter, and each bounded parameter just outside its bound."""
    cases: list[dict[str, Any]] = [{"no_such_parameter_xyz": 1}]
    outside = {"gt": 0.0, "ge": -1.0, "lt": 0.0, "le": 1.0}
    for name, info in plugin_class.Params.model_fields.items():
        for meta in info.metadata:
            for attr, offset in outside.items():
                bound = getattr(meta, attr, None)
                if bound is not None:
                    cases.append({name: bound + offset})
    return cases


@contract(
    "rejects_invalid_parameters",
    "unknown parameters and values outside their declared bounds raise PluginParameterError",
)
def check_invalid_parameters(plugin_class: type[Plugin]) -> None:
    for values in _invalid_parameter_sets(plugin_class):
        try:
            plugin_class(values, np.random.default_rng(0))
        except PluginParameterError:
            continue
        except Exception as error:  # anything else is the wrong way to refuse
            name = type(error).__name__
            fail(f"parameters {values} raised {name}: {error}, not PluginParameterError")
        fail(f"parameters {values} were accepted")


@contract(
    "deterministic",
    "two instances with the same seed, given the same inputs, give identical outputs",
)
def check_determinism(plugin_class: type[Plugin]) -> None:
    first = run_plugin(
        plugin_class,
        standard_inputs(plugin_class.kind, plugin_class=plugin_class),
        "the standard problem",
    )
    second = run_plugin(
        plugin_class,
        standard_inputs(plugin_class.kind, plugin_class=plugin_class),
        "the standard problem",
    )
    if not _same(first, second):
        i = _first_difference(first, second)
        fail(
            f"output {i} differs between two identically seeded runs: {first[i]!r} vs {second[i]!r}"
        )


@contract(
    "does_not_mutate_inputs",
    "every input (lists, messages and their arrays) is unchanged after the plugin used it",
)
def check_no_mutation(plugin_class: type[Plugin]) -> None:
    inputs = standard_inputs(plugin_class.kind, plugin_class=plugin_class)
    pristine = copy.deepcopy(inputs)
    run_plugin(plugin_class, inputs, "the standard problem")
    given, kept = _flatten(inputs), _flatten(pristine)
    if not _same(given, kept):
        i = _first_difference(given, kept)
        fail(f"an input was changed: it is now {given[i]!r}, it was given as {kept[i]!r}")


def _check_output(kind: str, output: Any, measures: str | None = None) -> str | None:
    """Why an output is not of the documented type, shape and finiteness, or (for an
    estimate) its covariance not symmetric (None if fine); ``measures``: a sensor
    model's slot."""
    problem = output_problem(kind, ANSWERS[kind].method, output, None, measures)
    if problem is not None:
        return problem
    if isinstance(output, StateEstimate):
        covariance = output.covariance
        if not np.allclose(covariance, covariance.T, rtol=1e-9, atol=1e-12):
            return f"covariance is not a symmetric square matrix: {covariance!r}"
    return None


@contract(
    "outputs_well_formed",
    "outputs are of the documented types, with finite values and valid shapes",
)
def check_outputs(plugin_class: type[Plugin]) -> None:
    for output in run_plugin(
        plugin_class,
        standard_inputs(plugin_class.kind, plugin_class=plugin_class),
        "the standard problem",
    ):
        problem = _check_output(plugin_class.kind, output, getattr(plugin_class, "measures", None))
        if problem:
            fail(problem)


@contract(
    "uses_only_the_public_api",
    "the plugin's module imports nothing of dcsim but dcsim.api, so it cannot reach ground "
    "truth: it works from its inputs alone (not asked of sensor models, which are part of "
    "the world and are given the truth)",
    kinds=tuple(kind for kind in PLUGIN_KINDS if kind != "sensor"),
)
def check_public_api(plugin_class: type[Plugin]) -> None:
    module = inspect.getmodule(plugin_class)
    if module is None:
        return  # classes defined interactively have no source to read
    try:
        source = inspect.getsource(module)
    except (OSError, TypeError):
        return  # nor do those of built-in or compiled modules
    for node in ast.walk(ast.parse(source)):
        names = []
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names = [node.module]
        for name in names:
            if name.split(".")[0] == "dcsim" and name not in ("dcsim.api", "dcsim.testing"):
                fail(f"imports {name}; plugins may use dcsim.api only")


@contract(
    "handles_empty_inputs",
    "with no beacons in view, no targets, no obstacles, no objects to sense or no detections "
    "the plugin returns its documented empty answer (an unconverged estimate, an empty plan, "
    "a path, a command, no reading, no tracks) instead of raising",
)
def check_empty_inputs(plugin_class: type[Plugin]) -> None:
    outputs = run_plugin(
        plugin_class,
        standard_inputs(plugin_class.kind, empty=True, plugin_class=plugin_class),
        "empty inputs",
    )
    for output in outputs:
        problem = _check_output(plugin_class.kind, output, getattr(plugin_class, "measures", None))
        if problem:
            fail(f"on empty inputs {problem}")
    if plugin_class.kind == "task_planner" and (outputs[0].tasks or outputs[0].drop_visits):
        fail(f"with no targets and nothing carried the plan should be empty, got {outputs[0]!r}")
    if plugin_class.kind == "path_planner" and not isinstance(outputs[0], Trajectory):
        fail(f"with no obstacles and no bounds there is a path, got {outputs[0]!r}")
