"""Generate the key reference of docs/scenarios.md from the scenario schema.

The reference lives between two marker lines in docs/scenarios.md; a test fails when it
differs from what the schema generates. Regenerate it with ``make docs``, which runs::

    python -m dcsim.scenario.reference docs/scenarios.md
"""

from __future__ import annotations

import sys
import types
from pathlib import Path
from typing import Annotated, Any, Literal, Union, get_args, get_origin

from pydantic import BaseModel
from pydantic_core import PydanticUndefined

from dcsim.params import field_bounds, field_unit
from dcsim.report.docgen import update_block
from dcsim.scenario.model import (
    MissionSettings,
    MotionSpec,
    PluginChoice,
    SphericalPoint,
    Vec3,
    scenario_model,
)

BEGIN = "<!-- BEGIN GENERATED KEY REFERENCE (make docs) -->"
END = "<!-- END GENERATED KEY REFERENCE -->"


def _type_name(annotation: Any) -> str:
    if annotation is MotionSpec:
        return "motion"
    if annotation == Vec3:
        return "[x, y, z]"
    if annotation == Vec3 | SphericalPoint:
        return "point"
    origin = get_origin(annotation)
    if origin is Annotated:
        return _type_name(get_args(annotation)[0])
    if origin is Literal:
        return " \\| ".join(f"`{a}`" for a in get_args(annotation))
    if origin in (Union, types.UnionType):
        args = [a for a in get_args(annotation) if a is not type(None)]
        inner = " or ".join(_type_name(a) for a in args)
        return inner + (" or null" if len(args) < len(get_args(annotation)) else "")
    if origin is list:
        return f"list of {_type_name(get_args(annotation)[0])}"
    if origin is dict:
        return "mapping"
    if origin is tuple:
        return f"[{', '.join('number' for _ in get_args(annotation))}]"
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return "section"
    return {float: "number", int: "integer", bool: "boolean", str: "string"}.get(
        annotation, str(annotation)
    )


def _default(model: type[BaseModel], name: str) -> str:
    info = model.model_fields[name]
    if isinstance(info.default, PluginChoice):  # a mission's choice of a role's plugin
        return f"`plugin: {info.default.plugin}`"
    if info.default_factory is not None:
        value = info.default_factory()  # type: ignore[call-arg]
        if isinstance(value, PluginChoice):
            return f"`plugin: {value.plugin}`"
        return "see below" if isinstance(value, BaseModel) else f"`{value}`"
    if info.default is PydanticUndefined:
        return "required"
    if info.default is None:
        return "`null`"
    return f"`{list(info.default) if isinstance(info.default, tuple) else info.default}`"


def _nested(annotation: Any) -> list[type[BaseModel]]:
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    return [cls for arg in get_args(annotation) for cls in _nested(arg)]


def _child_path(prefix: str, name: str, annotation: Any) -> str:
    path = f"{prefix}.{name}" if prefix else name
    return path + "[i]" if get_origin(annotation) is list else path


def _builtin_missions() -> list[type[MissionSettings]]:
    """The sections of dcsim's own missions, the default's (``debris``) first."""
    from dcsim.missions import mission_types  # the missions load the world engine

    sections = {
        name: cls.Settings
        for name, cls in mission_types().items()
        if cls.__module__.startswith("dcsim.")
    }
    return [sections.pop("debris"), *sections.values()]


def _sections() -> dict[type[BaseModel], list[str]]:
    """Every model class reachable from the default scenario and the other built-in
    missions' sections, with the key paths it appears at (a plugin role at its key)."""
    default, *missions = _builtin_missions()
    root = scenario_model(default)
    paths: dict[type[BaseModel], list[str]] = {root: [""]}
    paths.update({section: ["mission"] for section in missions})
    queue: list[tuple[str, type[BaseModel]]] = [("", root)]
    queue += [("mission", section) for section in missions]
    while queue:
        prefix, model = queue.pop(0)
        for name, info in model.model_fields.items():
            child = _child_path(prefix, name, info.annotation)
            for cls in _nested(info.annotation):
                if cls is SphericalPoint:
                    continue
                if cls not in paths:
                    paths[cls] = []
                    queue.append((child, cls))
                if child not in paths[cls]:  # two robot types' sections share a path
                    paths[cls].append(child)
    for section in missions:  # the roles only another mission names (capture's approach)
        paths[PluginChoice] += [r for r in section.role_defaults if r not in paths[PluginChoice]]
    return paths


def _heading(model: type[BaseModel], paths: list[str]) -> str:
    tag = model.model_fields.get("type")
    where = ", ".join(f"`{p}`" for p in paths) if paths != [""] else "top level"
    if tag is not None:
        key = paths[0].rsplit(".", 1)[-1].removesuffix("[i]")
        return f"{key} `type: {get_args(tag.annotation)[0]}` (in {where})"
    return where


def render_reference() -> str:
    """The generated key reference, as Markdown."""
    blocks: list[str] = []
    for model, paths in _sections().items():
        rows = ["| key | type | unit | default | bounds | meaning |", "|---|---|---|---|---|---|"]
        for name, info in model.model_fields.items():
            bounds = field_bounds(model, name).replace(">", "&gt;").replace("<", "&lt;")
            rows.append(
                f"| `{name}` | {_type_name(info.annotation)} | {field_unit(model, name)} | "
                f"{_default(model, name)} | {bounds} | {info.description or ''} |"
            )
        doc = (model.__doc__ or "").strip().splitlines()[0]
        blocks.append(f"### {_heading(model, paths)}\n\n{doc}\n\n" + "\n".join(rows))
    return "\n\n".join(blocks) + "\n"


if __name__ == "__main__":
    target = Path(sys.argv[1] if len(sys.argv) > 1 else "docs/scenarios.md")
    changed = update_block(target, BEGIN, END, render_reference())
    print(f"{target}: {'updated' if changed else 'already up to date'}")
