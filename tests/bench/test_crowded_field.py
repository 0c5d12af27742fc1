"""The crowded-field scenario and its per-seed obstacle fields."""

from __future__ import annotations

import numpy as np
import pytest

from dcsim.bench.controllers import (
    FIELD_BOX,
    ControllerCase,
    bench_controllers,
    crowded_obstacles,
    field_override,
    fly,
    markdown_table,
)
from dcsim.campaign import ClusterOptions
from dcsim.errors import DcsimError
from dcsim.scenario import packaged_scenario_path, read_scenario
from tests.conftest import REPO


def test_the_scenario_file_holds_the_seed_0_field():
    scenario = read_scenario(REPO / "scenarios" / "crowded_field.yaml")
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
    scenario = read_scenario(packaged_scenario_path("crowded_field.yaml"), [field_override(3)])
    assert [o.id for o in scenario.obstacles] == [o["id"] for o in crowded_obstacles(3)]


@pytest.mark.xdist_group("dask")
def test_the_bench_flies_its_cases_on_the_campaign_engine_as_in_process():
    scenario = packaged_scenario_path("crowded_field.yaml")
    short = ("world.duration=6.0",)
    lines = []
    runs = bench_controllers(
        scenario, ["pd", "elastic"], [3], short, ClusterOptions(workers=2), lines.append
    )
    assert [(r.controller, r.seed) for r in runs] == [("pd", 3), ("elastic", 3)]
    assert runs == [fly(ControllerCase(scenario, r.controller, 3, short)) for r in runs]
    assert len(lines) == 2
    with pytest.raises(DcsimError, match="(?s)bench controllers: ScenarioError: .*no_such_gain"):
        bench_controllers(
            scenario,
            ["pd"],
            [3],
            (*short, "controller.params.no_such_gain=1"),
            ClusterOptions(workers=1),
        )


def test_a_run_stopped_early_is_kept_and_counted_with_its_reason():
    scenario = packaged_scenario_path("crowded_field.yaml")
    cut = ("world.duration=2.0", "stop.max_wall_time=0.001")
    stopped = fly(ControllerCase(scenario, "pd", 3, cut))
    assert stopped.stopped == "wall-time limit of 0.001 s reached"
    complete = fly(ControllerCase(scenario, "pd", 3, cut[:1]))
    assert complete.stopped == ""
    row = markdown_table([stopped, complete]).splitlines()[2]
    assert row.split("|")[-2].strip() == "1"


def test_every_controller_flies_under_each_sensing_profile_in_its_own_row():
    scenario = packaged_scenario_path("crowded_field.yaml")
    short = ("world.duration=4.0",)
    runs = [
        fly(ControllerCase(scenario, name, 3, short, profile))
        for profile in ("ideal", "realistic")
        for name in ("elastic", "pd")
    ]
    ideal, realistic = runs[0], runs[2]
    assert (ideal.sensors, realistic.sensors) == ("ideal", "realistic")
    # Under realistic sensing the collector flies on the tracker's tracks and the
    # localiser's attitude readings: another flight than on the truth.
    assert realistic.delta_v != ideal.delta_v
    rows = [line.split("|")[1:3] for line in markdown_table(runs).splitlines()[2:]]
    assert [(a.strip(), b.strip()) for a, b in rows] == [
        ("elastic", "ideal"),
        ("elastic", "realistic"),
        ("pd", "ideal"),
        ("pd", "realistic"),
    ]
