"""The asteroid fields of the escape experiment (the RRT course project) and their bench family.

The course project modelled its asteroids in Blender and gives neither their number,
sizes nor places. :func:`draw_field` draws them from a seed: ``COUNT`` spheres of radius
uniform in ``RADII``, each wholly inside the force field, none within
``START_CLEARANCE`` of the ship's start (surface to the ship's surface) and none closer
than ``GAP`` to another. The goal region (z < -21 m) lies below the force field, so no
asteroid touches it. ``scenarios/asteroid_field.py`` prints seed 2023's field, the one
``scenarios/asteroid_escape.yaml`` holds; the ``asteroid-escape`` family of
``dcsim bench path-planners`` puts seed N's field into that scenario.
"""

from __future__ import annotations

from typing import Any

import numpy as np

SEED = 2023
"""Seed of the draw (the year of the source)."""
COUNT = 40
"""Number of asteroids."""
RADII = (0.8, 2.5)
"""Smallest and largest radius, m."""
FIELD = ((-16.0, 16.0), (-8.0, 8.0), (-20.0, 20.0))
"""The force field's box: every asteroid lies wholly inside it, m."""
START = (0.0, 0.0, 19.0)
"""The ship's start, m."""
SHIP_RADIUS = 0.5
"""The ship's bounding radius, m (``robot.radius`` of the scenario)."""
START_CLEARANCE = 2.0
"""Least gap between an asteroid and the ship at its start, m."""
GAP = 0.5
"""Least gap between two asteroids, m."""
DENSITY = 2000.0
"""Density of a rocky asteroid, kg/m^3 (gives each its mass)."""


def draw_field(seed: int = SEED, count: int = COUNT) -> list[tuple[np.ndarray, float]]:
    """Centres (m) and radii (m) of ``count`` asteroids, drawn by rejection.

    Parameters
    ----------
    seed : int
        Seed of ``numpy.random.default_rng``.
    count : int
        Number of asteroids.

    Returns
    -------
    list of (ndarray (3,), float)
        Each asteroid's centre and radius.
    """
    rng = np.random.default_rng(seed)
    low, high = np.array(FIELD).T
    field: list[tuple[np.ndarray, float]] = []
    while len(field) < count:
        radius = float(rng.uniform(*RADII))
        centre = rng.uniform(low + radius, high - radius)
        if _clear(centre, radius, field):
            field.append((centre, radius))
    return field


def _clear(centre: np.ndarray, radius: float, field: list[tuple[np.ndarray, float]]) -> bool:
    """Whether an asteroid at ``centre`` keeps its gaps to the start and to ``field``."""
    start_gap = np.linalg.norm(centre - np.array(START)) - radius - SHIP_RADIUS
    if start_gap < START_CLEARANCE:
        return False
    return all(np.linalg.norm(centre - other) - radius - r >= GAP for other, r in field)


def obstacle_entries(field: list[tuple[np.ndarray, float]]) -> list[dict]:
    """The asteroids as scenario ``obstacles`` entries (static spheres, ids from 1)."""
    return [
        {
            "id": i + 1,
            "mass": float(round(DENSITY * 4.0 / 3.0 * np.pi * radius**3, -1)),
            "shape": {"type": "sphere", "radius": round(radius, 2)},
            "motion": {"type": "static", "position": [round(float(c), 2) for c in centre]},
        }
        for i, (centre, radius) in enumerate(field)
    ]


GOAL = {"position": [0.0, 0.0, -23.0], "half_extents": [5.0, 5.0, 2.0]}
"""The goal region: |x| < 5 m, |y| < 5 m, -25 m < z < -21 m."""
BOUNDS = {"lower": [-16.0, -8.0, -25.0], "upper": [16.0, 8.0, 25.0]}
"""The source's position sampling box, m."""
BUDGET = 10.0
"""Planning budget of the bench's escapes, s (the target: solved within 10 s)."""
SAFETY_DISTANCE = 0.05
"""Surface gap every path planner keeps from the asteroids, m (``mission.safety_distance``)."""


def escape_scenario(seed: int) -> dict[str, Any]:
    """Scenario data of the escape through the field drawn with ``seed``: everything else
    as in ``scenarios/asteroid_escape.yaml`` (a test checks they agree), the planning
    budget :data:`BUDGET`."""
    return {
        "name": f"asteroid-escape-{seed}",
        "description": f"the RRT course project's escape through asteroid field {seed}",
        "world": {
            "frame": "geocentric",
            "physics_step": 0.01,
            "control_period": 0.1,
            "duration": 120.0,
            "seed": 0,
        },
        "robot": {
            "mass": 1.0,
            "propellant_mass": 0.1,
            "radius": SHIP_RADIUS,
            "max_force": 0.5,
            "max_torque": 0.01,
            "max_speed": 5.0,
            "specific_impulse": 220.0,
            "sensor_range": 100.0,
            "initial": {
                "position": list(START),
                "velocity": [0.0, 0.0, 0.0],
                "attitude": [0.0, 0.0, 0.0, 1.0],
                "angular_velocity": [0.0, 0.0, 0.0],
            },
        },
        "obstacles": obstacle_entries(draw_field(seed)),
        "mission": {
            "type": "transfer",
            "goal": GOAL,
            "bounds": BOUNDS,
            "planning_budget": BUDGET,
            "safety_distance": SAFETY_DISTANCE,
        },
        "path_planner": {"plugin": "ompl-control"},
        "controller": {"plugin": "pd"},
        "stop": {"on_collision": True},
    }
