"""Typed parameter models: fields with units, bounds and descriptions.

Plugin parameters and scenario sections are pydantic models built from
:func:`quantity` fields. Each field carries its unit, default, bounds and a one-line
description, which the documentation generator and the error messages read from the
same place. Numbers must be finite: NaN and ±infinity are rejected unless a field is
declared with ``allow_inf_nan=True`` and its description says "inf allowed".

Examples
--------
>>> class Params(PluginParams):
...     bandwidth: float = quantity(
...         0.5, unit="rad/s", gt=0, description="Closed-loop natural frequency."
...     )
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import UnionType
from typing import Any, ClassVar, Literal, Union, get_args, get_origin

from pydantic import BaseModel, ConfigDict, Field, ValidationError
from pydantic.json_schema import JsonDict
from pydantic_core import ErrorDetails, to_jsonable_python

from dcsim.errors import PluginParameterError, Problem, did_you_mean

_BOUND_SYMBOLS = {"gt": ">", "ge": ">=", "lt": "<", "le": "<="}


def quantity(
    default: Any = ...,
    *,
    unit: str = "",
    description: str,
    gt: float | None = None,
    ge: float | None = None,
    lt: float | None = None,
    le: float | None = None,
    **kwargs: Any,
) -> Any:
    """Declare a model field with a unit, bounds and a description.

    Parameters
    ----------
    default : Any
        Default value; omit (or pass ``...``) for a required field.
    unit : str
        SI unit of the value (``"m"``, ``"N"``, ``"deg/s"``); empty for dimensionless.
    description : str
        One sentence saying what the value means.
    gt, ge, lt, le : float, optional
        Exclusive and inclusive bounds.
    **kwargs
        Passed on to :func:`pydantic.Field` (e.g. ``default_factory``, or
        ``allow_inf_nan=True`` for a number that may be infinite, whose description
        then says "inf allowed").

    Returns
    -------
    pydantic.fields.FieldInfo
        The field declaration.
    """
    extra: JsonDict = {"unit": unit} if unit else {}
    if "default_factory" in kwargs:
        return Field(
            description=description, gt=gt, ge=ge, lt=lt, le=le, json_schema_extra=extra, **kwargs
        )
    return Field(
        default,
        description=description,
        gt=gt,
        ge=ge,
        lt=lt,
        le=le,
        json_schema_extra=extra,
        **kwargs,
    )


def field_unit(model: type[BaseModel], name: str) -> str:
    """Return the unit declared for field ``name`` of ``model`` (empty if none)."""
    extra = model.model_fields[name].json_schema_extra
    return str(extra.get("unit", "")) if isinstance(extra, dict) else ""


def field_bounds(model: type[BaseModel], name: str) -> str:
    """Return a field's bounds as text, e.g. ``"> 0, <= 10"`` (empty if unbounded)."""
    parts = []
    for meta in model.model_fields[name].metadata:
        for attr, symbol in _BOUND_SYMBOLS.items():
            value = getattr(meta, attr, None)
            if value is not None:
                parts.append(f"{symbol} {value if isinstance(value, int) else f'{value:g}'}")
    return ", ".join(parts)


def field_choices(model: type[BaseModel], name: str) -> tuple[Any, ...]:
    """The values a field of ``Literal`` type allows (``None`` too when it is optional);
    empty for any other field."""
    annotation = model.model_fields[name].annotation
    options = get_args(annotation) if get_origin(annotation) in (Union, UnionType) else ()
    literals = [a for a in (annotation, *options) if get_origin(a) is Literal]
    if not literals:
        return ()
    return (*get_args(literals[0]), *((None,) if type(None) in options else ()))


@dataclass(frozen=True)
class ParameterInfo:
    """What one field of a parameter model declares (``dcsim plugins NAME`` prints it).

    Attributes
    ----------
    name : str
        The field's name.
    default : Any
        Its default value, JSON-compatible (None also when there is none).
    required : bool
        Whether a value must be given (there is no default).
    unit : str
        Its SI unit, empty for a dimensionless value.
    bounds : str
        Its bounds (``"> 0, <= 5"``), or the values it allows (``"one of: fix, prior"``);
        empty when any value of its type goes.
    description : str
        One sentence saying what it means.
    """

    name: str
    default: Any
    required: bool
    unit: str
    bounds: str
    description: str


def parameter_infos(model: type[BaseModel]) -> list[ParameterInfo]:
    """What each field of ``model`` declares, in the model's order."""
    infos = []
    for name, info in model.model_fields.items():
        choices = field_choices(model, name)
        listed = ", ".join("null" if c is None else str(c) for c in choices)
        default = None if info.is_required() else info.get_default(call_default_factory=True)
        infos.append(
            ParameterInfo(
                name=name,
                default=to_jsonable_python(default),
                required=info.is_required(),
                unit=field_unit(model, name),
                bounds=f"one of: {listed}" if choices else field_bounds(model, name),
                description=info.description or "",
            )
        )
    return infos


class PluginParams(BaseModel):
    """Base class of every plugin's parameter model.

    Subclasses declare their fields with :func:`quantity`. Instances are immutable,
    unknown parameter names are rejected, numbers must be finite, and types are checked
    strictly enough that a string is never silently taken for a number.

    Attributes
    ----------
    retired : mapping of str to str
        Names that were parameters once, each with what to set instead: giving one is
        rejected with that advice rather than as an unknown key.
    """

    model_config = ConfigDict(
        extra="forbid", frozen=True, validate_default=True, allow_inf_nan=False
    )
    retired: ClassVar[Mapping[str, str]] = {}

    @classmethod
    def parse(cls, plugin: str, values: Mapping[str, Any] | None) -> PluginParams:
        """Validate raw parameter values for plugin ``plugin``.

        Parameters
        ----------
        plugin : str
            The plugin's name, used in error messages.
        values : mapping or None
            Raw values, e.g. the ``params:`` section of a scenario; None means defaults.

        Returns
        -------
        PluginParams
            The validated parameters, defaults filled in.

        Raises
        ------
        PluginParameterError
            Naming each bad parameter, its value and the allowed range.
        """
        try:
            return cls.model_validate(dict(values or {}))
        except ValidationError as exc:
            problems = [
                Problem(
                    path=".".join(str(p) for p in err["loc"]),
                    message=describe_error(cls, str(err["loc"][0]) if err["loc"] else None, err),
                )
                for err in exc.errors()
            ]
            raise PluginParameterError(plugin, problems) from None


def describe_error(model: type[BaseModel] | None, field: str | None, error: ErrorDetails) -> str:
    """Turn one pydantic error into a message naming the value and what is allowed.

    Parameters
    ----------
    model : type of BaseModel or None
        The model owning the failing field, if known; its keys, bounds and unit are quoted.
    field : str or None
        Name of the failing field of ``model``.
    error : dict
        One entry of :meth:`pydantic.ValidationError.errors`.

    Returns
    -------
    str
        E.g. ``"-1.0 is not allowed: Input should be greater than 0 (allowed: > 0 rad/s)"``.
    """
    if error["type"] == "missing":
        return "required but missing"
    if error["type"] == "extra_forbidden":
        if model is None:
            return "unknown key"
        advice = getattr(model, "retired", {}).get(str(field))
        if advice is not None:
            return f"no longer a parameter: {advice}"
        known = ", ".join(model.model_fields)
        return f"unknown key (known keys: {known})" + did_you_mean(str(field), model.model_fields)
    message = f"{short_repr(error['input'])} is not allowed: {error['msg']}"
    if model is not None and field in model.model_fields:
        bounds, unit = field_bounds(model, field), field_unit(model, field)
        if bounds:
            message += f" (allowed: {bounds}{' ' + unit if unit else ''})"
    return message


def short_repr(value: Any, limit: int = 80) -> str:
    """``repr(value)``, cut to about ``limit`` characters for error messages.

    Examples
    --------
    >>> short_repr(list(range(100)), 20)
    '[0, 1, 2, 3, 4, 5, …'
    """
    try:
        text = repr(value)
    except ValueError:  # an integer too long to print
        return f"an integer of {value.bit_length()} bits"
    return text if len(text) <= limit else text[: limit - 1] + "…"
