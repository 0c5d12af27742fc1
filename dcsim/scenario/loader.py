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

from collections.abc import Sequence
from importlib import resources
from pathlib import Path
from typing import Annotated, Any, get_args, get_origin

import yaml
from pydantic import BaseModel, ValidationError

from dcsim.errors import DcsimError, PluginParameterError, Problem, ScenarioError
from dcsim.interfaces import PLUGIN_KINDS
from dcsim.params import describe_error, short_repr
from dcsim.registry import PluginRegistry
from dcsim.scenario.document import KeyPath, ScenarioDocument
from dcsim.scenario.model import CWMotionSpec, Scenario

DEFAULT_SCENARIO = "default.yaml"


def default_scenario_path() -> Path:
    """Path of the default scenario shipped inside the package."""
    return packaged_scenario_path(DEFAULT_SCENARIO)


def packaged_scenario_path(name: str) -> Path:
    """Path of scenario file ``name`` shipped inside the package (``default.yaml``, ...)."""
    return Path(str(resources.files("dcsim") / "scenarios" / name))


def load_scenario(
    path: str | Path | None = None,
    overrides: Sequence[str] = (),
    registry: PluginRegistry | None = None,
) -> Scenario:
    """Load, override, validate and (given a registry) resolve a scenario file.

    Parameters
    ----------
    path : str or Path, optional
        Scenario file; the packaged default scenario if None.
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
    doc = ScenarioDocument.from_file(path if path is not None else default_scenario_path())
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
    try:
        scenario = Scenario.model_validate(doc.data)
    except ValidationError as exc:
        raise ScenarioError(doc.filename, _schema_problems(doc, exc)) from None
    problems = [doc.problem(path, message) for path, message in _rule_violations(scenario)]
    if problems:
        raise ScenarioError(doc.filename, problems)
    return scenario


def resolve_plugins(
    doc: ScenarioDocument, scenario: Scenario, registry: PluginRegistry
) -> Scenario:
    """Check each role's plugin name and parameters; return the scenario with defaults filled.

    Raises
    ------
    ScenarioError
        For unknown or ambiguous plugin names and invalid parameters.
    """
    problems: list[Problem] = []
    resolved: dict[str, Any] = {}
    for role in PLUGIN_KINDS:
        choice = getattr(scenario, role)
        try:
            cls = registry.get(role, choice.plugin).cls
            params = cls.Params.parse(choice.plugin, choice.params)
        except PluginParameterError as exc:
            problems += [doc.problem((role, "params", p.path), p.message) for p in exc.problems]
            continue
        except DcsimError as exc:
            problems.append(doc.problem((role, "plugin"), str(exc)))
            continue
        resolved[role] = choice.model_copy(update={"params": params.model_dump(mode="json")})
    if problems:
        raise ScenarioError(doc.filename, problems)
    return scenario.model_copy(update=resolved)


def dump_scenario(scenario: Scenario) -> str:
    """The scenario as YAML text, every default written out."""
    return yaml.safe_dump(scenario.model_dump(mode="json"), sort_keys=False, allow_unicode=True)


def _rule_violations(scenario: Scenario) -> list[tuple[KeyPath, str]]:
    """Rules that span fields or sections, as (key path, message) pairs."""
    found: list[tuple[KeyPath, str]] = []
    world, robot = scenario.world, scenario.robot
    ratio = world.control_period / world.physics_step
    if abs(ratio - round(ratio)) > 1e-9 * ratio or round(ratio) < 1:
        found.append(
            (
                ("world", "control_period"),
                f"{world.control_period:g} s is not a whole multiple of physics_step "
                f"({world.physics_step:g} s)",
            )
        )
    if robot.propellant_mass >= robot.mass:
        found.append(
            (
                ("robot", "propellant_mass"),
                f"{robot.propellant_mass:g} kg must be less than robot.mass ({robot.mass:g} kg)",
            )
        )
    if scenario.mission.reach > robot.grab_distance:
        found.append(
            (
                ("mission", "reach"),
                f"{scenario.mission.reach:g} m is beyond robot.grab_distance "
                f"({robot.grab_distance:g} m)",
            )
        )
    if sum(q * q for q in robot.initial.attitude) < 1e-12:
        found.append((("robot", "initial", "attitude"), "the quaternion must not be zero"))
    owners: dict[int, str] = {}
    for section in ("targets", "obstacles"):
        for index, obj in enumerate(getattr(scenario, section)):
            here = f"{section}[{index}]"
            if obj.id in owners:
                found.append(
                    ((section, index, "id"), f"id {obj.id} is already used by {owners[obj.id]}")
                )
            owners.setdefault(obj.id, here)
            if isinstance(obj.motion, CWMotionSpec) and world.frame != "lvlh":
                found.append(
                    (
                        (section, index, "motion", "type"),
                        "'cw' motion needs world.frame: lvlh",
                    )
                )
    drop = scenario.drop_point
    if drop.position is not None and drop.motion is not None:
        found.append((("drop_point", "motion"), "give either position or motion, not both"))
    if isinstance(drop.motion, CWMotionSpec) and world.frame != "lvlh":
        found.append((("drop_point", "motion", "type"), "'cw' motion needs world.frame: lvlh"))
    return found


def _schema_problems(doc: ScenarioDocument, exc: ValidationError) -> list[Problem]:
    """Turn pydantic errors into problems located at their keys in the document."""
    messages: dict[KeyPath, list[str]] = {}
    for err in exc.errors():
        path, owner, field = _locate(doc.data, err["loc"])
        exact = bool(err["loc"]) and path[-1:] == (err["loc"][-1],)
        if exact:
            message = describe_error(owner, field, err)
        elif err["type"] == "missing" and isinstance(err["loc"][-1], int):
            message = f"{short_repr(err['input'])} has too few items"
        else:
            message = f"{short_repr(err['input'])} is not allowed: {err['msg']}"
        messages.setdefault(path, []).append(message)
    found = [
        doc.problem(path, "; or ".join(dict.fromkeys(msgs))) for path, msgs in messages.items()
    ]
    return sorted(found, key=lambda p: (p.line is None, p.line or 0, p.column or 0))


def _locate(data: Any, loc: tuple[Any, ...]) -> tuple[KeyPath, type[BaseModel] | None, str | None]:
    """Follow a pydantic error location through the data and the schema.

    Returns the key path in the document (union tags skipped), the model owning the
    last key and that key's name.
    """
    path: list[str | int] = []
    model: type[BaseModel] | None = Scenario
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
    return None
