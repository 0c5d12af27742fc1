"""Boxes and cylinders in the world: gaps, contacts and grabs from the true shape."""

from __future__ import annotations

import textwrap

import numpy as np
import pytest

from dcsim.api import Shape, ShapeKind
from dcsim.missions.debris.services import grab
from dcsim.scenario import ScenarioDocument, validate
from dcsim.world import World, WorldInputs
from dcsim.world.bodies import create_body
from dcsim.world.pybullet_client import pb

SQRT_HALF = 0.5**0.5
CURVED = 1e-6  # m: PyBullet's closest points on a cylinder's curved side


def world_with(obstacle_shape: str, collector_at, velocity=(0, 0, 0), grab_distance=1.0) -> World:
    """A geocentric (force-free) world: a 0.5 m collector and one static obstacle at the origin."""
    text = f"""\
        world: {{frame: geocentric, physics_step: 0.01, control_period: 0.1}}
        robot: {{radius: 0.5, grab_distance: {grab_distance},
                initial: {{position: {list(collector_at)}, velocity: {list(velocity)}}}}}
        obstacles:
          - {{id: 7, shape: {obstacle_shape}, motion: {{type: static, position: [0, 0, 0]}}}}
        """
    scenario = validate(ScenarioDocument.from_text(textwrap.dedent(text), "shapes.yaml"))
    return World(scenario, np.random.default_rng(0))


def fly(world: World, periods: int = 3) -> list:
    events = []
    for _ in range(periods):
        events += world.step(WorldInputs())
    return events


BOX = "{type: box, half_extents: [0.5, 3.0, 2.0]}"  # bounding radius 3.64 m


@pytest.mark.parametrize(
    ("at", "gap"),
    [
        ([2.0, 0.0, 0.0], 1.0),  # facing the +x face, 2 m inside the bounding sphere
        ([0.0, 0.0, 3.0], 0.5),  # facing the +z face
        ([0.9, 3.4, 0.0], 0.4 * 2.0**0.5 - 0.5),  # beyond the edge x = 0.5, y = 3
    ],
)
def test_collector_inside_a_box_bounding_sphere_but_clear_of_it(at, gap):
    world = world_with(BOX, at)
    assert np.linalg.norm(at) - 0.5 < world.field.radii[0]  # within the bounding sphere
    assert world.nearest_obstacle_distance() == pytest.approx(gap, abs=1e-12)
    assert fly(world) == [] and world.collisions == []


def test_collector_touching_a_box_face_collides_with_its_penetration():
    world = world_with(BOX, [0.95, 1.0, 0.0])  # 0.05 m into the +x face
    assert world.nearest_obstacle_distance() == pytest.approx(-0.05, abs=1e-12)
    (event,) = fly(world)
    assert event.object_id == 7 and event.body == "collector"
    assert event.penetration == pytest.approx(0.05, abs=1e-12)


CYLINDER = "{type: cylinder, radius: 1.0, height: 6.0}"  # axis along z, bounding radius 3.16 m


@pytest.mark.parametrize(
    ("at", "gap", "tolerance"),
    [
        ([0.0, 0.0, 3.6], 0.1, 1e-12),  # along the axis, beyond the end cap
        ([1.2, 1.2, 2.0], 2**0.5 * 1.2 - 1.5, CURVED),  # across the axis, beside the side
        ([1.45, 0.0, 3.25], np.hypot(0.45, 0.25) - 0.5, CURVED),  # off the rim
    ],
)
def test_collector_clear_of_a_cylinder_inside_its_bounding_sphere(at, gap, tolerance):
    world = world_with(CYLINDER, at)
    assert np.linalg.norm(at) - 0.5 < world.field.radii[0]
    assert world.nearest_obstacle_distance() == pytest.approx(gap, abs=tolerance)
    assert fly(world) == []


@pytest.mark.parametrize(
    ("at", "depth", "tolerance"),
    [([0.0, 0.0, 3.4], 0.1, 1e-12), ([1.4, 0.0, -2.0], 0.1, CURVED)],
    ids=["end cap", "side"],
)
def test_collector_touching_a_cylinder_collides(at, depth, tolerance):
    world = world_with(CYLINDER, at)
    (event,) = fly(world)
    assert event.penetration == pytest.approx(depth, abs=tolerance)


def test_a_turned_box_is_measured_in_its_own_axes():
    long_along_x = "{type: box, half_extents: [3.0, 0.5, 0.5]}"
    eighth_turn = f"{{type: box, half_extents: [3.0, 0.5, 0.5], orientation: [0, 0, {np.sin(np.pi / 8)}, {np.cos(np.pi / 8)}]}}"
    quarter_turn = f"{{type: box, half_extents: [3.0, 0.5, 0.5], orientation: [0, 0, {SQRT_HALF}, {SQRT_HALF}]}}"
    at = [0.0, 4.0, 0.0]
    assert world_with(long_along_x, at).nearest_obstacle_distance() == pytest.approx(3.0)
    # 45° about z: the point is (4/√2, 4/√2) in the box's axes, beyond its y face.
    turned = world_with(eighth_turn, at)
    assert turned.nearest_obstacle_distance() == pytest.approx(4 * SQRT_HALF - 1.0, abs=1e-12)
    # 90° about z: the long side now points at the collector, 3 m + 0.5 m from its centre.
    upright = world_with(quarter_turn, [0.0, 3.4, 0.0])
    assert upright.nearest_obstacle_distance() == pytest.approx(-0.1, abs=1e-12)
    assert [e.penetration for e in fly(upright)] == [pytest.approx(0.1, abs=1e-12)]
    assert fly(world_with(long_along_x, [0.0, 3.4, 0.0])) == []


def test_a_moving_box_is_hit_when_its_face_arrives_not_its_bounding_sphere():
    text = """\
        world: {frame: geocentric, physics_step: 0.01, control_period: 0.1}
        robot: {radius: 0.5}
        obstacles:
          - id: 8
            shape: {type: box, half_extents: [0.5, 2.0, 2.0]}
            motion: {type: cartesian, position: [5.0, 0.0, 0.0], velocity: [-1.0, 0.0, 0.0]}
        """
    world = World(
        validate(ScenarioDocument.from_text(textwrap.dedent(text), "moving.yaml")),
        np.random.default_rng(0),
    )
    (event,) = fly(world, 50)
    # The face x = 5 - t - 0.5 meets the collector's surface x = 0.5 at t = 4 s; the
    # bounding sphere (2.87 m) would have touched at t = 1.63 s.
    assert event.time == pytest.approx(4.0, abs=0.011)


def test_grab_gap_and_cargo_use_the_target_shape():
    text = """\
        world: {frame: geocentric, physics_step: 0.01, control_period: 0.1}
        robot: {radius: 0.5, grab_distance: 1.0, capacity: 1}
        mission:
          targets:
            - id: 1
              shape: {type: box, half_extents: [1.0, 0.2, 0.2], orientation: [0, 1, 0, 1]}  # long along z
              motion: {type: static, position: [1.2, 0, 0]}
        obstacles:
          - {id: 2, radius: 0.5, motion: {type: static, position: [1.2, 0, 3.0]}}
        """
    world = World(
        validate(ScenarioDocument.from_text(textwrap.dedent(text), "grab.yaml")),
        np.random.default_rng(0),
    )
    before = world.nearest_obstacle_distance()  # the collector alone
    assert before == pytest.approx(np.hypot(1.2, 3.0) - 1.0, abs=1e-12)
    grabbed = grab(world, 1, world.robot.capacity, world.robot.grab_distance)
    assert grabbed.success and grabbed.gap == pytest.approx(0.5, abs=1e-12)  # face, not sphere
    # The carried box's top face is 1.5 m below the obstacle (its bounding sphere: 1.46 m),
    # and stays so: it is held as it was turned.
    assert world.nearest_obstacle_distance() == pytest.approx(1.5, abs=1e-9)
    fly(world, 20)
    assert world.nearest_obstacle_distance() == pytest.approx(1.5, abs=1e-6)


def test_tracks_carry_the_object_shape_built_once():
    world = world_with(
        f"{{type: cylinder, radius: 1.0, height: 6.0, orientation: [{SQRT_HALF}, 0, 0, {SQRT_HALF}]}}",
        [5.0, 0.0, 0.0],
    )
    (track,) = world.object_tracks()
    shape = track.shape
    assert (shape.kind, shape.radius, shape.height) == (ShapeKind.CYLINDER, 1.0, 6.0)
    np.testing.assert_allclose(shape.orientation, [SQRT_HALF, 0, 0, SQRT_HALF], rtol=1e-15)
    assert track.radius == pytest.approx(10**0.5)  # the bounding sphere's
    world.step()
    assert world.object_tracks()[0].shape is track.shape


def test_nearest_gap_among_shapes_is_not_the_nearest_bounding_sphere():
    text = """\
        world: {frame: geocentric}
        robot: {radius: 0.5}
        obstacles:
          - {id: 1, shape: {type: box, half_extents: [0.2, 4.0, 0.2]}, motion: {type: static, position: [2.5, 0, 0]}}
          - {id: 2, shape: {type: cylinder, radius: 0.5, height: 1.0}, motion: {type: static, position: [0, 2.0, 0]}}
          - {id: 3, radius: 0.5, motion: {type: static, position: [0, -3.0, 0]}}
        """
    world = World(
        validate(ScenarioDocument.from_text(textwrap.dedent(text), "mixed.yaml")),
        np.random.default_rng(0),
    )
    # Bounding gaps: box -2.0 m, cylinder 0.79 m, sphere 2.0 m; true gaps 1.8, 1.0 and 2.0 m.
    assert world.nearest_obstacle_distance() == pytest.approx(1.0, abs=CURVED)


@pytest.mark.parametrize(
    ("shape", "moments"),
    [
        (Shape(ShapeKind.SPHERE, radius=0.7), [0.588, 0.588, 0.588]),  # 2/5 m r²
        (Shape(ShapeKind.BOX, half_extents=[0.2, 0.3, 0.5]), [0.34, 0.29, 0.13]),  # m/12 (b² + c²)
        # across m (3 r² + h²) / 12, about the axis m r² / 2
        (Shape(ShapeKind.CYLINDER, radius=0.4, height=1.5), [0.6825, 0.6825, 0.24]),
    ],
    ids=lambda v: getattr(v, "kind", ""),
)
def test_a_shape_s_uniform_solid_inertia_is_pybullet_s(shape, moments):
    client = pb.connect(pb.DIRECT)
    try:
        body = create_body(client, shape, 3.0, np.zeros(3), False)
        held = pb.getDynamicsInfo(body, -1, physicsClientId=client)[2]
    finally:
        pb.disconnect(client)
    np.testing.assert_allclose(shape.moments_of_inertia(3.0), moments, rtol=1e-12)
    np.testing.assert_allclose(held, moments, rtol=1e-12)


def test_objects_of_one_shape_share_one_static_body_and_keep_their_own_gaps():
    # Two unit spheres, two boxes of one size turned differently, a thinner box: three
    # static bodies besides the collector's (PyBullet steps every body, even a static one).
    text = """\
        world: {frame: geocentric, physics_step: 0.01, control_period: 0.1}
        robot: {radius: 0.5}
        obstacles:
          - {id: 1, radius: 1.0, motion: {type: static, position: [3, 0, 0]}}
          - {id: 2, radius: 1.0, motion: {type: static, position: [0, -4, 0]}}
          - {id: 3, shape: {type: box, half_extents: [0.5, 1, 1]}, motion: {type: static, position: [0, 0, 5]}}
          - id: 4
            shape: {type: box, half_extents: [0.5, 1, 1], orientation: [0, 0.7071068, 0, 0.7071068]}
            motion: {type: static, position: [0, 0, -6]}
          - {id: 5, shape: {type: box, half_extents: [0.25, 1, 1]}, motion: {type: static, position: [7, 0, 0]}}
        """
    scenario = validate(ScenarioDocument.from_text(textwrap.dedent(text), "shared.yaml"))
    world = World(scenario, np.random.default_rng(0))
    assert pb.getNumBodies(physicsClientId=world.client) == 1 + 3
    gaps = [world.surface_gap(i, 10.0) for i in (1, 2, 3, 4, 5)]
    # The turned box shows the collector its 0.5 m half extent along z, the other its 1 m.
    np.testing.assert_allclose(gaps, [1.5, 2.5, 3.5, 5.0, 6.25], atol=1e-9)
