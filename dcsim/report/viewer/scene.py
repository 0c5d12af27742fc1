"""The scene the viewer page replays: what is drawn, where it is at each frame, what is read out.

:func:`build_scene` turns a run's records into a plain description (lists, numbers and
strings, ready for JSON) that the page's script plays without knowing dcsim:

- ``times``: the frames' times (s), at most ``max_frames`` telemetry rows evenly spread;
- ``static``: plotly traces that do not change (paths, beacons, goal region, bounds);
- ``bodies``: groups of solid meshes (one plotly ``mesh3d`` trace per group) whose
  members move (``positions``), turn (``turns``: quaternions applied to their vertices)
  and hide (``hidden``) frame by frame: the robot's base, the targets, the obstacles,
  the drop point's tolerance sphere; a group's members may be labelled, ``lift`` (m)
  above their centres;
- ``polylines``: lines redrawn at every frame (the base's body axes, the arm's links);
- ``thrusters``: the base's thrusters (body-frame ``positions`` and unit force
  ``directions``), each one's mean ``duty`` cycle over the rows a frame stands for
  (:class:`~dcsim.report.viewer.robot.Thrusters`) and the plume's ``length`` (m: at
  duty 0 and added at duty 1); the page draws a plume from each firing thruster
  against its force, turning with the base; null without thrusters;
- ``trails``: paths drawn up to the current frame;
- ``stages``: lines that change at given times (the debris mission's plans);
- ``readouts``: the key numbers at every frame, formatted; ``events``: the event log
  (:mod:`~dcsim.report.viewer.readouts`);
- ``extent``: boxes the views show; ``playback``: speeds offered;
- ``axes``: the names of the world frame's x, y and z axes (radial, along-track and
  orbit-normal in LVLH).

Units: metres, seconds, world frame.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from dcsim.messages import ObjectKind, Shape, ShapeKind
from dcsim.missions.debris.settings import DebrisMissionSection
from dcsim.report.outlines import wireframe
from dcsim.report.viewer.meshes import Mesh, shape_mesh
from dcsim.report.viewer.objects import Handling, ObjectTrack, Status, object_tracks
from dcsim.report.viewer.readouts import event_log, readouts, subtitle, title
from dcsim.report.viewer.records import RunRecords
from dcsim.report.viewer.robot import RobotPath, Thrusters, arm_polylines, body_axes
from dcsim.scenario.model import ManipulatorSection, frame_axes, point_to_cartesian

MAX_FRAMES = 600
"""Frames a page holds at most (telemetry rows evenly spread over the run)."""

PLAYBACK_SECONDS = 30.0
"""Wall time the default playback speed takes to play the whole run, s."""

# Colours (CSS), matplotlib's defaults as the run's plots use them.
_ROBOT = "#1f77b4"
_TARGET = "#2ca02c"
_OBSTACLE = "#d62728"
_PLAN = "#ff7f0e"
_GOAL = "#2ca02c"
_DROP = "#555555"
_BEACON = "#9467bd"
_PLUME = "#ffa600"
_AXIS_COLOURS = ("#e41a1c", "#4daf4a", "#377eb8")  # body x, y and z axes

_SPEEDS = (0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000)


def frame_rows(count: int, max_frames: int = MAX_FRAMES) -> np.ndarray:
    """At most ``max_frames`` row indices evenly spread over ``count`` rows, first and last kept."""
    frames = min(count, max(max_frames, 2))
    return np.unique(np.round(np.linspace(0, count - 1, frames)).astype(int))


def build_scene(records: RunRecords, max_frames: int = MAX_FRAMES) -> dict[str, Any]:
    """The scene of a run, as plain data (see the module's description).

    Parameters
    ----------
    records : RunRecords
        The run's records.
    max_frames : int
        Frames at most.

    Returns
    -------
    dict
        JSON-ready description of the scene; arrays are numpy arrays until written.
    """
    telemetry = records.telemetry
    path = RobotPath.from_telemetry(telemetry)
    rows = frame_rows(len(path.times), max_frames)
    times = path.times[rows]
    handling = Handling.from_events(records.events)
    tracks = object_tracks(records.scenario, times, path, handling, telemetry)
    arm = arm_polylines(records.scenario, telemetry, path, rows)
    thrusters = Thrusters.of(records.scenario, telemetry, rows)
    context = _Context(records, path, rows, times, tracks, arm, thrusters)
    bodies = [_robot_body(context), *_object_bodies(tracks), *_drop_body(context)]
    stages = _plans(context)
    return {
        "title": title(records.scenario),
        "subtitle": subtitle(records.summary),
        "axes": list(frame_axes(records.scenario.world.frame)),
        "times": times,
        "static": _static_traces(context),
        "bodies": bodies,
        "polylines": _robot_lines(context),
        "thrusters": _thrusters(context),
        "trails": _trails(context),
        "stages": stages,
        "readouts": readouts(records.scenario, telemetry, rows, handling, thrusters),
        "events": event_log(records.events),
        "extent": _extent(context, bodies, stages),
        "playback": _playback(times),
    }


class _Context:
    """What the scene's parts share: the records, the frames and the robot's path."""

    def __init__(
        self,
        records: RunRecords,
        path: RobotPath,
        rows: np.ndarray,
        times: np.ndarray,
        tracks: list[ObjectTrack],
        arm: np.ndarray | None,
        thrusters: Thrusters | None,
    ) -> None:
        self.records = records
        self.scenario = records.scenario
        self.telemetry = records.telemetry
        self.path = path
        self.rows = rows
        self.times = times
        self.tracks = tracks
        self.arm = arm
        self.thrusters = thrusters
        self.mission = self.scenario.mission.type

    def columns(self, names: Sequence[str]) -> np.ndarray | None:
        """Telemetry columns ``names`` side by side at every row, or None if one is absent."""
        if not all(name in self.telemetry for name in names):
            return None
        return np.column_stack([self.telemetry[name] for name in names]).astype(float)

    @property
    def robot_size(self) -> float:
        """A length the robot's glyphs scale with: its bounding radius, m."""
        return float(self.scenario.robot.radius)


# ---------------------------------------------------------------- bodies


def _member(
    label: str,
    mesh: Mesh,
    positions: np.ndarray,
    turns: np.ndarray | None = None,
    hidden: np.ndarray | None = None,
) -> dict[str, Any]:
    return {
        "label": label,
        "lift": float(np.max(np.linalg.norm(mesh.vertices, axis=1))),
        "vertices": mesh.vertices,
        "triangles": mesh.triangles,
        "positions": positions,
        "turns": turns,
        "hidden": None if hidden is None or not hidden.any() else hidden.astype(int),
    }


def _mesh_trace(
    name: str, colour: str, opacity: float = 1.0, group: str = "", flat: bool = True
) -> dict[str, Any]:
    """A plotly mesh trace's style; ``flat`` shading for faces with edges (boxes,
    cylinders), smooth for spheres."""
    return {
        "type": "mesh3d",
        "name": name,
        "color": colour,
        "opacity": opacity,
        "flatshading": flat,
        "lighting": {"ambient": 0.55, "diffuse": 0.7, "specular": 0.15},
        "showlegend": True,
        "legendgroup": group or name,
        "hoverinfo": "name",
    }


def _robot_body(context: _Context) -> dict[str, Any]:
    """The robot's base: a manipulator's box, or a free flyer's sphere, turned by its attitude."""
    robot = context.scenario.robot
    if isinstance(robot, ManipulatorSection):
        shape = Shape(ShapeKind.BOX, half_extents=0.5 * np.asarray(robot.size, dtype=float))
    else:
        shape = Shape(ShapeKind.SPHERE, radius=robot.radius)
    member = _member(
        "robot",
        shape_mesh(shape),
        context.path.positions[context.rows],
        context.path.attitudes[context.rows],
    )
    trace = _mesh_trace("robot", _ROBOT, 0.85, flat=shape.kind is not ShapeKind.SPHERE)
    return {"trace": trace, "labels": False, "members": [member]}


def _object_bodies(tracks: Sequence[ObjectTrack]) -> list[dict[str, Any]]:
    """One group of targets and one of obstacles, each member labelled by its id."""
    groups = []
    for kind, name, colour, prefix in (
        (ObjectKind.TARGET, "targets", _TARGET, "T"),
        (ObjectKind.OBSTACLE, "obstacles", _OBSTACLE, "O"),
    ):
        chosen = [t for t in tracks if t.object.kind is kind]
        if not chosen:
            continue
        members = [
            _member(
                f"{prefix}{t.object.id}",
                shape_mesh(t.object.shape),
                t.positions,
                t.turns,
                t.status == Status.DELIVERED,
            )
            for t in chosen
        ]
        flat = any(t.object.shape.kind is not ShapeKind.SPHERE for t in chosen)
        trace = _mesh_trace(name, colour, flat=flat)
        groups.append({"trace": trace, "labels": True, "members": members})
    return groups


def _drop_body(context: _Context) -> list[dict[str, Any]]:
    """The drop point's tolerance sphere, for missions that deliver (debris)."""
    if context.mission != "debris":
        return []
    drop = context.scenario.mission_as(DebrisMissionSection).drop_point
    positions = drop.build(context.scenario.mean_motion).state_at(context.times)[0]
    mesh = shape_mesh(Shape(ShapeKind.SPHERE, radius=drop.tolerance))
    trace = _mesh_trace("drop point (tolerance)", _DROP, 0.25, flat=False)
    return [{"trace": trace, "labels": True, "members": [_member("drop", mesh, positions)]}]


# ---------------------------------------------------------------- lines


def _line_trace(
    name: str,
    colour: str,
    width: float = 3.0,
    dash: str = "solid",
    mode: str = "lines",
    legend: bool = True,
    group: str = "",
) -> dict[str, Any]:
    trace: dict[str, Any] = {
        "type": "scatter3d",
        "mode": mode,
        "name": name,
        "line": {"color": colour, "width": width, "dash": dash},
        "showlegend": legend,
        "legendgroup": group or name,
        "hoverinfo": "name",
    }
    if "markers" in mode:
        trace["marker"] = {"color": colour, "size": 3}
    return trace


def _robot_lines(context: _Context) -> list[dict[str, Any]]:
    """The base's body axes, a marker at the robot, and a manipulator's links."""
    length = 2.0 * context.robot_size
    if isinstance(context.scenario.robot, ManipulatorSection):
        length = float(max(context.scenario.robot.size))
    axes = body_axes(context.path, context.rows, length)
    lines = [
        {
            "trace": _line_trace(f"body {name} axis", colour, 5, group="robot axes"),
            "frames": segment,
        }
        for name, colour, segment in zip("xyz", _AXIS_COLOURS, axes, strict=True)
    ]
    marker = _line_trace("robot centre", _ROBOT, mode="markers", legend=False, group="robot")
    marker["marker"] = {"color": _ROBOT, "size": 5, "symbol": "circle"}
    lines.append({"trace": marker, "frames": context.path.positions[context.rows][:, None]})
    if context.arm is not None:
        arm = _line_trace("arm links", "#444444", 9, mode="lines+markers")
        arm["marker"] = {"color": "#222222", "size": 4}
        lines.append({"trace": arm, "frames": context.arm})
    return lines


def _thrusters(context: _Context) -> dict[str, Any] | None:
    """The thrusters' geometry and duty cycles, and how the page draws their plumes: from
    a firing thruster against its force, one robot radius long plus two at full duty (a
    thruster inside the robot's sphere still shows)."""
    thrusters = context.thrusters
    if thrusters is None:
        return None
    size = context.robot_size
    return {
        "trace": _line_trace("thruster plumes", _PLUME, 8, group="robot"),
        "positions": thrusters.positions,
        "directions": thrusters.directions,
        "duty": thrusters.duty,
        "length": [size, 2.0 * size],
    }


def _trails(context: _Context) -> list[dict[str, Any]]:
    """The robot's path (and a manipulator's end effector's) up to the current frame."""
    trails = [
        {
            "trace": _line_trace("robot path", _ROBOT, 4, group="robot"),
            "points": context.path.positions[context.rows],
        }
    ]
    end_effector = context.columns(("ee_x", "ee_y", "ee_z"))
    if end_effector is not None:
        trails.append(
            {
                "trace": _line_trace("end-effector path", "#8c564b", 5),
                "points": end_effector[context.rows],
            }
        )
    return trails


def _static_traces(context: _Context) -> list[dict[str, Any]]:
    """Everything that does not move: the whole flown path, the reference, the plan,
    beacons, the goal region and bounds, a reach target."""
    traces = [
        _polyline(
            _line_trace("flown path (whole run)", _ROBOT, 1.5, legend=True),
            context.path.positions[context.rows],
        )
        | {"opacity": 0.35}
    ]
    traces += _references(context)
    traces += _beacons(context)
    traces += _goal(context)
    traces += _bounds(context)
    return traces


def _polyline(trace: dict[str, Any], points: np.ndarray) -> dict[str, Any]:
    return trace | {"x": points[:, 0], "y": points[:, 1], "z": points[:, 2]}


def _references(context: _Context) -> list[dict[str, Any]]:
    """The reference the controller tracked and the last planned trajectory."""
    traces = []
    for columns, name in (
        (("ref_x", "ref_y", "ref_z"), "reference"),
        (("ref_ee_x", "ref_ee_y", "ref_ee_z"), "planned end-effector path"),
    ):
        reference = context.columns(columns)
        if reference is not None:
            trace = _line_trace(name, "#222222", 2, dash="dash")
            traces.append(_polyline(trace, reference[context.rows]))
    planned = context.records.planned
    if len(planned):
        traces.append(_polyline(_line_trace("planned trajectory", _PLAN, 4), planned))
    return traces


def _beacons(context: _Context) -> list[dict[str, Any]]:
    positions = [point_to_cartesian(p) for p in context.scenario.beacons.positions]
    if not positions:
        return []
    points = np.array(positions, dtype=float)
    trace = _line_trace("beacons", _BEACON, mode="markers+text")
    trace["marker"] = {"color": _BEACON, "size": 6, "symbol": "diamond"}
    trace["text"] = [f"B{i}" for i in range(1, len(points) + 1)]
    trace["textposition"] = "top center"
    return [_polyline(trace, points)]


def _bounds(context: _Context) -> list[dict[str, Any]]:
    """The box a transfer's path must stay in, as a dotted wireframe (none without one)."""
    bounds = getattr(context.scenario.mission, "bounds", None)
    if bounds is None:
        return []
    lower, upper = np.asarray(bounds.lower), np.asarray(bounds.upper)
    box = Shape(ShapeKind.BOX, half_extents=0.5 * (upper - lower))
    return [_wireframe_trace(box, 0.5 * (lower + upper), "bounds", "#7f7f7f")]


def _goal(context: _Context) -> list[dict[str, Any]]:
    """A transfer's goal region; a reach's target."""
    settings = context.scenario.mission
    traces = []
    goal = getattr(settings, "goal", None)
    if goal is not None:
        if goal.half_extents is not None:
            shape = Shape(ShapeKind.BOX, half_extents=goal.half_extents)
        else:
            shape = Shape(ShapeKind.SPHERE, radius=goal.radius)
        traces.append(_placed_mesh(shape, np.asarray(goal.position), "goal region", _GOAL, 0.25))
    target = getattr(settings, "target", None)
    if isinstance(target, tuple | list) and len(target) == 3:  # a point (a capture's is a body)
        trace = _line_trace("reach target", _GOAL, mode="markers")
        trace["marker"] = {"color": _GOAL, "size": 12, "symbol": "cross"}
        traces.append(_polyline(trace, np.asarray(target, dtype=float)[None]))
    return traces


def _placed_mesh(
    shape: Shape, centre: np.ndarray, name: str, colour: str, opacity: float
) -> dict[str, Any]:
    mesh = shape_mesh(shape)
    vertices = mesh.vertices + centre
    return _mesh_trace(name, colour, opacity, flat=shape.kind is not ShapeKind.SPHERE) | {
        "x": vertices[:, 0],
        "y": vertices[:, 1],
        "z": vertices[:, 2],
        "i": mesh.triangles[:, 0],
        "j": mesh.triangles[:, 1],
        "k": mesh.triangles[:, 2],
    }


def _wireframe_trace(shape: Shape, centre: np.ndarray, name: str, colour: str) -> dict[str, Any]:
    """``shape``'s 3-D wireframe about ``centre`` as one line trace (gaps between polylines)."""
    gap = np.full((1, 3), np.nan)
    points = np.vstack([np.vstack([line + centre, gap]) for line in wireframe(shape)])
    return _polyline(_line_trace(name, colour, 1.5, dash="dot"), points)


def _plans(context: _Context) -> list[dict[str, Any]]:
    """The debris mission's plans: from the robot where it planned, through every pickup
    (where the target will be then) and drop visit, each shown from its time on."""
    plans = [e for e in context.records.events if e["event"] == "plan"]
    if not plans:
        return []
    motions = {t.object.id: t.object.motion for t in context.tracks}
    drop = context.scenario.mission_as(DebrisMissionSection).drop_point.build(
        context.scenario.mean_motion
    )
    stages = []
    for plan in plans:
        start = context.path.positions[context.path.row_at(np.array([plan["t"]]))[0]]
        points = [start]
        for kind, key, time in _plan_steps(plan):
            if kind == "drop":
                points.append(drop.position_at(time))
            elif key in motions:
                points.append(motions[key].position_at(time))
        stages.append({"t": float(plan["t"]), "points": np.array(points, dtype=float)})
    trace = _line_trace("plan", _PLAN, 3, dash="dash", mode="lines+markers")
    trace["marker"] = {"color": _PLAN, "size": 4}
    return [{"trace": trace, "stages": stages}]


def _plan_steps(plan: Mapping[str, Any]) -> list[tuple[str, int, float]]:
    """A ``plan`` event's pickups and drop visits in the order they are flown:
    ``(kind, target id or task index, time)``."""
    drops = {int(after): float(time) for after, time in plan.get("drops") or ()}
    steps = [("drop", -1, drops[-1])] if -1 in drops else []
    for index, (target, time) in enumerate(plan.get("tasks") or ()):
        steps.append(("pickup", int(target), float(time)))
        if index in drops:
            steps.append(("drop", index, drops[index]))
    return steps


# ---------------------------------------------------------------- views


def _extent(
    context: _Context, bodies: Sequence[Mapping[str, Any]], stages: Sequence[Mapping[str, Any]]
) -> dict[str, Any]:
    """The boxes the views show: the work area (robot, objects, drop point, plans, goal),
    the whole scene (beacons and bounds too), and the half width of the close-up, m."""
    points = [context.path.positions[context.rows], context.records.planned]
    for group in bodies:
        for member in group["members"]:
            points += [member["positions"] - member["lift"], member["positions"] + member["lift"]]
    if context.arm is not None:
        points.append(context.arm.reshape(-1, 3))
    points += [stage["points"] for staged in stages for stage in staged["stages"]]
    points += [_trace_points(trace) for trace in _goal(context)]
    work = _box(points)
    whole = [work, *(_trace_points(t) for t in [*_beacons(context), *_bounds(context)])]
    return {
        "work": work,
        "scene": _box(whole),
        "closeup": max(3.0 * context.robot_size, 2.0),
    }


def _trace_points(trace: Mapping[str, Any]) -> np.ndarray:
    return np.column_stack([trace["x"], trace["y"], trace["z"]])


def _box(points: Sequence[np.ndarray]) -> np.ndarray:
    """Lowest and highest corner (2, 3) of ``points``, padded by 5 % and at least 1 m."""
    stacked = np.vstack([np.asarray(p, dtype=float).reshape(-1, 3) for p in points])
    stacked = stacked[np.all(np.isfinite(stacked), axis=1)]
    lower, upper = stacked.min(axis=0), stacked.max(axis=0)
    pad = max(0.05 * float(np.max(upper - lower)), 1.0)
    return np.array([lower - pad, upper + pad])


def _playback(times: np.ndarray) -> dict[str, Any]:
    """Playback speeds (simulated seconds per wall second): the default plays the run in
    about :data:`PLAYBACK_SECONDS`."""
    duration = max(float(times[-1] - times[0]), 1e-3)
    wanted = duration / PLAYBACK_SECONDS
    default = min(_SPEEDS, key=lambda s: abs(np.log(s / wanted)))
    speeds = [s for s in _SPEEDS if default / 20 <= s <= default * 20]
    return {"speeds": speeds, "speed": default}
