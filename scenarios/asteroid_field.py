"""Print the asteroid field of ``scenarios/asteroid_escape.yaml``.

The field is drawn once, from a fixed seed, by :func:`dcsim.bench.asteroids.draw_field`
(its docstring says how). Run this to print the scenario's ``obstacles:`` entries::

    python scenarios/asteroid_field.py

A test checks that the scenario file holds exactly what this prints.
"""

from __future__ import annotations

import yaml

from dcsim.bench.asteroids import draw_field, obstacle_entries

__all__ = ["draw_field", "main", "obstacle_entries"]


def main() -> None:
    """Print the ``obstacles:`` entries, one flow-style line each."""
    for entry in obstacle_entries(draw_field()):
        line = yaml.safe_dump(entry, default_flow_style=True, sort_keys=False, width=200)
        print("  - " + line.strip())


if __name__ == "__main__":
    main()
