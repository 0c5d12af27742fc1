"""The default scenario flown with ``ga`` against the ``nearest`` baseline over 20 seeds."""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

from dcsim.runner import Runner
from dcsim.runsetup import prepare_run

SEEDS = range(20)


def fly(planner: str, seed: int) -> dict:
    """Summary of the default scenario with ``planner`` and ``seed`` (nothing written)."""
    setup = prepare_run(None, [f"task_planner.plugin={planner}"], seed)
    return Runner(setup, None).run()


@pytest.fixture(scope="module")
def summaries():
    with ProcessPoolExecutor(max_workers=2) as pool:
        jobs = {
            (planner, seed): pool.submit(fly, planner, seed)
            for planner in ("ga", "nearest")
            for seed in SEEDS
        }
        return {key: job.result() for key, job in jobs.items()}


def delta_v(summaries, planner):
    return np.array([summaries[planner, seed]["delta_v_mps"] for seed in SEEDS])


def test_ga_delivers_every_target_without_collision_on_every_seed(summaries):
    for seed in SEEDS:
        summary = summaries["ga", seed]
        assert summary["status"] == "completed", (seed, summary["reason"])
        assert summary["delivered"] == summary["targets"] == 4, seed
        assert summary["collisions"] == 0, seed


def test_ga_needs_no_more_delta_v_than_nearest(summaries):
    ga, nearest = delta_v(summaries, "ga"), delta_v(summaries, "nearest")
    complete = np.array([summaries["nearest", s]["delivered"] == 4 for s in SEEDS])
    assert complete.all()
    assert np.all(ga <= nearest), np.round(np.c_[ga, nearest], 3)
