"""PosePath: joint references that carry the end effector along a pose trajectory."""

from __future__ import annotations

import numpy as np
import pytest

from dcsim.api import (
    PosePath,
    Trajectory,
    load_robot_model,
    quaternion_from_matrix,
    quaternion_from_rotation_vector,
    quaternion_multiply,
    rotation_matrix,
    rotation_vector,
)
from tests.conftest import REPO

READY = np.radians([3.474921, 0.0, 90.0, 90.0, -149.725932, -123.748989])
"""The capture scenario's ready pose: the end effector 2.1 m ahead and 0.4 m up, x forward."""


@pytest.fixture(scope="module")
def model():
    return load_robot_model(REPO / "scenarios" / "debris_capture.yaml")


def ready_state() -> np.ndarray:
    q = np.zeros(13)
    q[6] = 1.0
    q[7:] = READY
    return q


def rolling_move(model, roll: float, shift: np.ndarray, duration: float = 10.0) -> Trajectory:
    """The end effector from the ready pose, shifted by ``shift`` (m) and rolled by
    ``roll`` (rad) about its own x axis, both by the minimum-jerk law."""
    frame = model.forward_kinematics(ready_state())
    times = np.linspace(0.0, duration, 401)
    tau = times / duration
    shape = tau**3 * (10 - 15 * tau + 6 * tau**2)
    rate = 30 * tau**2 * (1 - tau) ** 2 / duration
    axis = frame.end_effector_rotation[:, 0]
    start = quaternion_from_matrix(frame.end_effector_rotation)
    attitudes = np.array(
        [
            quaternion_multiply(quaternion_from_rotation_vector(s * roll * axis), start)
            for s in shape
        ]
    )
    return Trajectory(
        times=times,
        positions=frame.end_effector + np.outer(shape, shift),
        velocities=np.outer(rate, shift),
        attitudes=attitudes,
        angular_velocities=np.outer(rate * roll, axis),
    )


def test_the_joints_carry_the_end_effector_along_position_and_attitude(model):
    trajectory = rolling_move(model, np.radians(40.0), np.array([0.3, 0.1, -0.2]))
    path = PosePath(model, ready_state(), trajectory, step=0.02)
    for t in np.linspace(0.0, 10.0, 21):
        q = ready_state()
        q[7:] = path.at(t).angles
        frame = model.forward_kinematics(q)
        wanted = trajectory.state_at(t)
        assert np.linalg.norm(frame.end_effector - wanted.position) < 1e-5
        wanted_rotation = rotation_matrix(wanted.attitude)
        turn = quaternion_from_matrix(wanted_rotation @ frame.end_effector_rotation.T)
        assert np.linalg.norm(rotation_vector(turn)) < 1e-5
    assert path.tracking.max_error < 1e-5
    assert path.tracking.min_limit_margin == np.inf  # the thesis's arm has no limits


def test_rates_and_accelerations_are_those_of_the_angles(model):
    path = PosePath(model, ready_state(), rolling_move(model, 0.5, np.array([0.2, 0.0, 0.1])))
    h = 1e-4  # within one integration step (0.01 s): the curve is one cubic there
    for t in (2.005, 5.005, 7.505):
        sample = path.at(t)
        difference = (path.at(t + h).angles - path.at(t - h).angles) / (2 * h)
        assert np.allclose(sample.rates, difference, atol=1e-6)
        rate_difference = (path.at(t + h).rates - path.at(t - h).rates) / (2 * h)
        assert np.allclose(sample.accelerations, rate_difference, atol=1e-4)


def test_at_rest_outside_the_trajectory(model):
    path = PosePath(model, ready_state(), rolling_move(model, 0.3, np.array([0.1, 0.0, 0.0])))
    before, after = path.at(-1.0), path.at(11.0)
    assert np.array_equal(before.angles, READY)
    assert not before.rates.any() and not after.rates.any()
    assert np.allclose(after.angles, path.at(10.0).angles)


def test_a_path_through_a_singularity_is_reported(model):
    # the end effector pulled to the edge of the arm's reach: the arm stretches straight
    frame = model.forward_kinematics(ready_state())
    shoulder = frame.origins[0]
    far = shoulder + 1.2 * model.reach * (frame.end_effector - shoulder) / np.linalg.norm(
        frame.end_effector - shoulder
    )
    path = PosePath(model, ready_state(), rolling_move(model, 0.0, far - frame.end_effector))
    assert path.tracking.max_error > 0.1  # it cannot get there
    assert path.tracking.min_det_jjt < 1e-4


def test_a_trajectory_without_attitudes_is_refused(model):
    trajectory = rolling_move(model, 0.0, np.array([0.1, 0.0, 0.0]))
    positions_only = Trajectory(
        times=trajectory.times, positions=trajectory.positions, velocities=trajectory.velocities
    )
    with pytest.raises(ValueError, match="attitudes"):
        PosePath(model, ready_state(), positions_only)
