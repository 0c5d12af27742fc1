"""The nearest (greedy) baseline task planner."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from dcsim_plugins.task_planners.nearest import NearestTaskPlanner

from dcsim.api import (
    DropPoint,
    LinearMotion,
    ObjectKind,
    ObjectTrack,
    StateEstimate,
    StaticMotion,
    TaskRequest,
    plan_delta_v,
)


def track(target_id, position, velocity=(0, 0, 0), time=0.0):
    motion = LinearMotion(position, velocity, epoch=time)
    return ObjectTrack(
        target_id, ObjectKind.TARGET, time, position, velocity, mass=5.0, radius=0.5, motion=motion
    )


def request(targets, capacity=3, carried=0, time=0.0, speed=1.0, drop=(0.0, 0.0, 0.0)):
    return TaskRequest(
        time=time,
        robot=StateEstimate(time=time, position=[0, 0, 0], converged=True),
        targets=tuple(targets),
        drop_point=DropPoint(StaticMotion(drop), tolerance=1.0),
        capacity=capacity,
        carried=carried,
        max_speed=speed,
    )


def planner(**params):
    return NearestTaskPlanner({"speed_fraction": 1.0, "time_resolution": 0.5, **params})


def test_static_targets_are_taken_nearest_first_with_timed_pickups():
    targets = [track(1, (30, 0, 0)), track(2, (10, 0, 0)), track(3, (20, 0, 0))]
    plan = planner().plan(request(targets, capacity=3))
    assert [t.target_id for t in plan.tasks] == [2, 3, 1]
    np.testing.assert_allclose([t.pickup_time for t in plan.tasks], [10, 20, 30], atol=1e-6)
    assert [v.after_task for v in plan.drop_visits] == [2]
    assert plan.drop_visits[0].time == pytest.approx(60.0, abs=1e-6)
    assert plan.cost == pytest.approx(plan_delta_v(request(targets, capacity=3), plan))


def test_capacity_forces_drop_visits_between_runs():
    targets = [track(i, (10.0 * i, 0, 0)) for i in range(1, 6)]
    plan = planner().plan(request(targets, capacity=2))
    assert sorted(t.target_id for t in plan.tasks) == [1, 2, 3, 4, 5]
    assert [v.after_task for v in plan.drop_visits] == [1, 3, 4]
    events = sorted([t.pickup_time for t in plan.tasks] + [v.time for v in plan.drop_visits])
    assert np.all(np.diff(events) >= 1.0 - 1e-9)


def test_moving_target_is_intercepted_at_the_earliest_reachable_time():
    moving = track(7, (20, 0, 0), velocity=(0, 0.5, 0))
    plan = planner().plan(request([moving], speed=1.0))
    task = plan.tasks[0]
    point, velocity = moving.predict(task.pickup_time)
    np.testing.assert_allclose(task.pickup_point, point)
    np.testing.assert_allclose(task.pickup_velocity, velocity)
    # In the target's moving frame the aim point stays 20 m away and the cruise speed
    # there is 1 - 0.5 m/s (impulsive burns): 40 s.
    assert task.pickup_time == pytest.approx(40.0, abs=1e-6)


def test_finite_acceleration_delays_pickups_by_the_ramps():
    slow = request([track(1, (10, 0, 0))], speed=1.0)
    slow = dataclasses.replace(slow, max_acceleration=0.1)
    # Rest to rest over 10 m at 1 m/s and 0.1 m/s²: 10 s cruising plus 10 s of ramps.
    assert planner().plan(slow).tasks[0].pickup_time == pytest.approx(20.0, abs=1e-6)


def test_unreachable_targets_are_left_out_and_times_follow_now():
    runaway = track(1, (5, 0, 0), velocity=(2.0, 0, 0))
    reachable = track(2, (0, 8, 0))
    plan = planner().plan(request([runaway, reachable], time=100.0))
    assert [t.target_id for t in plan.tasks] == [2]
    assert plan.tasks[0].pickup_time >= 101.0


def test_empty_requests_give_empty_plans_or_just_a_drop():
    assert planner().plan(request([])).tasks == ()
    assert planner().plan(request([])).drop_visits == ()
    unload = planner().plan(request([], carried=1, drop=(3, 4, 0)))
    assert unload.tasks == () and [v.after_task for v in unload.drop_visits] == [-1]
    assert unload.drop_visits[0].time == pytest.approx(5.0, abs=1e-6)


def test_full_collector_unloads_before_the_first_pickup():
    plan = planner().plan(request([track(1, (10, 0, 0))], capacity=2, carried=2, drop=(-5, 0, 0)))
    assert [v.after_task for v in plan.drop_visits] == [-1, 0]
    assert plan.tasks[0].pickup_time > plan.drop_visits[0].time
