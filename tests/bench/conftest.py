"""Fixtures of the bench tests."""

from __future__ import annotations

import pytest

TRANSFER = """\
# a transfer past a sphere and a drifting box; obstacle 3 is beyond sensor range
name: two obstacles
world: {frame: geocentric, duration: 80}
robot: {radius: 0.8, max_speed: 1.0, max_force: 20, sensor_range: 100}
obstacles:
  - {id: 1, radius: 2.0, motion: {type: static, position: [20, 8, 0]}}
  - id: 2
    motion: {type: cartesian, position: [30, -6, 0], velocity: [0, -0.01, 0]}
    shape: {type: box, half_extents: [1, 2, 1], orientation: [0, 0, 0.38268343, 0.92387953]}
  - {id: 3, radius: 1.0, motion: {type: static, position: [20, 0, 150]}}
mission:
  type: transfer
  goal: {position: [30, 0, 0], radius: 1.0}
  planning_budget: 0.5
  max_delta_v: 3.0
"""


@pytest.fixture
def transfer_file(tmp_path):
    """A transfer scenario file (the mission's problem is clear on the straight line)."""
    path = tmp_path / "two_obstacles.yaml"
    path.write_text(TRANSFER)
    return path
