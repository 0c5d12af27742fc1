"""The PyBullet world engine against closed forms and the thesis's §6.2 checks."""

from __future__ import annotations

import textwrap

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from dcsim.api import (
    ClohessyWiltshireMotion,
    DropPoint,
    SphericalMotion,
    StaticMotion,
    mean_motion,
)
from dcsim.missions.debris.services import GrabResult, grab, release
from dcsim.scenario import ScenarioDocument, validate
from dcsim.world import World, WorldInputs
from dcsim.world.environment import STANDARD_GRAVITY, cw_acceleration
from dcsim.world.pybullet_client import pb

N = mean_motion(6_778_137.0)


def world_from(text: str, seed: int = 0) -> World:
    scenario = validate(ScenarioDocument.from_text(textwrap.dedent(text), "test.yaml"))
    return World(scenario, np.random.default_rng(seed))


def grab_target(world: World, target_id: int) -> GrabResult:
    """The debris mission's grab, with the world's robot's capacity and grab distance."""
    return grab(world, target_id, world.robot.capacity, world.robot.grab_distance)


FIELD = """\
    world: {frame: lvlh, physics_step: 0.01, control_period: 0.1}
    robot: {mass: 100, propellant_mass: 10, radius: 0.5, max_force: 5, sensor_range: 30,
            grab_distance: 1.0, capacity: 1, specific_impulse: 200}
    mission:
      targets:
        - {id: 1, radius: 0.5, mass: 5, motion: {type: cw, position: [2.5, 0, 0], velocity: [0, -0.005657, 0]}}
        - {id: 2, radius: 0.5, mass: 5, motion: {type: cw, position: [0, 2.2, 0], velocity: [0, 0, 0]}}
        - {id: 3, radius: 0.5, mass: 5, motion: {type: cw, position: [0, -25, 0], velocity: [0, 0, 0.01]}}
        - {id: 4, radius: 0.5, mass: 5, motion: {type: cw, position: [0, 0, 40], velocity: [0, 0, 0]}}
    obstacles:
      - {id: 9, radius: 1.0, motion: {type: cw, position: [-20, 5, 0], velocity: [0, 0.04525, 0]}}
    beacons:
      positions: [[100, 0, 0], [0, 100, 0], [0, 0, 100], [-100, -100, -100], [500, 500, 500]]
      max_range: 300
      noise_sigma: 0.1
      report_nearest: 3
    """


def test_free_objects_follow_their_closed_forms():
    world = world_from(FIELD)
    for _ in range(300):
        world.step()
    positions, velocities = world.object_states()
    for obj, position, velocity in zip(world.field.objects, positions, velocities, strict=True):
        expected = obj.motion.state_at(30.0)
        np.testing.assert_allclose(position, expected[0], atol=1e-12)
        np.testing.assert_allclose(velocity, expected[1], atol=1e-12)
    assert isinstance(world.field.objects[0].motion, ClohessyWiltshireMotion)
    assert world.time == pytest.approx(30.0)


def test_geocentric_objects_follow_the_thesis_model():
    world = world_from("""\
        world: {frame: geocentric, physics_step: 0.05, control_period: 0.5}
        robot: {initial: {position: {r: 150000, polar_deg: 45, azimuth_deg: 0}}}
        obstacles:
          - {id: 5, motion: {type: spherical, r: 155000, polar_deg: 89.05, azimuth_deg: 0.19, alpha_deg_s: -0.005}}
        """)
    for _ in range(20):
        world.step()
    expected = SphericalMotion(155000, 89.05, 0.19, alpha_deg_s=-0.005).state_at(10.0)[0]
    np.testing.assert_allclose(world.object_states()[0][0], expected, rtol=1e-15)


def test_tracks_only_within_sensor_range():
    world = world_from(FIELD)
    assert sorted(t.id for t in world.object_tracks()) == [1, 2, 3, 9]  # target 4 is 40 m away
    track = next(t for t in world.object_tracks() if t.id == 1)
    np.testing.assert_allclose(track.position, [2.5, 0, 0])
    assert track.kind.value == "target" and track.radius == 0.5 and track.motion is not None


def test_beacons_report_the_nearest_within_range_with_noise():
    world = world_from(FIELD)
    ranges = world.beacon_ranges()
    assert [r.beacon_id for r in ranges] == [0, 1, 2]  # 100 m each; the far two are not nearest
    errors = []
    for _ in range(200):
        world.step()
        for r in world.beacon_ranges():
            errors.append(
                r.range - np.linalg.norm(world.beacons[r.beacon_id] - world.base_state()[0])
            )
    assert np.std(errors) == pytest.approx(0.1, rel=0.15)
    assert abs(np.mean(errors)) < 0.02


def test_grab_within_reach_fails_beyond_and_beyond_capacity():
    world = world_from(FIELD)
    far = grab_target(world, 3)
    assert not far.success and "out of reach" in far.reason
    near = grab_target(world, 1)  # 2.5 m between centres: a 1.5 m gap... too far
    assert not near.success
    world_close = world_from(
        FIELD.replace(
            "position: [2.5, 0, 0], velocity: [0, -0.005657, 0]",
            "position: [1.8, 0, 0], velocity: [0, -0.004073, 0]",
        )
    )
    grabbed = grab_target(world_close, 1)
    assert grabbed.success and grabbed.gap == pytest.approx(0.8, abs=1e-6)
    full = grab_target(
        world_close, 2
    )  # 2.2 m: a 1.2 m gap would be out of reach anyway; capacity first
    assert not full.success and "capacity 1 reached" in full.reason
    assert not grab_target(world_close, 9).success  # an obstacle is no target
    assert grab_target(world_close, 1).reason == "target is not free"


def test_grabbed_target_leaves_the_field_and_rides_with_the_collector():
    world = world_from(FIELD.replace("position: [0, 2.2, 0]", "position: [0, 1.9, 0]"))
    assert grab_target(world, 2).success
    assert 2 not in [t.id for t in world.object_tracks()]

    def offset_in_collector_frame() -> np.ndarray:
        position, _, attitude, _ = world.base_state()
        rotation = np.array(pb.getMatrixFromQuaternion(attitude)).reshape(3, 3)
        return rotation.T @ (world.object_states()[0][1] - position)

    before = offset_in_collector_frame()
    for _ in range(200):
        world.step(WorldInputs(force=np.array([5.0, 0.0, 0.0])))
    np.testing.assert_allclose(offset_in_collector_frame(), before, atol=1e-4)
    assert world.base_state()[1][0] > 0.05  # the assembly moved
    # Thrust through the collector's centre, off the assembly's centre of mass, turns it.
    assert abs(world.base_state()[3][2]) > 1e-3
    assert world.assembly_mass() == pytest.approx(world.base_mass() + 5.0)


def test_cargo_protrusion_is_how_far_cargo_sticks_out_of_the_collector():
    world = world_from(FIELD.replace("position: [0, 2.2, 0]", "position: [0, 1.9, 0]"))
    assert world.cargo_protrusion() == 0.0
    grabbed = grab_target(world, 2)
    assert grabbed.success
    # The gap to the target plus its diameter (0.5 m radius); the robot's bounding radius
    # grows by as much, and stays so while the assembly flies.
    assert world.cargo_protrusion() == pytest.approx(grabbed.gap + 1.0, abs=1e-6)
    assert world.robot_spec().radius == pytest.approx(0.5 + grabbed.gap + 1.0, abs=1e-6)
    for _ in range(100):
        world.step(WorldInputs(force=np.array([5.0, 0.0, 0.0])))
    (centre, radius), (cargo, cargo_radius) = world._assembly_spheres()
    assert np.linalg.norm(cargo - centre) + cargo_radius - radius == pytest.approx(
        world.cargo_protrusion(), abs=1e-4
    )


def test_release_only_at_the_drop_point():
    world = world_from(FIELD.replace("position: [0, 2.2, 0]", "position: [0, 1.9, 0]"))
    here = DropPoint(StaticMotion([0.0, 0.0, 0.0]), tolerance=0.5)
    assert release(world, here).reason == "nothing carried"
    assert grab_target(world, 2).success
    assert release(world, here).delivered == (2,)
    assert world.outputs()["delivered"] == 1 and world.outputs()["carried"] == 0
    assert world.cargo_protrusion() == 0.0 and world.robot_spec().radius == 0.5
    away = world_from(FIELD.replace("position: [0, 2.2, 0]", "position: [0, 1.9, 0]"))
    assert grab_target(away, 2).success
    refused = release(away, DropPoint(StaticMotion([9.0, 0.0, 0.0]), tolerance=0.5))
    assert refused.delivered == () and "from the drop point" in refused.reason
    assert away.cargo_protrusion() > 1.0  # still on board


def test_thrust_bookkeeping_matches_impulse_over_mass():
    world = world_from("""\
        world: {frame: geocentric, physics_step: 0.01, control_period: 0.1}
        robot: {mass: 100, propellant_mass: 10, max_force: 4, specific_impulse: 250}
        """)
    force = np.array([3.0, 4.0, 0.0])  # 5 N, clipped to 4 N along the same direction
    masses = []
    for _ in range(500):
        masses.append(world.assembly_mass())
        world.step(WorldInputs(force=force))
    applied = 4.0 * force / 5.0
    expected_velocity = sum(applied * 0.1 / m for m in masses)
    np.testing.assert_allclose(world.base_state()[1], expected_velocity, rtol=1e-9)
    assert world.delta_v == pytest.approx(sum(4.0 * 0.1 / m for m in masses), rel=1e-12)
    assert world.fuel_used == pytest.approx(4.0 * 50.0 / (250 * STANDARD_GRAVITY), rel=1e-12)
    assert world.base_mass() == pytest.approx(100 - world.fuel_used)


def test_thrust_stops_when_the_propellant_runs_out():
    world = world_from("""\
        world: {frame: geocentric}
        robot: {mass: 10, propellant_mass: 0.001, max_force: 10, specific_impulse: 100}
        """)
    for _ in range(20):
        world.step(WorldInputs(force=np.array([10.0, 0, 0])))
    burn_time = 0.001 * 100 * STANDARD_GRAVITY / 10.0  # 0.098 s of full thrust
    assert world.propellant == 0.0
    assert world.fuel_used == pytest.approx(0.001)
    assert world.base_state()[1][0] == pytest.approx(10.0 * burn_time / 10.0, rel=1e-3)


def test_free_collector_drifts_as_clohessy_wiltshire_says():
    world = world_from("""\
        world: {frame: lvlh, physics_step: 0.01, control_period: 0.1}
        robot: {initial: {position: [10, -5, 3], velocity: [0.01, 0.02, -0.005]}}
        """)
    for _ in range(6000):  # 600 s, a tenth of an orbit
        world.step()
    expected = ClohessyWiltshireMotion((10, -5, 3), (0.01, 0.02, -0.005), N).state_at(600.0)
    position, velocity, _, _ = world.base_state()
    drift = np.linalg.norm(expected[0] - np.array([10, -5, 3]))
    assert drift > 10.0  # the check would be empty if nothing moved
    np.testing.assert_allclose(position, expected[0], atol=2e-3)
    np.testing.assert_allclose(velocity, expected[1], atol=1e-5)


def test_collision_is_detected_once_when_contact_starts():
    world = world_from("""\
        world: {frame: geocentric, physics_step: 0.01, control_period: 0.1}
        robot: {radius: 0.5, initial: {position: [0, 0, 0], velocity: [1.0, 0, 0]}}
        obstacles:
          - {id: 7, radius: 0.5, motion: {type: static, position: [5, 0, 0]}}
          - {id: 8, radius: 0.5, motion: {type: cartesian, position: [2.5, 2, 0], velocity: [0, -1, 0]}}
        """)
    events = []
    for _ in range(60):
        events += world.step()
    assert [e.object_id for e in events] == [8, 7]
    first = events[0]
    # Contact starts when (t - 2.5)² + (2 - t)² = 1, at t = (9 - 7 ** 0.5) / 4.
    assert first.time == pytest.approx((9 - 7**0.5) / 4, abs=0.011)
    assert first.body == "collector" and 0 < first.penetration < 0.02
    assert events[1].time == pytest.approx(4.0, abs=0.011)
    assert world.nearest_obstacle_distance() < 0


def test_the_world_is_a_system_with_named_inputs_outputs_and_parameters():
    world = world_from(FIELD)
    assert world.parameters()["robot.max_force"] == 5.0
    assert world.parameters()["mean_motion"] == pytest.approx(N)
    outputs = world.outputs()
    assert {
        "position",
        "velocity",
        "attitude",
        "angular_velocity",
        "fuel_used",
        "delta_v",
        "carried",
        "delivered",
        "collisions",
        "nearest_obstacle_distance",
    } <= set(outputs)
    with pytest.raises(ValueError, match="no end effector"):
        world.end_effector()
    world.inputs = WorldInputs(disturbance_force=np.array([0.0, 0.0, 2.0]))
    world.step()
    assert world.outputs()["velocity"][2] > 0 and world.outputs()["fuel_used"] == 0.0


FLYER = """\
    world: {frame: geocentric, physics_step: 0.01, control_period: 0.1}
    robot: {mass: 100, propellant_mass: 10, max_force: 10, max_torque: 1, specific_impulse: 20,
            inertia: [2, 3, 4]}
    """


def spin_up(world: World, torque: np.ndarray, periods: int = 5) -> np.ndarray:
    """Angular velocity gained from rest under ``torque`` (world frame) over ``periods``."""
    before = world.base_state()[3].copy()
    for _ in range(periods):
        world.step(WorldInputs(torque=torque))
    return world.base_state()[3] - before


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_a_free_flyer_spins_up_at_its_given_inertia(axis):
    world = world_from(FLYER)
    torque = 0.5 * np.eye(3)[axis]
    # About a principal axis the rate grows linearly: ω = τ t / I (the sphere's I is 40).
    np.testing.assert_allclose(spin_up(world, torque), torque * 0.5 / [2, 3, 4], rtol=1e-9)
    np.testing.assert_allclose(world.robot_spec().inertia, np.diag([2.0, 3.0, 4.0]), rtol=1e-12)


def test_a_free_flyer_inertia_scales_with_its_mass_as_propellant_burns():
    world = world_from(FLYER)
    for _ in range(100):
        world.step(WorldInputs(force=np.array([10.0, 0.0, 0.0])))
    mass = world.base_mass()
    assert mass < 99.6  # half a kilogram burnt
    moments = np.array([2.0, 3.0, 4.0]) * mass / 100.0
    np.testing.assert_allclose(world.robot_spec().inertia, np.diag(moments), rtol=1e-12)
    torque = np.array([0.0, 0.0, 0.5])
    np.testing.assert_allclose(spin_up(world, torque), torque * 0.5 / moments, rtol=1e-9)


def test_the_spec_inertia_is_the_assembly_s_about_its_centre_of_mass():
    world = world_from("""\
        world: {frame: lvlh, physics_step: 0.01, control_period: 0.1}
        robot: {mass: 100, propellant_mass: 10, radius: 0.5, grab_distance: 2, capacity: 1,
                inertia: [2, 3, 4], initial: {attitude: [0.1, 0.2, 0.3, 0.9]}}
        mission:
          targets:
            - id: 1
              mass: 5
              shape: {type: box, half_extents: [0.2, 0.3, 0.4], orientation: [0.3, -0.1, 0.2, 0.9]}
              motion: {type: static, position: [0.4, 1.1, -0.3]}
        """)
    assert grab_target(world, 1).success
    base_position, _, base_attitude, _ = world.base_state()
    cargo_position = world.object_states()[0][0]
    base_rotation = Rotation.from_quat(base_attitude).as_matrix()
    box_rotation = Rotation.from_quat([0.3, -0.1, 0.2, 0.9]).as_matrix()
    sides = np.array([0.4, 0.6, 0.8]) ** 2
    box = 5.0 / 12.0 * np.diag([sides[1] + sides[2], sides[0] + sides[2], sides[0] + sides[1]])
    base_mass = world.base_mass()
    centre = (base_mass * base_position + 5.0 * cargo_position) / (base_mass + 5.0)

    def shifted(mass: float, offset: np.ndarray) -> np.ndarray:
        return mass * (offset @ offset * np.eye(3) - np.outer(offset, offset))

    expected = (
        base_rotation @ np.diag([2.0, 3.0, 4.0]) @ base_rotation.T
        + shifted(base_mass, base_position - centre)
        + box_rotation @ box @ box_rotation.T
        + shifted(5.0, cargo_position - centre)
    )
    expected = base_rotation.T @ expected @ base_rotation
    np.testing.assert_allclose(world.robot_spec().inertia, expected, rtol=1e-9, atol=0)
    assert world.robot_spec().mass == pytest.approx(base_mass + 5.0)


def swept_sphere_candidates(world: World, force: np.ndarray) -> np.ndarray:
    """The broad phase's rule written out: a free object is a candidate when the gap
    between its bounding sphere and the assembly's reach (each part's centre distance
    from the base's centre plus its radius) is within 1.5 times its own move over the
    period plus the assembly's sweep, plus 1 mm."""
    position, velocity, _, _ = world.base_state()
    client, field = world.client, world.field
    reaches = [world.robot.radius]
    for index, (body, _) in world._payload.held.items():
        centre = np.array(pb.getBasePositionAndOrientation(body, physicsClientId=client)[0])
        reaches.append(np.linalg.norm(centre - position) + field.radii[index])
    accel = (np.linalg.norm(force) + np.linalg.norm(world.inputs.disturbance_force)) / (
        world.assembly_mass()
    )
    accel += 2 * np.linalg.norm(cw_acceleration(N, position, velocity))
    period = world.control_period
    sweep = np.linalg.norm(velocity) * period + accel * period**2
    end = (round(world.time / world.physics_step) + world.steps_per_control) * world.physics_step
    free = np.flatnonzero(field.status == 0)
    now, later = field.free_states(world.time)[0][free], field.free_states(end)[0][free]
    moves = np.linalg.norm(later - now, axis=1)
    gaps = np.linalg.norm(now - position, axis=1) - max(reaches) - field.radii[free]
    return free[gaps <= 1.5 * (moves + sweep) + 1e-3]


BROAD_PHASE = """\
    world: {frame: lvlh, physics_step: 0.01, control_period: 0.1}
    robot: {radius: 0.5, grab_distance: 1.0, capacity: 1, initial: {velocity: [0.5, 0, 0]}}
    mission:
      targets:
        - {id: 1, radius: 0.5, mass: 5, motion: {type: static, position: [0, 1.9, 0]}}
        - {id: 2, radius: 0.5, mass: 5, motion: {type: static, position: [-2.8, 0, 0]}}
    obstacles:
      - {id: 7, radius: 0.5, motion: {type: static, position: [1.05, 0, 0]}}
      - {id: 8, radius: 0.5, motion: {type: cw, position: [0, 0, -1.1], velocity: [0, 0, 0.5]}}
    """


def test_the_broad_phase_keeps_every_free_object_the_swept_spheres_may_reach():
    # Obstacle 7 is in reach by the robot's sweep, 8 by its own move, target 2 only once
    # the robot carries target 1 (its reach grows to 2.4 m); a carried target is no
    # candidate.
    world = world_from(BROAD_PHASE)
    force = np.array([5.0, 1.0, 0.0])
    world.inputs = WorldInputs(force=force, disturbance_force=np.array([0.0, 0.0, 0.3]))
    world._update_broad_phase(force)
    np.testing.assert_array_equal(world._candidates, [2, 3])
    np.testing.assert_array_equal(world._candidates, swept_sphere_candidates(world, force))
    assert grab_target(world, 1).success
    for _ in range(2):
        world.step()
        world._update_broad_phase(force)
        np.testing.assert_array_equal(world._candidates, [1, 2, 3])
        np.testing.assert_array_equal(world._candidates, swept_sphere_candidates(world, force))


def test_the_nearest_obstacle_gap_is_the_least_sphere_to_sphere_gap():
    world = world_from(FIELD)
    for _ in range(20):
        world.step(WorldInputs(force=np.array([-5.0, 1.0, 0.0])))
    position = world.base_state()[0]
    obstacles = np.flatnonzero(~world.field.is_target)
    centres = world.object_states()[0][obstacles]
    gaps = np.linalg.norm(centres - position, axis=1) - world.field.radii[obstacles] - 0.5
    assert world.nearest_obstacle_distance() == gaps.min()


def test_the_nearest_obstacle_gap_counts_the_cargo():
    # Target 1 (0.5 m) carried beside the collector passes nearer the obstacle at x = 2.
    text = BROAD_PHASE.replace("[1.05, 0, 0]", "[2.0, 2.2, 0]").replace(
        "[0, 0, -1.1]", "[0, 0, -4]"
    )
    world = world_from(text)
    assert grab_target(world, 1).success
    for _ in range(3):
        world.step()
        parts = [(world.base_state()[0], 0.5), (world.object_states()[0][0], 0.5)]
        obstacles = [2, 3]
        centres = world.object_states()[0][obstacles]
        gaps = [
            np.linalg.norm(centres - centre, axis=1) - world.field.radii[obstacles] - radius
            for centre, radius in parts
        ]
        assert np.argmin(np.min(gaps, axis=1)) == 1  # the cargo is the nearer part
        assert world.nearest_obstacle_distance() == np.min(gaps)
