"""Draw the asteroid field of ``scenarios/asteroid_escape.yaml``.

The course project this scenario comes from (source 002) modelled its asteroids in
Blender and gives neither their number, sizes nor places. This script draws them once,
from a fixed seed: ``COUNT`` spheres of radius uniform in ``RADII``, each wholly inside
the force field, none within ``START_CLEARANCE`` of the ship's start (surface to the
ship's surface) and none closer than ``GAP`` to another. The goal region (z < -21 m)
lies below the force field, so no asteroid touches it. Run it to print the scenario's
``obstacles:`` entries::

    python scenarios/asteroid_field.py

A test checks that the scenario file holds exactly what this prints.
"""

from __future__ import annotations

import numpy as np
import yaml

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


def main() -> None:
    """Print the ``obstacles:`` entries, one flow-style line each."""
    for entry in obstacle_entries(draw_field()):
        line = yaml.safe_dump(entry, default_flow_style=True, sort_keys=False, width=200)
        print("  - " + line.strip())


if __name__ == "__main__":
    main()
