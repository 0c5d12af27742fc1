"""The problem set of ``dcsim bench path-planners``: seeded random fields and transfer scenarios.

Every problem is a transfer scenario, so that it can also be flown: a random family
writes one from its seed, a scenario file is one. The path problem is the one the
transfer mission poses at t = 0 (:func:`dcsim.missions.transfer.mission.transfer_problem`), from
the robot's true initial state, with the obstacles in sensor range.

Families (the robot: the scenario default, 1 m radius, 1 m/s, 0.05 m/s² usable
acceleration; a 1.5 m goal 60 m away, planning budget 1 s, a safety margin of 0.5 m for
every planner):

- ``static-spheres``: 20 spheres of 1–3 m radius at rest in a force-free frame;
- ``cw-spheres``: 20 spheres of 1–2.5 m radius drifting in Clohessy–Wiltshire motion
  about a 400 km orbit (σ = 0.02 m/s per axis), the transfer along-track;
- ``shapes``: 16 boxes and cylinders of random size and orientation, at rest.

and the escape experiment of the kinodynamic RRT course project:

- ``asteroid-escape``: ``scenarios/asteroid_escape.yaml`` (a 1 kg ship, 0.5 N thrust,
  up 19 m above a 40 m force field and out through its bottom) with 40 asteroids drawn
  from the seed (:mod:`dcsim.bench.asteroids`) and a 10 s planning budget.

Obstacles start in a slab 10–50 m along the way, ±15 m across, none within 2 m of the
start or of the goal region.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from dcsim.bench.asteroids import escape_scenario
from dcsim.errors import DcsimError
from dcsim.messages import PathProblem, RobotState
from dcsim.missions.transfer.mission import transfer_problem
from dcsim.run.seeding import component_rng
from dcsim.scenario import Scenario, ScenarioDocument, validate
from dcsim.world import World

LENGTH = 60.0
"""Distance from the start to the goal, m."""
SLAB = (10.0, 50.0)
"""Where obstacles start along the way, m."""
HALF_WIDTH = 15.0
"""Half-width of the obstacle slab across the way, m."""
KEEP_OUT = 2.0
"""Least gap between an obstacle's bounding sphere and the start or the goal region, m."""
GOAL_RADIUS = 1.5
"""Radius of the goal region, m."""
FAMILY_MARGIN = 0.5
"""Safety margin of the random families' problems, m (``mission.safety_distance``)."""
ROBOT_RADIUS = 1.0
"""The robot's radius (the scenario default), m."""
ORBIT_RADIUS = 6_778_137.0
"""Reference orbit of ``cw-spheres`` (400 km altitude), m."""
FIRST_ID = 100
"""Id of a family's first obstacle."""


@dataclass(frozen=True)
class BenchProblem:
    """One problem of the set.

    Attributes
    ----------
    name : str
        ``FAMILY-SEED`` or the scenario file's stem; the experiment's name in the log.
    document : ScenarioDocument
        The transfer scenario it comes from (flown by ``--fly``).
    problem : PathProblem
        The path problem the transfer mission poses at t = 0.
    """

    name: str
    document: ScenarioDocument
    problem: PathProblem


def _axis_frame(along: int) -> tuple[np.ndarray, np.ndarray]:
    """Unit vector along the way and the two across it, for the axis index ``along``."""
    axes = np.eye(3)
    return axes[along], np.delete(axes, along, axis=0)


def _centres(rng: np.random.Generator, radii: np.ndarray, along: int) -> list[np.ndarray]:
    """A centre in the slab for each bounding radius of ``radii``, each redrawn until the
    obstacle keeps clear of the start (the robot) and of the goal region."""
    forward, across = _axis_frame(along)
    goal = LENGTH * forward
    centres = []
    for radius in radii:
        while True:
            centre = rng.uniform(*SLAB) * forward + rng.uniform(-HALF_WIDTH, HALF_WIDTH, 2) @ across
            clear_of_start = np.linalg.norm(centre) > radius + ROBOT_RADIUS + KEEP_OUT
            clear_of_goal = np.linalg.norm(centre - goal) > radius + GOAL_RADIUS + KEEP_OUT
            if clear_of_start and clear_of_goal:
                centres.append(centre)
                break
    return centres


def _rounded(values: np.ndarray, digits: int = 3) -> list[float]:
    return [round(float(v), digits) for v in values]


def _scenario(name: str, frame: str, along: int, obstacles: list[dict]) -> dict[str, Any]:
    """A transfer scenario's data: start at rest at the origin, goal ``LENGTH`` along axis
    ``along``, bounds 10 m beyond the slab and the goal."""
    forward, _ = _axis_frame(along)
    lower, upper = np.full(3, -HALF_WIDTH - 10.0), np.full(3, HALF_WIDTH + 10.0)
    lower[along], upper[along] = -10.0, LENGTH + 10.0
    world: dict[str, Any] = {"frame": frame, "duration": 400.0}
    if frame == "lvlh":
        world["orbit"] = {"radius": ORBIT_RADIUS}
    return {
        "name": name,
        "description": f"path-planner bench problem {name}",
        "world": world,
        "obstacles": obstacles,
        "mission": {
            "type": "transfer",
            "goal": {"position": _rounded(LENGTH * forward), "radius": GOAL_RADIUS},
            "bounds": {"lower": _rounded(lower), "upper": _rounded(upper)},
            "planning_budget": 1.0,
            "safety_distance": FAMILY_MARGIN,
        },
    }


def static_spheres(seed: int) -> dict[str, Any]:
    """Scenario data of ``static-spheres`` for ``seed``."""
    rng = np.random.default_rng(seed)
    radii = np.round(rng.uniform(1.0, 3.0, 20), 3)
    obstacles = [
        {
            "id": FIRST_ID + i,
            "radius": float(radius),
            "motion": {"type": "static", "position": _rounded(centre)},
        }
        for i, (centre, radius) in enumerate(zip(_centres(rng, radii, 0), radii, strict=True))
    ]
    return _scenario(f"static-spheres-{seed}", "geocentric", 0, obstacles)


def cw_spheres(seed: int) -> dict[str, Any]:
    """Scenario data of ``cw-spheres`` for ``seed`` (the way runs along-track, +y)."""
    rng = np.random.default_rng(seed)
    radii = np.round(rng.uniform(1.0, 2.5, 20), 3)
    centres = _centres(rng, radii, 1)
    obstacles = [
        {
            "id": FIRST_ID + i,
            "radius": float(radius),
            "motion": {
                "type": "cw",
                "position": _rounded(centre),
                "velocity": _rounded(rng.normal(0.0, 0.02, 3), 4),
            },
        }
        for i, (centre, radius) in enumerate(zip(centres, radii, strict=True))
    ]
    return _scenario(f"cw-spheres-{seed}", "lvlh", 1, obstacles)


def _random_shape(rng: np.random.Generator, box: bool) -> dict[str, Any]:
    """A box or a cylinder of random size, turned uniformly at random."""
    quaternion = rng.normal(size=4)
    orientation = _rounded(quaternion / np.linalg.norm(quaternion), 6)
    if box:
        extents = _rounded(rng.uniform(0.5, 2.5, 3))
        return {"type": "box", "half_extents": extents, "orientation": orientation}
    radius, height = round(rng.uniform(0.5, 2.0), 3), round(rng.uniform(2.0, 8.0), 3)
    return {"type": "cylinder", "radius": radius, "height": height, "orientation": orientation}


def shapes(seed: int) -> dict[str, Any]:
    """Scenario data of ``shapes`` for ``seed``: boxes and cylinders in turn."""
    rng = np.random.default_rng(seed)
    drawn = [_random_shape(rng, box=i % 2 == 0) for i in range(16)]
    centres = _centres(rng, np.array([_bounding_radius(shape) for shape in drawn]), 0)
    obstacles = [
        {
            "id": FIRST_ID + i,
            "motion": {"type": "static", "position": _rounded(centre)},
            "shape": shape,
        }
        for i, (centre, shape) in enumerate(zip(centres, drawn, strict=True))
    ]
    return _scenario(f"shapes-{seed}", "geocentric", 0, obstacles)


def _bounding_radius(shape: dict[str, Any]) -> float:
    if shape["type"] == "box":
        return float(np.linalg.norm(shape["half_extents"]))
    return float(np.hypot(shape["radius"], 0.5 * shape["height"]))


FAMILIES: dict[str, Callable[[int], dict[str, Any]]] = {
    "static-spheres": static_spheres,
    "cw-spheres": cw_spheres,
    "shapes": shapes,
    "asteroid-escape": escape_scenario,
}
"""The random families by name: each gives a transfer scenario's data for a seed."""

DEFAULT_PROBLEMS = ("static-spheres", "cw-spheres", "shapes")
"""The problem set when none is named: each family with seed 0."""


def initial_problem(scenario: Scenario) -> PathProblem:
    """The path problem a transfer scenario's mission poses at t = 0.

    The world is built from the scenario for the robot's properties, its true initial
    state (the state the mission is fed when it flies without a localiser) and the
    obstacle tracks in sensor range, then closed.

    Raises
    ------
    DcsimError
        If the scenario's mission is not a transfer.
    """
    if scenario.mission.type != "transfer":
        raise DcsimError(
            f"scenario '{scenario.name}' is a {scenario.mission.type} mission; "
            "the path-planner bench takes transfer scenarios (mission.type: transfer)"
        )
    with World(scenario, component_rng(scenario.world.seed, "world")) as world:
        position, velocity, attitude, angular_velocity = world.base_state()
        start = RobotState(world.time, position, attitude, velocity, angular_velocity)
        obstacles = world.observations().obstacles()
        return transfer_problem(scenario, start, obstacles, world.robot_spec())


def _family_spec(spec: str) -> tuple[str, int] | None:
    """``(family, seed)`` of ``FAMILY`` or ``FAMILY:SEED``, or None if ``spec`` is neither."""
    match = re.fullmatch(r"([a-z-]+)(?::(\d+))?", spec)
    if match is None or match[1] not in FAMILIES:
        return None
    return match[1], int(match[2] or 0)


def expand_specs(specs: Sequence[str]) -> list[str]:
    """Problem specs with every ``FAMILY:A..B`` replaced by ``FAMILY:A`` to ``FAMILY:B``."""
    expanded = []
    for spec in specs:
        match = re.fullmatch(r"([a-z-]+):(\d+)\.\.(\d+)", spec)
        if match is None or match[1] not in FAMILIES:
            expanded.append(spec)
            continue
        first, last = int(match[2]), int(match[3])
        expanded += [f"{match[1]}:{seed}" for seed in range(first, last + 1)]
    return expanded


def load_problem(spec: str) -> BenchProblem:
    """A problem from ``FAMILY``, ``FAMILY:SEED`` or the path of a transfer scenario file.

    Raises
    ------
    DcsimError
        If ``spec`` is no family and no readable transfer scenario (a
        :class:`~dcsim.errors.ScenarioError` for an invalid file).
    """
    family = _family_spec(spec)
    if family is not None:
        name, seed = family
        data = FAMILIES[name](seed)
        document = ScenarioDocument(f"<{data['name']}>", data)
        problem_name = data["name"]
    else:
        path = Path(spec)
        if not path.is_file():
            raise DcsimError(
                f"'{spec}' is neither a problem family ({', '.join(FAMILIES)}, optionally "
                "with :SEED) nor a scenario file"
            )
        document = ScenarioDocument.from_file(path)
        problem_name = re.sub(r"\s+", "_", path.stem)
    return BenchProblem(problem_name, document, initial_problem(validate(document)))
