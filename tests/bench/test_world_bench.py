"""``dcsim bench world --orbit-model``: its synthetic fields fly under the model asked."""

from __future__ import annotations

import numpy as np
import pytest

from dcsim.bench.world import bench_world, field_scenario, markdown_table
from dcsim.errors import PlannerModelWarning
from dcsim.run.seeding import component_rng
from dcsim.world import World


def object_positions(orbit_model: str) -> np.ndarray:
    """The field's object positions (m) after 10 s of a 5-object field of ``orbit_model``."""
    with World(field_scenario(5, 10.0, orbit_model=orbit_model), component_rng(0, "w")) as world:
        for _ in range(100):
            world.step()
        return world.object_states()[0]


def test_the_fields_move_by_the_orbit_model_asked():
    assert field_scenario(5, 10.0).world.orbit.model == "cw"  # the default, as before
    cw, j2 = object_positions("cw"), object_positions("j2")
    assert 1e-9 < np.abs(cw - j2).max() < 1e-2  # the same field, the other dynamics


def test_the_bench_measures_a_j2_field():
    with pytest.warns(PlannerModelWarning, match="not the world's j2"):  # they model cw
        rows = bench_world([5], 1.0, progress=lambda line: None, orbit_model="j2")
    assert [row.objects for row in rows] == [5] and rows[0].closed_loop > rows[0].bare > 0
    # the localiser alone is part of the loop, so the loop costs more than it and stepping
    assert rows[0].closed_loop > rows[0].localiser > 0 and rows[0].floor_ratio > 1
    table = markdown_table(rows)
    assert "loop / (bare + localiser alone)" in table.splitlines()[0]
    assert table.splitlines()[2].endswith(f"| {rows[0].floor_ratio:.1f}× |")
