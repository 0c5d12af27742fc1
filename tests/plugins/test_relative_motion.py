"""Free motion and burn plans of the burn planners: single-burn arcs against the
Clohessy–Wiltshire closed form and the world's free drift, the two-burn delta-v against
a direct solve, and burn plans flown with finite thrust."""

from __future__ import annotations

import textwrap

import numpy as np
import pytest
from dcsim_plugins.path_planners.relative_motion import BurnPlan, FreeMotion
from scipy.optimize import least_squares

from dcsim.api import (
    ClohessyWiltshireMotion,
    FrameDynamics,
    FrameKind,
    LinearMotion,
    mean_motion,
)
from dcsim.scenario import ScenarioDocument, validate
from dcsim.world import World

N = mean_motion(6_778_137.0)
"""Mean motion of a 400 km orbit (the scenarios' default), rad/s; its period is 93 min."""

START = np.array([2.0, -1.0, 0.5])
END = np.array([-3.0, 6.0, 2.0])


def test_free_motion_of_a_frame():
    assert FreeMotion.of(FrameDynamics()).mean_motion == 0.0
    cw = FrameDynamics(kind=FrameKind.CLOHESSY_WILTSHIRE, mean_motion=N)
    assert FreeMotion.of(cw).mean_motion == N
    assert FreeMotion(N).longest_duration == pytest.approx(0.9 * np.pi / N)
    assert FreeMotion(0.0).longest_duration == np.inf


# ---------------------------------------------------------------- single burn (closed form)


@pytest.mark.parametrize("fraction", [0.002, 0.05, 0.3, 0.99])
def test_single_burn_arc_lands_on_the_end_point_by_the_closed_form(fraction):
    motion = FreeMotion(N)
    duration = fraction * motion.longest_duration  # 5 s to 41 min
    departure, arrival = motion.single_burn(START, END, duration)
    position, velocity = ClohessyWiltshireMotion(START, departure, N).state_at(duration)
    np.testing.assert_allclose(position, END, rtol=0, atol=1e-9)
    np.testing.assert_allclose(velocity, arrival, rtol=0, atol=1e-12)
    # the orbit bends the arc: a straight line at the departure velocity misses the end
    if fraction >= 0.3:
        assert np.linalg.norm(START + departure * duration - END) > 1.0


def test_single_burn_is_vectorised_over_leading_axes():
    rng = np.random.default_rng(3)
    starts, ends = rng.uniform(-20, 20, (4, 5, 3)), rng.uniform(-20, 20, (4, 5, 3))
    durations = rng.uniform(10.0, 2000.0, (4, 5))
    departure, arrival = FreeMotion(N).single_burn(starts, ends, durations)
    assert departure.shape == arrival.shape == (4, 5, 3)
    for i, j in [(0, 0), (1, 3), (3, 4)]:
        exact = ClohessyWiltshireMotion(starts[i, j], departure[i, j], N)
        position, velocity = exact.state_at(durations[i, j])
        np.testing.assert_allclose(position, ends[i, j], atol=1e-9)
        np.testing.assert_allclose(velocity, arrival[i, j], atol=1e-12)


def test_propagate_follows_the_closed_form():
    rng = np.random.default_rng(5)
    positions, velocities = rng.uniform(-30, 30, (6, 3)), rng.uniform(-0.1, 0.1, (6, 3))
    durations = rng.uniform(0.0, 6000.0, 6)  # up to an orbit
    moved, speeds = FreeMotion(N).propagate(positions, velocities, durations)
    for k in range(6):
        exact = ClohessyWiltshireMotion(positions[k], velocities[k], N).state_at(durations[k])
        np.testing.assert_allclose(moved[k], exact[0], atol=1e-9)
        np.testing.assert_allclose(speeds[k], exact[1], atol=1e-12)


def test_inertial_single_burn_is_a_straight_line():
    motion = FreeMotion(0.0)
    departure, arrival = motion.single_burn(START, END, 40.0)
    np.testing.assert_allclose(departure, (END - START) / 40.0, rtol=1e-15)
    np.testing.assert_array_equal(arrival, departure)
    times = np.linspace(0.0, 40.0, 9)
    points, velocities = motion.propagate(START, departure, times)
    straight = LinearMotion(START, departure).state_at(times)[0]
    np.testing.assert_allclose(points, straight, atol=1e-12)
    np.testing.assert_allclose(points, START + np.outer(times / 40.0, END - START), atol=1e-12)
    np.testing.assert_allclose(velocities, np.tile(departure, (9, 1)), rtol=0)


# ---------------------------------------------------------------- single burn (the world)


def test_single_burn_arc_is_the_world_free_drift():
    """A robot started on an arc's departure state in the world's LVLH frame, with no
    thrust, ends where the arc does.

    PyBullet integrates with semi-implicit Euler (velocity first, then position with the
    new velocity): positions run ahead of the exact ones by about ½ dt times the
    velocity gained, here ½ × 0.01 s × 0.019 m/s ≈ 0.1 mm after 300 s. The tolerance is
    twice that (0.19 mm), against a drift of 8.7 m of which 2.9 m is the orbit's bending.
    """
    motion, duration, step = FreeMotion(N), 300.0, 0.01
    departure, arrival = motion.single_burn(START, END, duration)
    world = World(
        validate(
            ScenarioDocument.from_text(
                textwrap.dedent(f"""\
                    world: {{frame: lvlh, physics_step: {step}, control_period: 0.1}}
                    robot: {{initial: {{position: {START.tolist()}, velocity: {departure.tolist()}}}}}
                    """),
                "drift.yaml",
            )
        ),
        np.random.default_rng(0),
    )
    for _ in range(round(duration / 0.1)):
        world.step()
    assert world.time == pytest.approx(duration)
    position, velocity, _, _ = world.base_state()
    expected, expected_velocity = motion.propagate(START, departure, duration)
    np.testing.assert_allclose(expected, END, atol=1e-9)
    np.testing.assert_allclose(expected_velocity, arrival, atol=1e-12)
    assert np.linalg.norm(START + departure * duration - END) > 2.5  # the check is not empty
    tolerance = step * np.linalg.norm(arrival - departure)
    assert np.linalg.norm(position - expected) < tolerance
    np.testing.assert_allclose(velocity, expected_velocity, rtol=0, atol=1e-6)


# ---------------------------------------------------------------- two burns (direct solve)


def direct_two_burn(n, position, velocity, goal_position, goal_velocity, duration):
    """Delta-v of the two-burn transfer found by solving for the departure velocity with
    scipy and the closed-form propagation (``LinearMotion`` when ``n`` is 0)."""

    def state(departure):
        if n == 0:
            return LinearMotion(position, departure).state_at(duration)
        return ClohessyWiltshireMotion(position, departure, n).state_at(duration)

    guess = (goal_position - position) / duration
    solved = least_squares(
        lambda v: (state(v)[0] - goal_position) / np.linalg.norm(goal_position - position),
        guess,
        xtol=1e-15,
        ftol=1e-15,
        gtol=1e-15,
    )
    end, arrival = state(solved.x)
    assert np.linalg.norm(end - goal_position) < 1e-8  # the solve converged
    return np.linalg.norm(solved.x - velocity) + np.linalg.norm(goal_velocity - arrival)


@pytest.mark.parametrize("n", [0.0, N])
def test_two_burn_delta_v_matches_a_direct_solve(n):
    rng = np.random.default_rng(11)
    positions = rng.uniform(-30, 30, (8, 3))
    velocities = rng.uniform(-0.05, 0.05, (8, 3))
    goal, goal_velocity = np.array([12.0, -4.0, 7.0]), np.array([0.01, -0.02, 0.0])
    durations = rng.uniform(30.0, 2400.0, 8)
    estimate = FreeMotion(n).two_burn_delta_v(positions, velocities, goal, goal_velocity, durations)
    assert estimate.shape == (8,)
    for k in range(8):
        direct = direct_two_burn(n, positions[k], velocities[k], goal, goal_velocity, durations[k])
        assert estimate[k] == pytest.approx(direct, rel=1e-7)


# ---------------------------------------------------------------- burn plans flown


def burn_plan(n: float) -> BurnPlan:
    """Three legs of 60 to 90 s with burns of 0.04 to 0.06 m/s, moving at start and goal."""
    return BurnPlan(
        FreeMotion(n),
        times=np.array([10.0, 70.0, 160.0, 250.0]),
        positions=np.array([[0, 0, 0], [3, 1, 0], [5, 4, 2], [8, 3, 1.0]]),
        start_velocity=np.array([0.01, -0.02, 0.0]),
        goal_velocity=np.array([0.0, 0.03, 0.01]),
    )


MASS = 150.0


@pytest.mark.parametrize("n", [0.0, N])
def test_burn_plan_trajectory_starts_and_ends_on_the_plan(n):
    plan = burn_plan(n)
    path = plan.trajectory(0.01, MASS, 5.0, {"points_searched": 7.0})
    assert path.times[0] == plan.times[0] and path.times[-1] == plan.times[-1]
    np.testing.assert_array_equal(path.positions[0], plan.positions[0])
    np.testing.assert_array_equal(path.velocities[0], plan.start_velocity)
    np.testing.assert_allclose(path.positions[-1], plan.positions[-1], rtol=0, atol=1e-9)
    np.testing.assert_allclose(path.velocities[-1], plan.goal_velocity, rtol=0, atol=1e-15)
    assert np.all(np.diff(path.times) > 0)
    assert np.diff(path.times).max() <= 5.0 + 1e-9  # the sample step
    assert path.duration == pytest.approx(240.0)
    chords = np.linalg.norm(np.diff(path.positions, axis=0), axis=1).sum()
    assert path.length == pytest.approx(chords, rel=1e-12)
    assert path.statistics == {"points_searched": 7.0}
    assert path.attitudes is None


@pytest.mark.parametrize("n", [0.0, N])
def test_burn_plan_trajectory_delta_v_and_forces(n):
    plan, limit = burn_plan(n), 0.01
    path = plan.trajectory(limit, MASS, 5.0)
    spans = np.diff(path.times)
    changes = np.diff(path.velocities, axis=0)
    accelerations = changes / spans[:, None]
    burning = np.linalg.norm(path.forces, axis=1) > 0
    assert burning.sum() == 4 * 4  # four burns of four segments each
    # forces are the mass times the acceleration while burning, nothing while coasting
    np.testing.assert_allclose(path.forces[burning], MASS * accelerations[burning], rtol=1e-9)
    # the delta-v the samples imply is the trajectory's delta-v
    implied = np.linalg.norm(changes[burning], axis=1).sum()
    assert implied == pytest.approx(path.delta_v, rel=1e-9)
    thrust = (np.linalg.norm(path.forces, axis=1) / MASS * spans).sum()
    assert thrust == pytest.approx(path.delta_v, rel=1e-9)
    if n == 0:  # nothing else changes the velocity in an inertial frame
        assert np.linalg.norm(changes, axis=1).sum() == pytest.approx(path.delta_v, rel=1e-9)
        np.testing.assert_array_equal(path.forces[~burning], 0.0)
    # finite burns cost more than the impulsive plan, but not much when they are short
    assert plan.delta_v <= path.delta_v <= 1.05 * plan.delta_v
    assert plan.trajectory(limit, None, 5.0).forces is None


@pytest.mark.parametrize(
    "n, limit",
    [
        (0.0, 0.01),
        (0.0, 0.002),
        (N, 0.01),
        (N, 0.002),
    ],
)
def test_burns_keep_to_the_acceleration_limit(n, limit):
    # each burn takes 4 to 6 s (0.01 m/s²) or 20 to 28 s (0.002 m/s²) of a 60 to 90 s leg
    plan = burn_plan(n)
    path = plan.trajectory(limit, MASS, 5.0)
    accelerations = np.linalg.norm(np.diff(path.velocities, axis=0), axis=1) / np.diff(path.times)
    thrusts = np.linalg.norm(path.forces, axis=1) / MASS
    assert thrusts.max() <= limit * 1.0001
    assert accelerations.max() <= limit * 1.0001


@pytest.mark.parametrize("n", [0.0, N])
def test_long_burns_end_at_the_goal(n):
    plan = burn_plan(n)
    path = plan.trajectory(0.002, MASS, 5.0)
    np.testing.assert_allclose(path.positions[-1], plan.positions[-1], rtol=0, atol=1e-6)
    np.testing.assert_allclose(path.velocities[-1], plan.goal_velocity, rtol=0, atol=1e-15)


def test_burns_longer_than_their_leg_are_refused():
    # 0.5 m/s onto the leg and 0.5 m/s off it at 0.05 m/s²: 20 s of burns in a 10 s leg
    plan = BurnPlan(
        FreeMotion(0.0),
        times=np.array([0.0, 10.0]),
        positions=np.array([[0.0, 0.0, 0.0], [5.0, 0.0, 0.0]]),
        start_velocity=np.zeros(3),
        goal_velocity=np.zeros(3),
    )
    with pytest.raises(ValueError, match="a leg is shorter than the burns at its ends"):
        plan.trajectory(0.05, None, 1.0)
    # at 0.2 m/s² the burns would fill the leg (bang-bang, 5 s each); at 0.25 they take 2.8 s
    assert plan.trajectory(0.25, None, 1.0).times[-1] == 10.0


def test_overlapping_interior_burns_are_refused():
    # burns of 1 m/s at t = 50 s and t = 51 s take 20 s each at 0.05 m/s²
    plan = BurnPlan(
        FreeMotion(0.0),
        times=np.array([0.0, 50.0, 51.0, 100.0]),
        positions=np.array([[0, 0, 0], [5, 0, 0], [5, 1, 0], [10, 0, 0.0]]),
        start_velocity=np.zeros(3),
        goal_velocity=np.zeros(3),
    )
    with pytest.raises(ValueError):
        plan.trajectory(0.05, 10.0, 5.0)
