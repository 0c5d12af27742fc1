"""The crowded-field scenario and its per-seed obstacle fields."""

from __future__ import annotations

import numpy as np

from dcsim.bench.controllers import FIELD_BOX, crowded_obstacles, field_override
from dcsim.scenario import load_scenario, packaged_scenario_path
from tests.conftest import REPO


def test_the_scenario_file_holds_the_seed_0_field():
    scenario = load_scenario(REPO / "scenarios" / "crowded_field.yaml")
    assert len(scenario.obstacles) >= 50
    written = [o.model_dump(exclude_none=True) for o in scenario.obstacles]
    for entry, generated in zip(written, crowded_obstacles(0), strict=True):
        assert entry["id"] == generated["id"] and entry["radius"] == generated["radius"]
        np.testing.assert_allclose(entry["motion"]["position"], generated["motion"]["position"])
        np.testing.assert_allclose(entry["motion"]["velocity"], generated["motion"]["velocity"])


def test_every_seed_draws_another_field_inside_the_slab():
    first, second = crowded_obstacles(1), crowded_obstacles(2)
    assert first != second
    low, high = np.array(FIELD_BOX).T
    positions = np.array([o["motion"]["position"] for o in first])
    assert np.all(positions >= low) and np.all(positions <= high)
    # The field travels as a scenario override that validates.
    scenario = load_scenario(packaged_scenario_path("crowded_field.yaml"), [field_override(3)])
    assert [o.id for o in scenario.obstacles] == [o["id"] for o in crowded_obstacles(3)]
