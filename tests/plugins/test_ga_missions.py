"""The default scenario flown with ``ga`` against the ``nearest`` baseline over 20 seeds.

Each seed is a test group of its own, so that pytest-xdist spreads the 40 runs over
its workers; the checks hold on every seed when they pass for each. The first
``QUICK_SEEDS`` are in ``make test``; the rest of the sweep is in the slow group
(``make test-slow``).
"""

from __future__ import annotations

import pytest

from dcsim.run.loop import Runner
from dcsim.run.setup import setup_run

SEEDS = range(20)
QUICK_SEEDS = 5


def fly(planner: str, seed: int) -> dict:
    """Summary of the default scenario with ``planner`` and ``seed`` (nothing written)."""
    setup = setup_run(None, [f"task_planner.plugin={planner}"], seed)
    return Runner(setup, None).run()


@pytest.fixture(
    scope="module",
    params=[
        pytest.param(
            seed,
            id=f"seed{seed}",
            marks=[pytest.mark.xdist_group(f"ga-seed{seed}")]
            + ([] if seed < QUICK_SEEDS else [pytest.mark.slow]),
        )
        for seed in SEEDS
    ],
)
def summaries(request) -> dict[str, dict]:
    """Both planners' summaries on one seed, by planner."""
    return {planner: fly(planner, request.param) for planner in ("ga", "nearest")}


def test_ga_delivers_every_target_without_collision_on_every_seed(summaries):
    summary = summaries["ga"]
    assert summary["status"] == "completed", summary["reason"]
    assert summary["delivered"] == summary["targets"] == 4
    assert summary["collisions"] == 0


def test_ga_needs_no_more_delta_v_than_nearest(summaries):
    ga, nearest = summaries["ga"]["delta_v_mps"], summaries["nearest"]["delta_v_mps"]
    assert summaries["nearest"]["delivered"] == 4
    assert ga <= nearest, (round(ga, 3), round(nearest, 3))
