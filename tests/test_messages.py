"""Messages: immutability, value equality, shapes, and the general state contracts."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

from dcsim.api import (
    BeaconRange,
    Command,
    GoalRegion,
    LinearMotion,
    ObjectKind,
    ObjectTrack,
    Reference,
    RobotSpec,
    RobotState,
    Shape,
    ShapeKind,
    StateEstimate,
    Trajectory,
    quaternion_between,
    quaternion_from_rotation_vector,
    rotate,
    rotation_vector,
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


def test_messages_keep_arrays_nobody_can_write_and_copy_the_others():
    owner = np.array([1.0, 2.0, 3.0])
    owner.setflags(write=False)
    kept = Command(force=owner)
    assert kept.force is owner
    assert Command(torque=kept.force).torque is owner
    writable = np.array([[1.0, 2.0, 3.0]])
    view = writable[0]
    view.setflags(write=False)  # read-only, but its owner can still change it
    copied = Command(force=view)
    writable[0, 0] = 9.0
    assert copied.force[0] == 1.0
    assert Command(force=np.array([1, 2, 3])).force.dtype == float


def test_trusted_messages_equal_checked_ones_and_need_every_field():
    position = np.array([1.0, 2.0, 3.0])
    position.setflags(write=False)
    trusted = BeaconRange.trusted(beacon_id=1, beacon_position=position, range=4.0, sigma=0.5)
    assert trusted == BeaconRange(1, [1.0, 2.0, 3.0], 4.0, 0.5)
    with pytest.raises(TypeError, match="needs exactly the fields"):
        BeaconRange.trusted(beacon_id=1, beacon_position=position, range=4.0)


def test_shapes_are_checked():
    with pytest.raises(ValueError, match=r"covariance must have shape \(-1, -1\)"):
        StateEstimate(time=0.0, position=[0, 0, 0], covariance=np.ones(6))
    with pytest.raises(ValueError, match="covariance must be square, got 3×4"):
        StateEstimate(time=0.0, position=[0, 0, 0], covariance=np.ones((3, 4)))
    with pytest.raises(ValueError, match=r"force must have shape \(3,\)"):
        Command(force=[1.0, 2.0])


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


def test_rotation_vectors_become_scipys_quaternions_and_back():
    vectors = np.vstack([np.random.default_rng(4).normal(size=(50, 3)), np.zeros((1, 3))])
    vectors[:50] *= 3.0 / np.linalg.norm(vectors[:50], axis=1, keepdims=True)  # angles < π
    quaternions = quaternion_from_rotation_vector(vectors)
    np.testing.assert_allclose(quaternions, Rotation.from_rotvec(vectors).as_quat(), atol=1e-12)
    np.testing.assert_allclose(rotation_vector(quaternions), vectors, atol=1e-12)


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
    position, velocity = trajectory.sample(10.0)  # the last sample exactly
    np.testing.assert_allclose(position, [10, 0, 0])
    positions, velocities = trajectory.sample([-1.0, 2.5, 20.0])
    np.testing.assert_allclose(positions, [[0, 0, 0], [2.5, 0, 0], [10, 0, 0]])
    np.testing.assert_allclose(velocities, [[2, 0, 0], [1.5, 0, 0], [0, 0, 0]])


def test_trajectory_samples_inside_as_numpy_interp_does_to_the_bit():
    rng = np.random.default_rng(3)
    times = np.cumsum(rng.uniform(0.01, 10.0, 40))
    trajectory = Trajectory(
        times=times, positions=rng.normal(0, 1e3, (40, 3)), velocities=rng.normal(0, 1, (40, 3))
    )
    for t in [*rng.uniform(times[0], times[-1], 200), *times[1:-1]]:
        position, velocity = trajectory.sample(t)
        expected = [np.interp(t, times, trajectory.positions[:, k]) for k in range(3)]
        assert position.tolist() == expected
        expected = [np.interp(t, times, trajectory.velocities[:, k]) for k in range(3)]
        assert velocity.tolist() == expected


def test_trajectory_end_state_takes_the_goal_attitude_when_it_leaves_the_attitude_free():
    free = Trajectory(
        times=[0, 10], positions=[[0, 0, 0], [10, 0, 0]], velocities=[[1, 0, 0], [0, 0, 0]]
    )
    turned = [0.0, 0.0, np.sin(np.pi / 4), np.cos(np.pi / 4)]
    goal = GoalRegion(position=[10, 0, 0], tolerance=0.1, attitude=turned, attitude_tolerance=0.01)
    assert free.end_state().time == 10.0
    np.testing.assert_allclose(free.end_state().attitude, [0, 0, 0, 1])
    assert goal.contains(free.end_state(goal))
    held = dataclasses.replace(free, attitudes=[[0, 0, 0, 1], [0, 0, 0, 1]])
    assert not goal.contains(held.end_state(goal))


def test_robot_state_checks_its_attitude_and_joints():
    state = RobotState(
        time=1.0,
        position=[1, 2, 3],
        velocity=[0.1, 0.2, 0.3],
        angular_velocity=[0.01, 0.02, 0.03],
        joint_positions=[0.5, -0.5],
        joint_velocities=[1.0, 2.0],
    )
    np.testing.assert_array_equal(
        state.generalised_velocity, [0.1, 0.2, 0.3, 0.01, 0.02, 0.03, 1.0, 2.0]
    )
    np.testing.assert_array_equal(state.configuration, [1, 2, 3, 0, 0, 0, 1, 0.5, -0.5])
    assert RobotState().joint_positions.shape == (0,)
    with pytest.raises(ValueError, match="attitude must be a unit quaternion, its norm is 2"):
        RobotState(attitude=[0, 0, 0, 2])
    with pytest.raises(ValueError, match="2 joint positions but 1 joint velocities"):
        RobotState(joint_positions=[0.0, 0.0], joint_velocities=[0.0])


def test_an_estimate_is_a_robot_state_with_covariance():
    estimate = StateEstimate(time=2.0, position=[1, 0, 0], converged=True)
    assert isinstance(estimate, RobotState)
    np.testing.assert_array_equal(estimate.covariance, np.eye(6))
    np.testing.assert_array_equal(estimate.attitude, [0, 0, 0, 1])
    state = estimate.as_state(5.0)
    assert type(state) is RobotState and state.time == 5.0
    np.testing.assert_array_equal(state.position, [1, 0, 0])
    assert estimate.as_state().time == 2.0


def test_reference_attitude_is_optional_and_command_carries_joint_torques():
    free = Reference(time=0.0, position=[0, 0, 0])
    assert free.attitude is None
    held = Reference(time=0.0, position=[0, 0, 0], attitude=[0, 0, 1, 0])
    np.testing.assert_array_equal(held.attitude, [0, 0, 1, 0])
    assert held != free
    with pytest.raises(ValueError, match=r"attitude must have shape \(4,\)"):
        Reference(time=0.0, position=[0, 0, 0], attitude=[0, 0, 1])
    command = Command(joint_torques=[1.0, -2.0, 3.0])
    assert command.joint_torques.shape == (3,)
    assert Command().joint_torques.shape == (0,)


def test_robot_spec_holds_inertia_and_joint_limits():
    spec = RobotSpec(mass=10.0, inertia=np.diag([1.0, 2.0, 3.0]), radius=1.0)
    assert spec.joint_position_limits.shape == (0, 2)
    assert spec.model is None
    with pytest.raises(ValueError, match=r"inertia must have shape \(3, 3\)"):
        RobotSpec(mass=10.0, inertia=[1.0, 2.0, 3.0])


def test_shapes_know_their_bounding_radius_and_tracks_default_to_spheres():
    box = Shape(ShapeKind.BOX, half_extents=[1.0, 2.0, 2.0])
    assert box.bounding_radius == pytest.approx(3.0)
    cylinder = Shape(ShapeKind.CYLINDER, radius=3.0, height=8.0)
    assert cylinder.bounding_radius == pytest.approx(5.0)
    track = ObjectTrack(1, ObjectKind.OBSTACLE, 0.0, [0, 0, 0], [0, 0, 0], radius=2.0)
    assert track.shape == Shape(ShapeKind.SPHERE, radius=2.0)
    boxed = ObjectTrack(2, ObjectKind.OBSTACLE, 0.0, [0, 0, 0], [0, 0, 0], shape=box)
    assert boxed.radius == pytest.approx(3.0)


def test_a_track_s_shape_margin_is_the_part_of_its_radius_that_was_not_sensed():
    track = ObjectTrack(1, ObjectKind.TARGET, 0.0, [0, 0, 0], [0, 0, 0], radius=0.4)
    assert track.shape_margin == 0.0 and track.sensed_radius == 0.4
    widened = ObjectTrack(
        2, ObjectKind.TARGET, 0.0, [0, 0, 0], [0, 0, 0], radius=0.4, shape_margin=0.1
    )
    assert widened.radius == 0.4 and widened.sensed_radius == pytest.approx(0.3)
    point = ObjectTrack(
        3, ObjectKind.TARGET, 0.0, [0, 0, 0], [0, 0, 0], radius=0.4, shape_margin=0.4
    )
    assert point.sensed_radius == 0.0  # a detection without extent, widened by the margin
    for margin in (-0.1, 0.5, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="shape_margin must be 0 m or more"):
            ObjectTrack(
                3, ObjectKind.TARGET, 0.0, [0, 0, 0], [0, 0, 0], radius=0.4, shape_margin=margin
            )


def test_trajectory_attitude_follows_scipy_slerp():
    times = np.array([0.0, 2.0, 5.0])
    rotations = Rotation.from_euler(
        "xyz", [[0, 0, 0], [40, -30, 120], [170, 10, -60]], degrees=True
    )
    trajectory = Trajectory(
        times=times,
        positions=np.zeros((3, 3)),
        velocities=np.zeros((3, 3)),
        attitudes=rotations.as_quat(),
    )
    reference = Slerp(times, rotations)
    for t in np.linspace(0.0, 5.0, 23):
        ours = Rotation.from_quat(trajectory.state_at(t).attitude)
        assert (ours * reference(t).inv()).magnitude() < 1e-9, t
    np.testing.assert_allclose(trajectory.attitude_at(-1.0), rotations[0].as_quat())
    np.testing.assert_allclose(trajectory.attitude_at(9.0), rotations[2].as_quat())


def test_trajectory_rows_must_match_its_times():
    with pytest.raises(ValueError, match="forces has 3 rows, expected 2 for 3 times"):
        Trajectory(
            times=[0, 1, 2],
            positions=np.zeros((3, 3)),
            velocities=np.zeros((3, 3)),
            forces=np.zeros((3, 3)),
        )
    free = Trajectory(times=[0, 1], positions=np.zeros((2, 3)), velocities=np.zeros((2, 3)))
    with pytest.raises(ValueError, match="leaves the attitude free"):
        free.attitude_at(0.5)
    np.testing.assert_array_equal(free.state_at(0.5).attitude, [0, 0, 0, 1])


def test_goal_regions_check_position_velocity_time_and_attitude():
    sphere = GoalRegion(position=[10, 0, 0], tolerance=1.0)
    assert sphere.contains(RobotState(position=[10.5, 0.5, 0]))
    assert not sphere.contains(RobotState(position=[11.5, 0, 0]))
    box = GoalRegion(position=[0, 0, 0], half_extents=[1.0, 2.0, 3.0])
    assert box.contains(RobotState(position=[0.9, -1.9, 2.9]))
    assert not box.contains(RobotState(position=[1.1, 0, 0]))
    slow = GoalRegion(position=[0, 0, 0], tolerance=1.0, velocity_tolerance=0.1)
    assert not slow.contains(RobotState(velocity=[0.2, 0, 0]))
    timed = GoalRegion(position=[0, 0, 0], tolerance=1.0, time=10.0, time_tolerance=1.0)
    assert timed.contains(RobotState(time=10.5)) and not timed.contains(RobotState(time=12.0))
    turn = Rotation.from_euler("z", 10, degrees=True).as_quat()
    pointed = GoalRegion(
        position=[0, 0, 0], tolerance=1.0, attitude=[0, 0, 0, 1], attitude_tolerance=np.radians(15)
    )
    assert pointed.contains(RobotState(attitude=turn))
    assert pointed.contains(RobotState(attitude=-turn))  # the same attitude
    tight = dataclasses.replace(pointed, attitude_tolerance=np.radians(5))
    assert not tight.contains(RobotState(attitude=turn))
