"""Loading a scenario: parse, override, validate, resolve plugins, dump.

The steps, each of which reports every problem it finds at once:

1. :meth:`ScenarioDocument.from_file` parses the YAML (safe loader) and records where
   each key is;
2. ``--set key.path=value`` overrides are applied to the raw data;
3. :func:`validate` checks the data against the schema and the rules across sections;
4. :func:`resolve_plugins` looks up each role's plugin and validates its parameters,
   filling in their defaults.

:func:`dump_scenario` writes the resolved scenario back as YAML; loading that text again
gives an equal scenario.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable, Mapping, Sequence
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Annotated, Any, get_args, get_origin

import numpy as np
import yaml
from pydantic import BaseModel, TypeAdapter, ValidationError

from dcsim.errors import DcsimError, PluginParameterError, Problem, ScenarioError, did_you_mean
from dcsim.params import describe_error, field_unit, short_repr
from dcsim.registry.discovery import PluginRegistry
from dcsim.scenario.document import KeyPath, ScenarioDocument, format_key_path
from dcsim.scenario.model import (
    MAX_PHYSICS_STEPS,
    MAX_STEPS_PER_CONTROL_PERIOD,
    MEAN_MOTION_RANGE,
    ActuatorsSpec,
    MissionSettings,
    OrbitSpec,
    Scenario,
    SensorChoice,
    SensorsSection,
    scenario_model,
)
from dcsim.scenario.sensors import sensor_choices, sensor_model_class

DEFAULT_SCENARIO = "default.yaml"

ROBOT_TYPES = ("free-flyer", "manipulator")
"""The values of ``robot.type``."""


def default_scenario_path() -> Path:
    """Path of the default scenario shipped inside the package."""
    return packaged_scenario_path(DEFAULT_SCENARIO)


def packaged_scenario_path(name: str) -> Path:
    """Path of scenario file ``name`` shipped inside the package (``default.yaml``, ...)."""
    return Path(str(resources.files("dcsim") / "scenarios" / name))


ScenarioSource = str | Path | Mapping[str, Any] | ScenarioDocument | None
"""A scenario file's path, the scenario's data as a mapping, a parsed document (copied:
overrides never change it), or None for the packaged one."""

MAPPING_NAME = "scenario mapping"
"""How errors name a scenario given as a mapping rather than a file."""


def scenario_document(source: ScenarioSource = None) -> ScenarioDocument:
    """Read a scenario file, or take a mapping of the same data, as a document.

    A mapping is held to the same rules as a file: it goes through YAML's safe dumper
    and parser, so it may hold only plain data (numbers, strings, booleans, None, lists
    and mappings). Its problems are reported by key path, without lines.

    Raises
    ------
    ScenarioError
        If the file cannot be read or parsed, or the mapping holds other objects.
    """
    if source is None:
        return ScenarioDocument.from_file(default_scenario_path())
    if isinstance(source, ScenarioDocument):
        return copy.deepcopy(source)
    if not isinstance(source, Mapping):
        return ScenarioDocument.from_file(source)
    try:
        text = yaml.safe_dump(dict(source), sort_keys=False)
    except yaml.YAMLError as error:
        message = f"holds a value that is not plain data (numbers, text, lists, mappings): {error}"
        raise ScenarioError(MAPPING_NAME, [Problem("", message)]) from None
    doc = ScenarioDocument.from_text(text, MAPPING_NAME)
    doc.marks.clear()  # lines of a text the user never saw would mislead
    return doc


def read_scenario(
    path: ScenarioSource = None,
    overrides: Sequence[str] = (),
    registry: PluginRegistry | None = None,
) -> Scenario:
    """Load, override, validate and (given a registry) resolve a scenario file.

    Parameters
    ----------
    path : str, Path or mapping, optional
        Scenario file, or the scenario's data as a mapping (:func:`scenario_document`);
        the packaged default scenario if None.
    overrides : sequence of str
        ``key.path=value`` assignments applied before validation.
    registry : PluginRegistry, optional
        When given, plugin names and parameters are checked and defaults filled in.

    Returns
    -------
    Scenario
        The validated scenario.

    Raises
    ------
    ScenarioError
        Listing every problem with its key path and line, or its override.
    """
    doc = scenario_document(path)
    for assignment in overrides:
        doc.apply_override(assignment)
    scenario = validate(doc)
    return resolve_plugins(doc, scenario, registry) if registry is not None else scenario


def validate(doc: ScenarioDocument) -> Scenario:
    """Validate a document against the schema and the rules across sections.

    Raises
    ------
    ScenarioError
        With one problem per invalid value.
    """
    _refuse_campaign(doc)
    model = _scenario_model(doc)
    data, problems = _without_moved_keys(doc, model)
    try:
        scenario = model.model_validate(data)
    except ValidationError as exc:
        problems += schema_problems(doc, exc, model)
    violations = _rule_violations(data, model)
    problems += [doc.problem(path, message) for path, message in violations]
    if problems:
        raise ScenarioError(doc.filename, sorted(problems, key=_document_order))
    return scenario


def _mission_section(model: type[Scenario]) -> type[MissionSettings]:
    """The mission section class a scenario model validates (:func:`scenario_model`)."""
    section = model.model_fields["mission"].annotation
    if not (isinstance(section, type) and issubclass(section, MissionSettings)):
        raise TypeError(f"{model.__name__}.mission is not a mission section: {section!r}")
    return section


def _without_moved_keys(
    doc: ScenarioDocument, model: type[Scenario]
) -> tuple[dict[str, Any], list[Problem]]:
    """The document's data without the keys its mission moved elsewhere
    (``MissionSettings.moved_keys``), and one problem per such key naming its new place."""
    moved = _mission_section(model).moved_keys
    present = ScenarioValues(doc.data, model).given
    found = [(old, new) for old, new in moved.items() if present(*old)]
    if not found:
        return doc.data, []
    data = copy.deepcopy(doc.data)
    problems = []
    for old, new in found:
        *parents, last = old
        section = data
        for key in parents:
            section = section[key]
        del section[last]
        problems.append(doc.problem(old, f"this key has moved: give it as {format_key_path(new)}"))
    return data, problems


def _refuse_campaign(doc: ScenarioDocument) -> None:
    """Answer a campaign file given as a scenario with one error saying what it is.

    A document is taken for a campaign file when it names a base ``scenario`` and has
    none of a scenario's own sections.

    Raises
    ------
    ScenarioError
        If the document is a campaign file.
    """
    if "scenario" not in doc.data:
        return
    from dcsim.campaign.spec import CampaignSpec  # campaigns build on this module

    scenario_only = set(Scenario.model_fields) - set(CampaignSpec.model_fields)
    if scenario_only.isdisjoint(doc.data):
        message = f"this is a campaign file: run it with `dcsim campaign run {doc.filename}`"
        raise ScenarioError(doc.filename, [Problem("", message)])


def _document_order(problem: Problem) -> tuple[bool, int, int]:
    """Sort key of problems: by line and column, those without a line last."""
    return (problem.line is None, problem.line or 0, problem.column or 0)


def resolve_plugins(
    doc: ScenarioDocument, scenario: Scenario, registry: PluginRegistry
) -> Scenario:
    """Check each role's plugin name and parameters; return the scenario with defaults filled.

    Raises
    ------
    ScenarioError
        For unknown or ambiguous plugin names and invalid parameters.
    """
    from dcsim.missions import mission_class, scenario_roles  # missions load the world engine

    problems: list[Problem] = []
    resolved: dict[str, Any] = {}
    robot = scenario.robot.type
    mission = mission_class(scenario.mission.type)
    if robot not in mission.robots:
        message = (
            f"mission type '{mission.type}' does not support robot type '{robot}' "
            f"(it supports: {', '.join(mission.robots)})"
        )
        problems.append(doc.problem(("mission", "type"), message))
    for role, (kind, plans_for) in scenario_roles(scenario).items():
        choice = getattr(scenario, role)
        try:
            cls = registry.get(kind, choice.plugin).cls
            params = cls.Params.parse(choice.plugin, choice.params)
        except PluginParameterError as exc:
            problems += [doc.problem((role, "params", p.path), p.message) for p in exc.problems]
            continue
        except DcsimError as exc:
            problems.append(doc.problem((role, "plugin"), str(exc)))
            continue
        if plans_for not in cls.robots:
            which = "" if plans_for == robot else f", which the {role} plans for"
            problems.append(
                doc.problem(
                    (role, "plugin"),
                    f"{role} plugin '{choice.plugin}' does not support robot type "
                    f"'{plans_for}'{which} (it supports: {', '.join(cls.robots)})",
                )
            )
            continue
        resolved[role] = choice.model_copy(update={"params": params.model_dump(mode="json")})
    sensors, sensor_problems = _resolve_sensors(doc, scenario, registry)
    problems += sensor_problems
    if problems:
        raise ScenarioError(doc.filename, problems)
    return scenario.model_copy(update={**resolved, "sensors": sensors})


def _resolve_sensors(
    doc: ScenarioDocument, scenario: Scenario, registry: PluginRegistry
) -> tuple[SensorsSection, list[Problem]]:
    """Each sensor's model checked (registered, measuring that sensor, valid parameters)
    and written out with every parameter, the profile's choices included."""
    problems: list[Problem] = []
    resolved: dict[str, SensorChoice | None] = {}
    for slot, choice in sensor_choices(scenario.sensors).items():
        resolved[slot] = choice
        if choice is None:
            continue
        try:
            cls = sensor_model_class(registry, slot, choice.model)
            params = cls.Params.parse(choice.model, choice.params)
        except PluginParameterError as exc:
            problems += [
                doc.problem(("sensors", slot, "params", p.path), p.message) for p in exc.problems
            ]
            continue
        except DcsimError as exc:
            problems.append(doc.problem(("sensors", slot, "model"), str(exc)))
            continue
        resolved[slot] = choice.model_copy(update={"params": params.model_dump(mode="json")})
    return scenario.sensors.model_copy(update=resolved), problems


_DUMPER = getattr(yaml, "CSafeDumper", yaml.SafeDumper)
"""libyaml's safe dumper where PyYAML was built with it (the same text, written several
times faster: a field of a thousand objects is 260 kB of YAML), else PyYAML's own."""


def dump_scenario(scenario: Scenario) -> str:
    """The scenario as YAML text, every default written out."""
    data = scenario.model_dump(mode="json")
    return yaml.dump(data, Dumper=_DUMPER, sort_keys=False, allow_unicode=True)


class _Invalid(Exception):
    """A value a rule reads is itself invalid (the schema reports it); the rule is skipped."""


class ScenarioValues:
    """Validated values of single keys of raw scenario data, for the rules across keys
    (the schema's, and a mission's: :attr:`MissionSettings.rules`).

    ``get("world", "physics_step")`` is the key's value validated on its own (its
    default if absent); :class:`_Invalid` is raised when it cannot be known.
    """

    def __init__(self, data: dict[str, Any], model: type[Scenario]) -> None:
        self.data, self.model = data, model

    def __call__(self, *path: str | int) -> Any:
        return _value(self.data, path, self.model)

    def given(self, *path: str | int) -> bool:
        """Whether the raw data has a value at ``path``."""
        node: Any = self.data
        for key in path:
            found = isinstance(node, dict) and key in node
            found = found or (isinstance(node, list) and isinstance(key, int) and key < len(node))
            if not found:
                return False
            node = node[key]
        return True

    def items(self, *path: str) -> range:
        """Indices of the raw list at ``path`` (none if there is no list there)."""
        raw: Any = self.data
        for key in path:
            raw = raw.get(key) if isinstance(raw, dict) else None
        return range(len(raw) if isinstance(raw, list) else 0)


Rule = Callable[..., list[tuple[KeyPath, str]]]
"""A rule across keys: takes :class:`ScenarioValues` (and more), gives (key path, message) pairs."""


def _rule_violations(data: dict[str, Any], model: type[Scenario]) -> list[tuple[KeyPath, str]]:
    """Rules that span fields or sections, as (key path, message) pairs.

    The schema's own rules, then those of the scenario's mission (its section's
    ``rules``). A rule is checked whenever the values it reads are valid, whatever
    other keys of the document are invalid, so that its violations are reported with
    the schema's. A rule reading a key the scenario's mission does not have is skipped.
    """
    get = ScenarioValues(data, model)
    rules = [*_RULES, *_mission_section(model).rules]
    return [found for rule in rules for found in _checked(rule, get)]


def _checked(rule: Rule, *args: Any) -> list[tuple[KeyPath, str]]:
    """The violations of ``rule``; none if a value it reads is invalid."""
    try:
        return rule(*args)
    except _Invalid:
        return []


def _control_period_rule(get: ScenarioValues) -> list[tuple[KeyPath, str]]:
    step, period = get("world", "physics_step"), get("world", "control_period")
    ratio = period / step
    if ratio > MAX_STEPS_PER_CONTROL_PERIOD:
        message = (
            f"{period:g} s is more than {MAX_STEPS_PER_CONTROL_PERIOD:,} physics steps of "
            f"{step:g} s; shorten world.control_period or lengthen world.physics_step"
        )
    elif abs(ratio - round(ratio)) > 1e-9 * ratio or round(ratio) < 1:
        message = f"{period:g} s is not a whole multiple of physics_step ({step:g} s)"
    else:
        return []
    return [(("world", "control_period"), message)]


def _duration_rule(get: ScenarioValues) -> list[tuple[KeyPath, str]]:
    step, duration = get("world", "physics_step"), get("world", "duration")
    if duration / step <= MAX_PHYSICS_STEPS:
        return []
    message = (
        f"{duration:g} s is more than {MAX_PHYSICS_STEPS:,} physics steps of {step:g} s; "
        "shorten world.duration or lengthen world.physics_step"
    )
    return [(("world", "duration"), message)]


def _orbit_rule(get: ScenarioValues) -> list[tuple[KeyPath, str]]:
    """The chief's orbit: one size, a mean motion in range, a perigee above the surface,
    a circular orbit for ``cw``, an orbit model only in the LVLH frame."""
    if get("world", "frame") != "lvlh":
        if get("world", "orbit", "model") == "cw":
            return []
        return [(("world", "orbit", "model"), "an orbit model needs world.frame: lvlh")]
    sizes = (get("world", "orbit", "radius"), get("world", "orbit", "altitude"))
    if None not in sizes:
        message = "give radius or altitude, not both"
        return [(("world", "orbit", "altitude"), message)]
    orbit = OrbitSpec(**{key: get("world", "orbit", key) for key in OrbitSpec.model_fields})
    return [*_mean_motion_rule(orbit), *_perigee_rule(orbit), *_circular_cw_rule(orbit)]


def _mean_motion_rule(orbit: OrbitSpec) -> list[tuple[KeyPath, str]]:
    radius, mu = orbit.semi_major_axis, orbit.mu
    with np.errstate(all="ignore"):  # as mean_motion() computes it, overflow giving inf or 0
        rate = float(np.sqrt(np.float64(mu) / np.float64(radius) ** 3))
    low, high = MEAN_MOTION_RANGE
    if low <= rate <= high:
        return []
    message = (
        f"radius {radius:g} m and mu {mu:g} m^3/s^2 give a mean motion of {rate:.3g} rad/s; "
        f"change them so that it is between {low:g} and {high:g} rad/s"
    )
    return [(("world", "orbit"), message)]


def _perigee_rule(orbit: OrbitSpec) -> list[tuple[KeyPath, str]]:
    perigee = orbit.semi_major_axis * (1.0 - orbit.eccentricity)
    if perigee > orbit.earth_radius:
        return []
    message = (
        f"the perigee ({perigee:,.0f} m from the centre) is not above earth_radius "
        f"({orbit.earth_radius:,.0f} m); raise the orbit or lower its eccentricity"
    )
    if orbit.eccentricity > 0:
        key = "eccentricity"
    else:
        key = "altitude" if orbit.altitude is not None else "radius"
    return [(("world", "orbit", key), message)]


def _circular_cw_rule(orbit: OrbitSpec) -> list[tuple[KeyPath, str]]:
    if orbit.model != "cw" or orbit.eccentricity == 0.0:
        return []
    message = (
        "Clohessy-Wiltshire relative motion needs a circular orbit; set "
        "world.orbit.model to two-body or j2 for an eccentric one"
    )
    return [(("world", "orbit", "eccentricity"), message)]


def _propellant_rule(get: ScenarioValues) -> list[tuple[KeyPath, str]]:
    propellant, mass = get("robot", "propellant_mass"), get("robot", "mass")
    if propellant < mass:
        return []
    message = f"{propellant:g} kg must be less than robot.mass ({mass:g} kg)"
    return [(("robot", "propellant_mass"), message)]


def _actuator_limit_rule(get: ScenarioValues) -> list[tuple[KeyPath, str]]:
    """With thrusters or reaction wheels, a ``robot.max_force`` or ``robot.max_torque``
    given must be within what they give along every body axis."""
    actuators = get("robot", "actuators")
    if not isinstance(actuators, ActuatorsSpec):
        return []
    found: list[tuple[KeyPath, str]] = []
    for key, limit, unit, what in (
        ("max_force", actuators.force_limit(), "N", "thrusters' force"),
        ("max_torque", actuators.torque_limit(), "N*m", f"{_torquers(actuators)} torque"),
    ):
        if limit is None or not get.given("robot", key):
            continue
        given = get("robot", key)
        if given <= limit * (1.0 + 1e-9):
            continue
        message = (
            f"{given:g} {unit} exceeds the {what} along the weakest body axis "
            f"({limit:.6g} {unit}); leave {key} out to use it"
        )
        found.append((("robot", key), message))
    return found


def _torquers(actuators: ActuatorsSpec) -> str:
    """Who gives the torque: the reaction wheels, or else the thrusters."""
    return "reaction wheels'" if actuators.reaction_wheels is not None else "thrusters'"


def _joint_count_rule(get: ScenarioValues) -> list[tuple[KeyPath, str]]:
    """A manipulator's initial joint angles and rates: one per link."""
    if get("robot", "type") != "manipulator":
        return []
    robot = get.data.get("robot")
    links = robot.get("links") if isinstance(robot, dict) else None
    if not isinstance(links, list):  # the schema reports it
        return []
    found: list[tuple[KeyPath, str]] = []
    for key in ("joint_angles_deg", "joint_rates_deg_s"):
        values = get("robot", "initial", key)
        if values is not None and len(values) != len(links):
            message = f"{len(values)} values for {len(links)} links: give one per link"
            found.append((("robot", "initial", key), message))
    return found


def _attitude_rule(get: ScenarioValues) -> list[tuple[KeyPath, str]]:
    if sum(q * q for q in get("robot", "initial", "attitude")) >= 1e-12:
        return []
    return [(("robot", "initial", "attitude"), "the quaternion must not be zero")]


def _object_rules(get: ScenarioValues) -> list[tuple[KeyPath, str]]:
    """Ids unique across the mission's targets, its tumbling body and the obstacles;
    their motions and shapes."""
    found: list[tuple[KeyPath, str]] = []
    owners: dict[int, str] = {}
    mission = _mission_section(get.model)
    if mission.body_key is not None and get.given("mission", mission.body_key):
        found += _checked(_unique_id_rule, get, ("mission", mission.body_key), owners)
    targets = [] if mission.targets_key is None else [("mission", mission.targets_key)]
    for section in (*targets, ("obstacles",)):
        for index in get.items(*section):
            item = (*section, index)
            found += _checked(_unique_id_rule, get, item, owners)
            found += _checked(cw_motion_rule, get, (*item, "motion", "type"))
            found += _checked(_shape_radius_rule, get, item)
    return found


def _unique_id_rule(
    get: ScenarioValues, item: KeyPath, owners: dict[int, str]
) -> list[tuple[KeyPath, str]]:
    obj_id = get(*item, "id")
    if obj_id in owners:
        return [((*item, "id"), f"id {obj_id} is already used by {owners[obj_id]}")]
    owners[obj_id] = format_key_path(item)
    return []


def _shape_radius_rule(get: ScenarioValues, item: KeyPath) -> list[tuple[KeyPath, str]]:
    """A radius given beside a shape must be the shape's bounding radius."""
    if not get.given(*item, "radius") or get(*item, "shape") is None:
        return []
    radius, bounding = get(*item, "radius"), get(*item, "shape").build().bounding_radius
    if math.isclose(radius, bounding, rel_tol=1e-9):
        return []
    message = (
        f"{radius:g} m disagrees with the shape's bounding radius ({bounding:g} m); "
        "leave radius out when giving a shape"
    )
    return [((*item, "radius"), message)]


def cw_motion_rule(get: ScenarioValues, path: KeyPath) -> list[tuple[KeyPath, str]]:
    """A ``cw`` motion type at ``path`` needs the LVLH frame."""
    if get(*path) == "cw" and get("world", "frame") != "lvlh":
        return [(path, "'cw' motion needs world.frame: lvlh")]
    return []


_RULES: list[Rule] = [
    _control_period_rule,
    _duration_rule,
    _orbit_rule,
    _propellant_rule,
    _actuator_limit_rule,
    _joint_count_rule,
    _attitude_rule,
    _object_rules,
]
"""Every rule across keys, in the order their messages are listed."""


def _value(data: dict[str, Any], path: KeyPath, root: type[BaseModel]) -> Any:
    """The validated value at ``path`` of raw scenario data under model ``root``, its
    default if absent.

    Each key is validated on its own, so one invalid key does not hide the others.

    Raises
    ------
    _Invalid
        If the value, or a section or list on the way to it, is invalid.
    """
    model, section = _owner(data, path, root)
    return _field_value(model, str(path[-1]), section)


def key_unit(data: Mapping[str, Any], path: KeyPath) -> str:
    """The unit of the scenario key at ``path`` (``m`` for ``robot.initial.position``).

    Parameters
    ----------
    data : mapping
        The raw scenario data, which selects the mission's settings and the sections'
        types.
    path : tuple of str and int
        The key path, without an index into the key's own value.

    Returns
    -------
    str
        The unit the schema gives the key; empty when it has none or there is no such key.
    """
    doc = ScenarioDocument(MAPPING_NAME, dict(data))
    try:
        model, _ = _owner(doc.data, path, _scenario_model(doc))
    except (_Invalid, ScenarioError):
        return ""
    return field_unit(model, str(path[-1]))


def _owner(
    data: dict[str, Any], path: KeyPath, root: type[BaseModel]
) -> tuple[type[BaseModel], dict[str, Any]]:
    """The model owning the last key of ``path`` and the raw section holding it.

    Raises
    ------
    _Invalid
        If there is no such key, or a section or list on the way to it is invalid.
    """
    node: Any = data
    model: type[BaseModel] | None = root
    annotation: Any = None
    for position, key in enumerate(path):
        if isinstance(key, int):
            if not isinstance(node, list) or key >= len(node):
                raise _Invalid
            node = node[key]
            model = _pick_model(annotation, node)
            continue
        if model is None or key not in model.model_fields or not isinstance(node, dict):
            raise _Invalid
        if position == len(path) - 1:
            return model, node
        annotation = model.model_fields[key].annotation
        node = node.get(key, {})
        model = _pick_model(annotation, node)
    raise _Invalid


def _field_value(model: type[BaseModel], name: str, section: dict[str, Any]) -> Any:
    """Field ``name`` of ``model`` validated on its own from raw ``section`` data."""
    if name not in section:
        return model.model_fields[name].get_default(call_default_factory=True)
    try:
        return _field_adapter(model, name).validate_python(section[name])
    except ValidationError:
        raise _Invalid from None


@cache
def _field_adapter(model: type[BaseModel], name: str) -> TypeAdapter[Any]:
    """A validator of field ``name`` of ``model`` on its own: type, bounds and config."""
    info = model.model_fields[name]
    assert info.annotation is not None  # pydantic gives every field of a model its type
    if isinstance(info.annotation, type) and issubclass(info.annotation, BaseModel):
        return TypeAdapter(info.annotation)  # a section has its own config
    annotation = Annotated[info.annotation, *info.metadata] if info.metadata else info.annotation
    # mypy types an Annotated built at run time as a special form, which pydantic accepts
    return TypeAdapter(annotation, config=model.model_config)  # type: ignore[arg-type]


def _scenario_model(doc: ScenarioDocument) -> type[Scenario]:
    """The scenario model of the document's ``mission.type`` (``debris`` if absent).

    Raises
    ------
    ScenarioError
        If no mission has that type.
    """
    from dcsim.missions import mission_types  # missions load the world engine

    section = doc.data.get("mission") if isinstance(doc.data, dict) else None
    mission_type = section.get("type", "debris") if isinstance(section, dict) else "debris"
    missions = mission_types()
    if not isinstance(mission_type, str) or mission_type not in missions:
        message = f"unknown mission type {short_repr(mission_type)}; known: {', '.join(missions)}"
        if isinstance(mission_type, str):
            message += did_you_mean(mission_type, missions)
        raise ScenarioError(doc.filename, [doc.problem(("mission", "type"), message)])
    return scenario_model(missions[mission_type].Settings)


def schema_problems(
    doc: ScenarioDocument, exc: ValidationError, model: type[BaseModel]
) -> list[Problem]:
    """Turn pydantic errors of ``model`` into problems located at their keys in ``doc``."""
    messages: dict[KeyPath, list[str]] = {}
    for err in exc.errors():
        path, owner, field = _locate(doc.data, err["loc"], model)
        if err["type"] == "robot_type" and isinstance(err["input"], dict):
            tag = err["input"].get("type")  # the robot section's tag names no robot type
            message = f"unknown robot type {short_repr(tag)}; known: {', '.join(ROBOT_TYPES)}"
            if isinstance(tag, str):
                message += did_you_mean(tag, ROBOT_TYPES)
            messages.setdefault((*path, "type"), []).append(message)
            continue
        exact = bool(err["loc"]) and path[-1:] == (err["loc"][-1],)
        if exact:
            message = describe_error(owner, field, err)
        elif err["type"] == "missing" and isinstance(err["loc"][-1], int):
            message = f"{short_repr(err['input'])} has too few items"
        else:
            message = f"{short_repr(err['input'])} is not allowed: {err['msg']}"
        messages.setdefault(path, []).append(message)
    return [doc.problem(path, "; or ".join(dict.fromkeys(msgs))) for path, msgs in messages.items()]


def _locate(
    data: Any, loc: tuple[Any, ...], root: type[BaseModel]
) -> tuple[KeyPath, type[BaseModel] | None, str | None]:
    """Follow a pydantic error location through the data and the schema from ``root``.

    Returns the key path in the document (union tags skipped), the model owning the
    last key and that key's name.
    """
    path: list[str | int] = []
    model: type[BaseModel] | None = root
    owner: type[BaseModel] | None = None
    field: str | None = None
    for position, item in enumerate(loc):
        last = position == len(loc) - 1
        known = model is not None and item in model.model_fields
        if isinstance(data, dict) and isinstance(item, str) and (item in data or (last and known)):
            path.append(item)
            owner, field = model, item
            data = data.get(item)
            annotation = (
                model.model_fields[item].annotation
                if model and item in model.model_fields
                else None
            )
            model = _pick_model(annotation, data)
        elif isinstance(data, list) and isinstance(item, int) and 0 <= item < len(data):
            path.append(item)
            data = data[item]
    return tuple(path), owner, field


def _model_classes(annotation: Any) -> list[type[BaseModel]]:
    """Every model class an annotation can hold (through Optional, list, unions)."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    if get_origin(annotation) is Annotated:
        return _model_classes(get_args(annotation)[0])
    return [cls for arg in get_args(annotation) for cls in _model_classes(arg)]


def _pick_model(annotation: Any, data: Any) -> type[BaseModel] | None:
    """The model class that validates ``data`` under ``annotation``, if one is clear."""
    classes = _model_classes(annotation)
    if len(classes) == 1:
        return classes[0]
    if isinstance(data, dict) and "type" in data:
        for cls in classes:
            tag = cls.model_fields.get("type")
            if tag is not None and data["type"] in get_args(tag.annotation):
                return cls
    if isinstance(data, dict):  # no type: the one class whose type has a default
        tagged = [cls for cls in classes if "type" in cls.model_fields]
        defaults = [cls for cls in tagged if not cls.model_fields["type"].is_required()]
        if len(defaults) == 1 and len(tagged) == len(classes):
            return defaults[0]
    return None
