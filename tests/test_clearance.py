"""The swept clearance check against hand-computed distances."""

from __future__ import annotations

import numpy as np
import pytest

from dcsim.messages import (
    GoalRegion,
    ObjectKind,
    ObjectTrack,
    PathProblem,
    RobotState,
    Shape,
    ShapeKind,
    Trajectory,
)
from dcsim.motion import LinearMotion, StaticMotion
from dcsim.yardsticks.clearance import (
    min_clearance,
    path_clearance,
    resolution_step,
    sample_times,
    surface_distance,
)

SQRT2 = np.sqrt(2.0)
QUARTER_TURN_Z = [0.0, 0.0, np.sin(np.pi / 4), np.cos(np.pi / 4)]
EIGHTH_TURN_Z = [0.0, 0.0, np.sin(np.pi / 8), np.cos(np.pi / 8)]
Z_ONTO_X = [0.0, np.sin(np.pi / 4), 0.0, np.cos(np.pi / 4)]  # a quarter turn about y


def line(start, end, duration: float) -> Trajectory:
    """From ``start`` to ``end`` at constant velocity over ``duration`` s."""
    start, end = np.asarray(start, float), np.asarray(end, float)
    velocity = (end - start) / duration
    return Trajectory(
        times=[0.0, duration], positions=[start, end], velocities=[velocity, velocity]
    )


def obstacle(position, shape: Shape, velocity=(0.0, 0.0, 0.0), obstacle_id: int = 7):
    motion = StaticMotion(position) if not np.any(velocity) else LinearMotion(position, velocity)
    return ObjectTrack(
        obstacle_id, ObjectKind.OBSTACLE, 0.0, position, velocity, motion=motion, shape=shape
    )


def distance(shape: Shape, point) -> float:
    return float(surface_distance(shape, np.zeros((1, 3)), np.array([point], float))[0])


BOX = Shape(ShapeKind.BOX, half_extents=(1.0, 2.0, 3.0), orientation=QUARTER_TURN_Z)
CUBE_45 = Shape(ShapeKind.BOX, half_extents=(1.0, 1.0, 1.0), orientation=EIGHTH_TURN_Z)
CYLINDER = Shape(ShapeKind.CYLINDER, radius=1.0, height=4.0, orientation=Z_ONTO_X)
# turned one way only: these tell body-to-world from world-to-body
BAR_30 = Shape(
    ShapeKind.BOX,
    half_extents=(3.0, 1.0, 1.0),
    orientation=[0, 0, np.sin(np.pi / 12), np.cos(np.pi / 12)],
)
ROD_60 = Shape(
    ShapeKind.CYLINDER,
    radius=1.0,
    height=4.0,
    orientation=[np.sin(np.pi / 6), 0, 0, np.cos(np.pi / 6)],
)


@pytest.mark.parametrize(
    "shape, point, expected",
    [
        (Shape(ShapeKind.SPHERE, radius=2.0), (3.0, 4.0, 0.0), 3.0),
        (Shape(ShapeKind.SPHERE, radius=2.0), (0.5, 0.0, 0.0), -1.5),
        # box turned a quarter about z: it reaches 2 m along world x and 1 m along y
        (BOX, (5.0, 0.0, 0.0), 3.0),
        (BOX, (0.0, 4.0, 1.0), 3.0),
        (BOX, (0.0, 0.0, -3.5), 0.5),
        (BOX, (0.0, 0.0, 0.0), -1.0),
        # cube turned an eighth about z: a vertical edge at x = √2, corners at z = ±1
        (CUBE_45, (3.0, 0.0, 0.0), 3.0 - SQRT2),
        (CUBE_45, (3.0, 0.0, 5.0), np.hypot(3.0 - SQRT2, 4.0)),
        (CUBE_45, (2.0, 2.0, 0.0), 2 * SQRT2 - 1.0),
        # cylinder of radius 1, 4 m long, its axis turned onto world x
        (CYLINDER, (0.0, 3.0, 0.0), 2.0),
        (CYLINDER, (1.0, 0.0, -2.5), 1.5),
        (CYLINDER, (5.0, 0.5, 0.0), 3.0),
        (CYLINDER, (4.0, 3.0, 0.0), np.sqrt(8.0)),
        (CYLINDER, (4.0, 0.0, -3.0), np.sqrt(8.0)),
        (CYLINDER, (1.5, 0.0, 0.0), -0.5),
        (CYLINDER, (0.0, 0.2, 0.0), -0.8),
        (BAR_30, (5 * np.cos(np.pi / 6), 5 * np.sin(np.pi / 6), 0.0), 2.0),
        (ROD_60, (0.0, -5 * np.sin(np.pi / 3), 5 * np.cos(np.pi / 3)), 3.0),
    ],
    ids=[
        "sphere-outside",
        "sphere-inside",
        "box-face-x",
        "box-face-y",
        "box-face-z",
        "box-inside",
        "box-edge",
        "box-corner",
        "box-face-diagonal",
        "cylinder-side",
        "cylinder-side-z",
        "cylinder-cap",
        "cylinder-rim",
        "cylinder-rim-z",
        "cylinder-inside-near-cap",
        "cylinder-inside-near-side",
        "box-turned-30-deg",
        "cylinder-turned-60-deg",
    ],
)
def test_point_to_shape_distances(shape, point, expected):
    assert distance(shape, point) == pytest.approx(expected, abs=1e-12)


def test_distances_are_vectorised_over_samples():
    points = np.array([[5.0, 0.0, 0.0], [0.0, 4.0, 1.0], [0.0, 0.0, 0.0]])
    centres = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [10.0, 0.0, 0.0]])
    np.testing.assert_allclose(surface_distance(BOX, centres, points), [3.0, 3.0, 8.0])


def test_passing_a_sphere_gives_the_gap_where_and_when_it_is_smallest():
    trajectory = line((0, 0, 0), (20, 0, 0), 20.0)
    sphere = obstacle((10.0, 3.0, 0.0), Shape(ShapeKind.SPHERE, radius=2.0))
    result = min_clearance(trajectory, [sphere], robot_radius=0.5, step=0.1)
    assert result.distance == pytest.approx(0.5)
    assert result.time == pytest.approx(10.0)
    np.testing.assert_allclose(result.position, [10.0, 0.0, 0.0], atol=1e-9)
    assert result.obstacle_id == 7 and not result.collides
    assert result.samples == 201


def test_the_closest_of_several_obstacles_is_named_and_a_penetration_collides():
    trajectory = line((0, 0, 0), (20, 0, 0), 20.0)
    far = obstacle((5.0, 6.0, 0.0), Shape(ShapeKind.SPHERE, radius=1.0), obstacle_id=1)
    box = obstacle((15.0, 0.0, 1.5), BOX, obstacle_id=2)  # the path runs 1.5 m into it
    result = min_clearance(trajectory, [far, box], robot_radius=0.5, step=0.5)
    assert result.obstacle_id == 2 and result.collides
    assert result.distance == pytest.approx(-1.0 - 0.5)
    assert 13.0 <= result.time <= 17.0


def test_corners_of_the_trajectory_are_checked_between_coarse_steps():
    trajectory = Trajectory(
        times=[0.0, 1.0, 2.0],
        positions=[[0, 0, 0], [10, 10, 0], [20, 0, 0]],
        velocities=np.zeros((3, 3)),
    )
    near_corner = obstacle((10.0, 13.0, 0.0), CYLINDER)  # the side faces the corner
    result = min_clearance(trajectory, [near_corner], robot_radius=0.5, step=100.0)
    assert result.samples == 3
    assert result.distance == pytest.approx(3.0 - 1.0 - 0.5)
    assert result.time == 1.0


def test_an_obstacle_crossing_the_path_collides_when_both_arrive_together():
    trajectory = line((0, 0, 0), (20, 0, 0), 20.0)
    sphere = Shape(ShapeKind.SPHERE, radius=1.0)
    crossing = obstacle((10.0, -10.0, 0.0), sphere, velocity=(0.0, 1.0, 0.0))
    result = min_clearance(trajectory, [crossing], robot_radius=0.5, step=0.01)
    assert result.collides and result.time == pytest.approx(10.0)
    assert result.distance == pytest.approx(-1.5)


def test_an_obstacle_crossing_earlier_is_missed_by_the_computed_gap():
    # robot (t, 0, 0), obstacle (10, t - 15, 0): centres closest at t = 12.5, √12.5 m apart
    trajectory = line((0, 0, 0), (20, 0, 0), 20.0)
    sphere = Shape(ShapeKind.SPHERE, radius=1.0)
    early = obstacle((10.0, -15.0, 0.0), sphere, velocity=(0.0, 1.0, 0.0))
    result = min_clearance(trajectory, [early], robot_radius=0.5, step=0.01)
    assert not result.collides
    assert result.distance == pytest.approx(np.sqrt(12.5) - 1.5, abs=1e-9)
    assert result.time == pytest.approx(12.5)


def test_no_obstacles_means_infinite_clearance():
    result = min_clearance(line((0, 0, 0), (1, 0, 0), 1.0), [], robot_radius=1.0, step=0.1)
    assert result.distance == np.inf and result.obstacle_id is None and not result.collides


def test_the_step_must_be_positive():
    with pytest.raises(ValueError, match="must be positive"):
        sample_times(line((0, 0, 0), (1, 0, 0), 1.0), 0.0)


def test_resolution_step_bounds_the_closing_motion_between_samples():
    trajectory = line((0, 0, 0), (20, 0, 0), 20.0)  # 1 m/s
    sphere = Shape(ShapeKind.SPHERE, radius=1.0)
    moving = obstacle((10.0, -15.0, 0.0), sphere, velocity=(0.0, 1.0, 0.0))
    assert resolution_step(trajectory, [moving], 0.1) == pytest.approx(0.05)
    assert resolution_step(trajectory, [], 0.1) == pytest.approx(0.1)
    at_rest = line((1, 1, 1), (1, 1, 1), 4.0)
    assert resolution_step(at_rest, [], 0.1) == 4.0


def test_path_clearance_samples_a_planned_trajectory_at_a_tenth_of_the_robot_radius():
    trajectory = line((0, 0, 0), (20, 0, 0), 20.0)
    sphere = obstacle((10.0, 3.0, 0.0), Shape(ShapeKind.SPHERE, radius=2.0))
    problem = PathProblem(
        start=RobotState(time=0.0, position=[0, 0, 0]),
        goal=GoalRegion(position=[20, 0, 0], tolerance=1.0),
        obstacles=(sphere,),
        robot_radius=0.5,
    )
    result = path_clearance(trajectory, problem)
    assert result.distance == pytest.approx(0.5) and result.samples == 401  # 0.05 s steps
    point = PathProblem(start=problem.start, goal=problem.goal, obstacles=(sphere,))
    assert path_clearance(trajectory, point).samples == 2001  # 1 cm at 1 m/s
