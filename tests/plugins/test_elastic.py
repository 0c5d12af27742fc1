"""The elastic controller: eqs 5.1-5.3, the Move message, and avoidance in the world."""

from __future__ import annotations

import textwrap

import numpy as np
import pytest
from dcsim_plugins.controllers.elastic import (
    ElasticController,
    MoveCommand,
    braking_limit,
    early_dodge,
    perpendicular_repulsion,
    repulsion,
)

from dcsim.api import (
    LinearMotion,
    ObjectKind,
    ObjectTrack,
    Reference,
    RobotSpec,
    StateEstimate,
    Surroundings,
    quaternion_between,
    rotate,
    unit,
)
from dcsim.run.loop import Runner
from dcsim.run.setup import setup_run

ROBOT = RobotSpec(
    mass=100.0, inertia=10.0 * np.eye(3), radius=0.5, max_force=5.0, max_torque=0.5, max_speed=0.5
)


def controller(**params):
    plugin = ElasticController(params)
    plugin.reset(ROBOT)
    return plugin


def obstacle(position, velocity=(0.0, 0.0, 0.0), radius=1.0, obstacle_id=9):
    return ObjectTrack(
        obstacle_id,
        ObjectKind.OBSTACLE,
        0.0,
        position,
        velocity,
        radius=radius,
        motion=LinearMotion(position, velocity),
    )


def at(position, velocity=(0.0, 0.0, 0.0)):
    return StateEstimate(time=0.0, position=position, velocity=velocity, converged=True)


# --------------------------------------------------------------------- equations


def test_the_two_cross_products_and_the_less_disruptive_choice():
    closeness = np.array([[1.0, 0.0, 0.0]])
    velocity = np.array([[0.0, 2.0, 0.0]])
    plus, minus, chosen = perpendicular_repulsion(closeness, velocity, np.array([0, 0, 1.0]))
    np.testing.assert_allclose(plus, [[0.0, 0.0, 2.0]])  # (D' - D) x V
    np.testing.assert_allclose(minus, [[0.0, 0.0, -2.0]])  # V x (D' - D)
    np.testing.assert_allclose(chosen, plus)  # +z agrees with an attraction along +z
    leaning_down = perpendicular_repulsion(closeness, velocity, np.array([0, 0.3, -1.0]))[2]
    np.testing.assert_allclose(leaning_down, minus)


def push(closeness, relative_velocity, attraction, gain=0.5, **options):
    """The repulsion with eq. 5.2's own choice of side, as the controller uses it."""
    chosen = perpendicular_repulsion(closeness, relative_velocity, attraction)[2]
    return repulsion(closeness, relative_velocity, attraction, gain, chosen, **options)


def test_a_perpendicular_push_grows_with_the_depth_inside_the_safety_sphere():
    pushed = push(
        np.array([[0.8, 0.0, 0.0]]), np.array([[0.0, 0.3, 0.0]]), np.array([0.0, 0.0, 0.4])
    )
    np.testing.assert_allclose(pushed, [[0.0, 0.0, 0.5 * 0.8]], atol=1e-12)


def test_head_on_and_static_cases_push_half_away_half_aside():
    closeness = np.array([[2.0, 0.0, 0.0]])
    attraction = np.array([-0.3, 0.1, 0.0])  # towards the obstacle, leaning to +y
    expected = 0.5 * 2.0 * np.array([1.0, 1.0, 0.0]) / np.sqrt(2.0)
    for velocity in ([[0.0, 0.0, 0.0]], [[-0.4, 0.0, 0.0]]):  # both at rest; head-on
        pushed = push(closeness, np.array(velocity), attraction)
        np.testing.assert_allclose(pushed, [expected], atol=1e-12)


def test_a_slow_obstacle_pushes_away_and_aside_rather_than_perpendicular():
    closeness = np.array([[1.0, 0.0, 0.0]])
    attraction = np.array([0.0, 0.2, 0.0])
    slow = push(closeness, np.array([[0.0, 0.0, 0.001]]), attraction, speed_scale=0.05)
    fast = push(closeness, np.array([[0.0, 0.0, 0.2]]), attraction, speed_scale=0.05)
    # V x C is along +y (the attraction's side) for V along +z; the slow obstacle gets 2 %
    # of that push, the rest radial + aside.
    np.testing.assert_allclose(fast, [[0.0, 0.5, 0.0]], atol=1e-12)
    aside = 0.5 * np.array([1.0, 1.0, 0.0]) / np.sqrt(2.0)
    np.testing.assert_allclose(slow, [0.02 * np.array([0, 0.5, 0]) + 0.98 * aside], atol=1e-12)


def test_desired_velocity_is_attraction_plus_the_pushes_of_closing_obstacles():
    plugin = controller(gain=0.1, repulsion_gain=0.5, lookahead=0.0, brake_fraction=0.0)
    reference = Reference(time=0.0, position=[2.0, 0.0, 0.0])
    estimate = at([0.0, 0.0, 0.0], velocity=[0.3, 0.0, 0.0])
    attraction = np.array([0.2, 0.0, 0.0])  # 0.1/s x 2 m
    far = Surroundings((obstacle([0.0, 30.0, 0.0]),), safety_distance=2.0)
    np.testing.assert_allclose(plugin.desired_velocity(0.0, estimate, reference, far), attraction)
    # Beside the path while the collector closes: D = (-0.5, 3, 0), |D| = 3.04 m inside the
    # 2 + 0.5 + 1 m sphere; C x V with V = (-0.3, 0, 0) points along z, and sin(C, V) =
    # 3 / |D| of the push is perpendicular, the rest half radial, half aside.
    beside = Surroundings((obstacle([0.5, -3.0, 0.0]),), safety_distance=2.0)
    push = plugin.desired_velocity(0.0, estimate, reference, beside) - attraction
    distance = np.hypot(0.5, 3.0)
    depth, sine = 3.5 - distance, 3.0 / distance
    assert abs(push[2]) == pytest.approx(0.5 * depth * sine)
    assert np.linalg.norm(push[:2]) == pytest.approx(0.5 * depth * (1 - sine))
    # The same obstacle once passed (the collector moving away from it) does not push.
    receding = Surroundings((obstacle([-0.5, -3.0, 0.0]),), safety_distance=2.0)
    np.testing.assert_allclose(
        plugin.desired_velocity(0.0, estimate, reference, receding), attraction
    )


def test_the_early_dodge_widens_a_foreseen_miss_and_leaves_a_clear_pass_alone():
    planned = np.array([0.3, 0.0, 0.0])
    still = np.zeros((1, 3))
    sphere = np.array([4.0])
    # 1 m beside the line, closest approach in 33 s: one pass adds (4 - 1) m / 33 s along
    # the miss vector, across the relative velocity, on the side the collector already misses.
    beside = np.array([[-10.0, -1.0, 0.0]])  # D, obstacle to collector
    once = early_dodge(beside, still, sphere, planned, 0.5, 60.0, 4.0)
    assert once[1] < 0 and once[2] == 0  # on the side the collector already misses
    # Flying the dodged velocity, the straight-line closest approach clears the sphere.
    relative = -once
    t_star = beside[0] @ relative / (relative @ relative)
    assert 0 < t_star < 60.0
    assert np.linalg.norm(beside[0] - relative * t_star) == pytest.approx(4.0, abs=1e-6)
    # The first pass alone is (4 - 1) m over the 33 s to the closest approach, along -y.
    one_pass = early_dodge(beside, still, sphere, planned, 0.5, 60.0, 4.0, passes=1)
    np.testing.assert_allclose(one_pass, planned + [0.0, -3.0 / (10.0 / 0.3), 0.0])
    # Passing clear (miss 5 m > 4 m), beyond the horizon, or behind: no dodge.
    for away in ([-10.0, -5.0, 0.0], [-30.0, -1.0, 0.0], [10.0, -1.0, 0.0]):
        np.testing.assert_allclose(
            early_dodge(np.array([away]), still, sphere, planned, 0.5, 60.0, 4.0), planned
        )


def test_a_dead_on_dodge_takes_the_thesis_candidate():
    planned = np.array([0.3, 0.05, 0.0])
    dodged = early_dodge(
        np.array([[-10.0, 0.0, 0.0]]), np.zeros((1, 3)), np.array([4.0]), planned, 0.5, 60.0, 4.0
    )
    assert np.linalg.norm(dodged - planned) > 0.05
    assert dodged[1] > planned[1]  # the side the attraction leans to (eq. 5.2)


def test_the_braking_limit_slows_the_approach_and_escapes_a_creeping_obstacle():
    still = np.zeros((1, 3))
    keep = np.array([3.0])
    a, lag = 0.02, 4.0
    # 1 m outside the kept distance, flying straight at a static obstacle at 0.5 m/s.
    limited = braking_limit(
        np.array([[-4.0, 0.0, 0.0]]), still, keep, np.array([0.5, 0.1, 0.0]), 0.5, a, lag, 0.2
    )
    stoppable = a * (-lag + np.sqrt(lag**2 + 2 * 1.0 / a))
    assert limited[0] == pytest.approx(stoppable)
    assert limited[1] == pytest.approx(0.1)  # the sideways part is left alone
    # Far away: untouched.
    far = braking_limit(
        np.array([[-40.0, 0.0, 0.0]]), still, keep, np.array([0.5, 0.0, 0.0]), 0.5, a, lag, 0.2
    )
    np.testing.assert_allclose(far, [0.5, 0.0, 0.0])
    # At rest, an obstacle creeping in at 5 cm/s and 0.5 m inside the kept distance: the
    # collector moves straight away, faster than the obstacle comes.
    creeping = braking_limit(
        np.array([[0.0, 2.5, 0.0]]),
        np.array([[0.0, 0.05, 0.0]]),
        keep,
        np.zeros(3),
        0.5,
        a,
        lag,
        0.2,
    )
    np.testing.assert_allclose(creeping, [0.0, 0.05 + 0.2 * 0.5, 0.0])


def test_the_braking_limit_heeds_every_obstacle_at_once():
    keep = np.array([3.0, 3.0])
    away = np.array([[-3.5, 0.0, 0.0], [0.0, -3.2, 0.0]])  # one ahead, one beside
    velocities = np.array([[0.0, 0.0, 0.0], [0.0, 0.04, 0.0]])  # the one beside creeps in
    a, lag = 0.02, 4.0
    out = braking_limit(away, velocities, keep, np.array([0.5, 0.0, 0.0]), 0.5, a, lag, 0.2)
    normals = away / np.linalg.norm(away, axis=1)[:, None]
    gaps = np.linalg.norm(away, axis=1) - keep
    allowed = a * (-lag + np.sqrt(lag**2 + 2 * gaps / a))
    receding = np.einsum("ij,ij->i", out - velocities, normals)
    assert np.all(receding >= -allowed - 1e-9)


def test_drop_speed_limits_the_desired_velocity():
    plugin = controller()
    reference = Reference(time=0.0, position=[100.0, 0.0, 0.0], max_speed=0.2)
    desired = plugin.desired_velocity(0.0, at([0.0, 0.0, 0.0]), reference, Surroundings())
    assert np.linalg.norm(desired) == pytest.approx(0.2)


@pytest.mark.parametrize("velocity", [[0.2, 0.0, 0.0], [0.0, -0.3, 0.1], [-0.2, 0.0, 0.0]])
def test_the_move_quaternion_turns_the_heading_onto_the_commanded_direction(velocity):
    plugin = controller()
    estimate = at([0.0, 0.0, 0.0], velocity=velocity)
    reference = Reference(time=0.0, position=[3.0, 4.0, 0.0])
    surroundings = Surroundings((obstacle([1.5, 1.5, 0.3], [0.0, 0.05, 0.0]),), safety_distance=2.0)
    move = plugin.move(0.0, estimate, reference, surroundings)
    desired = plugin.desired_velocity(0.0, estimate, reference, surroundings)
    np.testing.assert_allclose(np.linalg.norm(move.rotation), 1.0)
    np.testing.assert_allclose(rotate(move.rotation, unit(velocity)), unit(desired), atol=1e-9)
    assert move.speed == pytest.approx(np.linalg.norm(desired))
    force = plugin.command(0.0, estimate, reference, surroundings).force
    assert np.linalg.norm(force) <= ROBOT.max_force + 1e-9


# --------------------------------------------------------------------- in the world

CROSSING = """\
    world: {{frame: geocentric, duration: 600}}
    robot: {{radius: 0.5, max_speed: 0.5, initial: {{position: [0, 0, 0]}}}}
    mission:
      targets:
        - {{id: 1, radius: 0.3, motion: {{type: static, position: [40, 0, 0]}}}}
      drop_point: {{position: [-5, 0, 0], tolerance: 1.5}}
      safety_distance: 5.0
    obstacles:
      - {{id: 9, radius: 1.0, motion: {{type: cartesian, position: {obstacle_at}, velocity: {obstacle_v}}}}}
    beacons: {{positions: [[100, 100, 100], [100, -100, -100], [-100, 100, -100], [-100, -100, 100]]}}
    localiser: {{plugin: ekf}}
    task_planner: {{plugin: nearest}}
    path_planner: {{plugin: straight-line, params: {{check_obstacles: false}}}}
    controller: {{plugin: {controller}}}
    stop: {{on_collision: false}}
    """


def fly(tmp_path, controller_name, obstacle_at, obstacle_v):
    path = tmp_path / f"{controller_name}.yaml"
    path.write_text(
        textwrap.dedent(CROSSING).format(
            controller=controller_name, obstacle_at=obstacle_at, obstacle_v=obstacle_v
        )
    )
    return Runner(setup_run(path), None).run()


@pytest.mark.parametrize(
    "case, obstacle_at, obstacle_v",
    [
        ("static, on the line", "[20, 0, 0]", "[0, 0, 0]"),
        ("head-on", "[45, 0, 0]", "[-0.1, 0, 0]"),
    ],
)
def test_elastic_flies_round_what_pd_flies_into(tmp_path, case, obstacle_at, obstacle_v):
    pd = fly(tmp_path, "pd", obstacle_at, obstacle_v)
    assert pd["collisions"] > 0, case  # the straight line really is blocked
    elastic = fly(tmp_path, "elastic", obstacle_at, obstacle_v)
    assert elastic["collisions"] == 0, case
    assert elastic["delivered"] == 1, case
    assert elastic["min_obstacle_distance_m"] > 0.5, case


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
