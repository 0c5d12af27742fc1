"""The debris mission judges its reach by a tracked target's sensed size.

A tracker that cannot see shapes widens each track's sphere by its ``shape_margin`` so
that planners keep clear of what it does not know; the collector still has to stop at
its standoff from the target's surface as sensed, or every grab happens further out
than planned (and, at grab distance, fails).
"""

from __future__ import annotations

import pytest

from tests.conftest import REPO
from tests.test_runner import run


@pytest.mark.parametrize("shape_margin", [0.1, 0.4])
def test_the_first_grab_is_within_reach_whatever_the_tracker_s_margin(
    shape_margin,
):
    overrides = ["world.duration=150", f"tracker.params.shape_margin={shape_margin}"]
    scenario = REPO / "scenarios" / "default_sensed.yaml"
    runner, _ = run(scenario, overrides)
    (grab,) = [e for e in runner.recorder.events if e["event"] == "grab"]
    # Empty-handed, the collector holds half its reach from the surface and grabs once
    # within the other half: the true gap is within reach, up to the estimates' errors.
    reach = runner.scenario.mission.reach
    assert grab["success"]
    assert 0.5 * reach - 0.03 <= grab["gap"] <= reach + 0.03
