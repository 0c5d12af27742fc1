"""Messages: immutability, value equality, shapes, and the Move conversion."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from dcsim.api import (
    BeaconRange,
    Command,
    LinearMotion,
    LocationEstimate,
    MoveCommand,
    ObjectKind,
    ObjectTrack,
    Trajectory,
    quaternion_between,
    rotate,
)


def test_messages_are_immutable_down_to_their_arrays():
    reading = BeaconRange(beacon_id=2, beacon_position=[1.0, 2.0, 3.0], range=4.0, sigma=0.1)
    with pytest.raises(dataclasses.FrozenInstanceError):
        reading.range = 5.0
    with pytest.raises(ValueError):
        reading.beacon_position[0] = 9.0


def test_messages_copy_their_inputs_and_compare_by_value():
    source = np.array([1.0, 2.0, 3.0])
    a = Command(force=source)
    source[0] = 100.0
    assert a.force[0] == 1.0
    assert a == Command(force=[1, 2, 3])
    assert a != Command(force=[1, 2, 4])


def test_shapes_are_checked():
    with pytest.raises(ValueError, match=r"covariance must have shape \(6, 6\)"):
        LocationEstimate(time=0.0, position=[0, 0, 0], covariance=np.eye(3))


def test_track_prediction_uses_its_motion_or_constant_velocity():
    track = ObjectTrack(1, ObjectKind.TARGET, time=2.0, position=[0, 0, 0], velocity=[1, 0, 0])
    np.testing.assert_allclose(track.predict(4.0)[0], [2.0, 0.0, 0.0])
    moving = dataclasses.replace(track, motion=LinearMotion((5, 5, 5), (0, 1, 0)))
    np.testing.assert_allclose(moving.predict(4.0)[0], [5.0, 9.0, 5.0])


@pytest.mark.parametrize(
    "a, b",
    [
        ([1, 0, 0], [0, 1, 0]),
        ([1, 2, 3], [-3, 0.5, 2]),
        ([0, 0, 1], [0, 0, -1]),
        ([1, 0, 0], [1, 0, 0]),
    ],
)
def test_quaternion_between_rotates_a_onto_b(a, b):
    q = quaternion_between(a, b)
    assert np.linalg.norm(q) == pytest.approx(1.0)
    rotated = rotate(q, np.asarray(a, float) / np.linalg.norm(a))
    np.testing.assert_allclose(rotated, np.asarray(b, float) / np.linalg.norm(b), atol=1e-12)


def test_move_command_converts_to_a_force_within_the_limit():
    heading = [1.0, 0.0, 0.0]
    move = MoveCommand(rotation=quaternion_between(heading, [0, 1, 0]), speed=0.5)
    np.testing.assert_allclose(move.desired_velocity(heading), [0.0, 0.5, 0.0], atol=1e-12)
    gentle = move.to_command(
        heading, velocity=[0, 0.4, 0], mass=100.0, max_force=50.0, response_time=2.0
    )
    np.testing.assert_allclose(gentle.force, [0.0, 5.0, 0.0], atol=1e-9)
    hard = move.to_command(
        heading, velocity=[0, -1, 0], mass=100.0, max_force=10.0, response_time=1.0
    )
    assert np.linalg.norm(hard.force) == pytest.approx(10.0)
    assert hard.force[1] > 0


def test_trajectory_samples_linearly_and_holds_at_the_ends():
    trajectory = Trajectory(
        times=[0, 10], positions=[[0, 0, 0], [10, 0, 0]], velocities=[[2, 0, 0], [0, 0, 0]]
    )
    position, velocity = trajectory.sample(2.5)
    np.testing.assert_allclose(position, [2.5, 0, 0])
    np.testing.assert_allclose(velocity, [1.5, 0, 0])
    position, velocity = trajectory.sample(20.0)
    np.testing.assert_allclose(position, [10, 0, 0])
    np.testing.assert_allclose(velocity, [0, 0, 0])
