"""Task planners planning from tracked targets (``dcsim bench task-planners --studies tracked``)."""

from __future__ import annotations

import dataclasses

import numpy as np

from dcsim.bench.task_planners import (
    OBSERVATION,
    flown_against_truth,
    random_request,
    request_at,
    tracked_request,
    tracked_table,
    tracked_targets,
)
from dcsim.registry.discovery import PluginRegistry


def _truth(seed: int, n: int = 5, observation: float = OBSERVATION):
    return request_at(random_request(np.random.default_rng(seed), n, True), observation)


def test_the_request_at_the_watch_s_end_has_its_targets_moved_there():
    start = random_request(np.random.default_rng(3), 4, True)
    later = request_at(start, 10.0)
    assert later.time == 10.0 and later.robot.time == 10.0
    for before, after in zip(start.targets, later.targets, strict=True):
        np.testing.assert_allclose(after.position, before.position + 10.0 * before.velocity)
        np.testing.assert_allclose(after.predict(500.0)[0], before.predict(500.0)[0])


def test_the_tracker_knows_every_target_after_watching_within_its_covariance():
    registry = PluginRegistry.discover()
    errors = {}
    for observation in (2.0, 20.0):
        truth = _truth(7, 8, observation)
        tracked = tracked_request(truth, registry, 7, observation)
        assert [t.id for t in tracked.targets] == [t.id for t in truth.targets]
        assert all(t.time == truth.time and t.covariance is not None for t in tracked.targets)
        velocity = np.array([t.velocity for t in tracked.targets])
        true_velocity = np.array([t.velocity for t in truth.targets])
        errors[observation] = np.abs(velocity - true_velocity).max()
        for track, true in zip(tracked.targets, truth.targets, strict=True):
            error = track.position - true.position
            assert error @ np.linalg.solve(track.covariance[:3, :3], error) < 25.0
    # A longer watch knows the drift better (its velocity error shrinks as T^-1.5).
    assert errors[20.0] < errors[2.0] / 4


def test_a_plan_from_the_truth_flies_as_planned_one_from_wrong_tracks_does_not():
    registry = PluginRegistry.discover()
    truth = _truth(11)
    planner = registry.create("task_planner", "nearest", {}, np.random.default_rng(0))
    plan = planner.plan(truth)
    flown = flown_against_truth(truth, plan)
    for planned, true in zip(plan.tasks, flown.tasks, strict=True):
        np.testing.assert_allclose(true.pickup_point, planned.pickup_point, atol=1e-9)
    shifted = tuple(
        dataclasses.replace(t, position=t.position + 5.0, motion=None) for t in truth.targets
    )
    wrong = planner.plan(dataclasses.replace(truth, targets=shifted))
    misses = [
        np.linalg.norm(a.pickup_point - b.pickup_point)
        for a, b in zip(wrong.tasks, flown_against_truth(truth, wrong).tasks, strict=True)
    ]
    np.testing.assert_allclose(misses, 5.0 * np.sqrt(3.0), rtol=1e-6)


def test_the_study_at_its_least_counts_prints_a_row_per_planner():
    results = tracked_targets((5,), 1, OBSERVATION, progress=lambda line: None)
    assert [(r.label, len(r.oracle), len(r.flown), r.incomplete) for r in results] == [
        ("ga", 1, 1, 0),
        ("nearest", 1, 1, 0),
    ]
    assert all(len(r.misses) == 5 for r in results)
    lines = tracked_table(results).splitlines()
    assert [line.split("|")[2].strip() for line in lines[2:]] == ["ga", "nearest"]
