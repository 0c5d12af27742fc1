"""The tracker's consistency in the closed loop (``dcsim bench tracking``)."""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner

from dcsim.api import close_run, open_run
from dcsim.bench.tracking import BOUND, TrackingRun, markdown_table, track_consistency
from dcsim.cli.main import cli
from dcsim.errors import DcsimError
from tests.conftest import REPO

DEFAULT = REPO / "scenarios" / "default.yaml"
SHORT = 4.0
"""Simulated seconds of the short runs, s."""


def _seen_by_the_mission(seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Position NEES of the tracks of free objects the debris mission saw each tick of a
    short realistic run of the default scenario, and the same with the localiser's
    error taken out, computed here on their own."""
    runner = open_run(
        DEFAULT, ["sensors.profile=realistic", f"world.duration={SHORT}"], seed=seed, plots=False
    )
    values, relative = [], []
    while True:
        world, mission = runner.world, runner.mission
        positions, _ = world.object_states()
        localiser_error = runner.estimate.position - world.base_state()[0]
        for track in mission.visible.values():
            index = world.field.index[track.id]
            if world.field.status[index] == 0:  # free
                error = track.position - positions[index]
                inverse = np.linalg.inv(track.covariance[:3, :3])
                values.append(error @ inverse @ error)
                own = error - localiser_error
                relative.append(own @ inverse @ own)
        if runner.ended:
            break
        runner.advance()
    close_run(runner)
    return np.array(values), np.array(relative)


def test_every_track_the_mission_sees_is_compared_with_its_object_at_that_tick():
    run = track_consistency(DEFAULT, 2, SHORT)
    assert run.ticks == round(SHORT / 0.1) + 1
    seen, relative = _seen_by_the_mission(2)
    np.testing.assert_allclose(run.position_nees, seen, rtol=1e-9)
    np.testing.assert_allclose(run.relative_nees, relative, rtol=1e-9)
    # Tracks of a few centimetres' error, told to the tracker at that size.
    assert 0 < np.sqrt(np.mean(run.position_error**2)) < 0.3
    assert 1.0 < np.mean(run.position_nees) < 10.0
    assert np.all(run.velocity_nees >= 0) and run.velocity_error.shape == run.position_error.shape
    # The localiser's error is a part of every track's, so taking it out changes the NEES.
    assert run.relative_nees.shape == run.position_nees.shape
    assert not np.allclose(run.relative_nees, run.position_nees)


def test_the_table_counts_the_track_ticks_inside_the_bound_per_scenario():
    nees = np.array([1.0, 2.0, BOUND + 0.1, 3.0])
    errors = np.array([0.1, 0.1, 0.1, 0.1])
    runs = [
        TrackingRun("a.yaml", 0, 10, nees, nees / 2, nees / 4, errors, errors / 10),
        TrackingRun("a.yaml", 1, 10, nees[:2], nees[:2], nees[:2], errors[:2], errors[:2] / 10),
        TrackingRun("b.yaml", 0, 10, *[np.zeros(0)] * 5),
    ]
    table = markdown_table(runs).splitlines()
    assert len(table) == 4
    cells = [cell.strip() for cell in table[2].split("|")[1:-1]]
    assert cells[:7] == [
        "a.yaml",
        "2",
        "20",
        "6",
        f"{np.mean([*nees, 1, 2]):.2f}",
        "83.33%",
        "75.00%",
    ]
    assert cells[-4:] == ["0.100", "0.0100", f"{np.mean([*nees / 4, 1, 2]):.2f}", "100.00%"]
    assert table[3].startswith("| b.yaml | 1 | 10 | 0 | – | 100.00% |")


def test_a_run_without_a_tracker_is_a_dcsim_error_saying_what_to_change():
    with pytest.raises(DcsimError, match="give the object sensor a model"):
        track_consistency(DEFAULT, 0, 1.0, ["sensors.profile=ideal"])
    result = CliRunner().invoke(
        cli, ["bench", "tracking", str(DEFAULT), "--seeds", "1", "--duration", "1",
              "--set", "sensors.profile=ideal"]
    )  # fmt: skip
    assert result.exit_code != 0 and "give the object sensor a model" in result.output


def test_the_command_prints_a_row_per_scenario():
    crowded = REPO / "scenarios" / "crowded_field.yaml"
    result = CliRunner().invoke(
        cli, ["bench", "tracking", str(DEFAULT), str(crowded), "--seeds", "1", "--duration", "1"]
    )
    assert result.exit_code == 0, result.output
    rows = [line for line in result.stdout.splitlines() if line.startswith("| ")]
    assert [row.split("|")[1].strip() for row in rows[1:]] == [
        "default.yaml",
        "crowded_field.yaml",
    ]
