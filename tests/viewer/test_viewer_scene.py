"""The scene a run's page replays, checked against the run's records and dcsim's models."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from dcsim.api import Shape, ShapeKind
from dcsim.registry.discovery import PluginRegistry
from dcsim.report.viewer.meshes import shape_mesh
from dcsim.report.viewer.page import scene_json
from dcsim.report.viewer.records import read_run
from dcsim.report.viewer.scene import build_scene, frame_rows
from dcsim.run.loop import Runner
from dcsim.run.setup import setup_run
from dcsim.world.objects import build_objects
from tests.conftest import CAPTURE, REPO, SHARES_DEFAULT_RUN, short_capture

QUARTER_TURN_X = [0.5**0.5, 0.0, 0.0, 0.5**0.5]


def area(mesh) -> float:
    corners = mesh.vertices[mesh.triangles]
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    return 0.5 * float(np.linalg.norm(cross, axis=1).sum())


def test_frames_are_at_most_the_limit_and_keep_the_first_and_last_rows():
    rows = frame_rows(7242, 600)
    assert len(rows) == 600 and rows[0] == 0 and rows[-1] == 7241
    assert np.all(np.diff(rows) > 0)
    assert frame_rows(5, 600).tolist() == [0, 1, 2, 3, 4]
    assert frame_rows(1, 600).tolist() == [0]


@pytest.mark.parametrize(
    "shape, surface, tolerance",
    [
        (Shape(ShapeKind.BOX, half_extents=[1.0, 2.0, 3.0]), 8 * (2 + 6 + 3), 1e-12),
        (Shape(ShapeKind.SPHERE, radius=2.0), 4 * np.pi * 4.0, 0.02),
        (
            Shape(ShapeKind.CYLINDER, radius=0.5, height=6.0, orientation=QUARTER_TURN_X),
            2 * np.pi * 0.5 * 6.0 + 2 * np.pi * 0.25,
            0.01,
        ),
    ],
)
def test_a_mesh_covers_its_shape_s_surface(shape, surface, tolerance):
    mesh = shape_mesh(shape)
    assert area(mesh) == pytest.approx(surface, rel=tolerance)
    assert np.max(np.linalg.norm(mesh.vertices, axis=1)) == pytest.approx(shape.bounding_radius)


def test_a_turned_cylinder_s_mesh_lies_along_its_axis():
    lying = shape_mesh(
        Shape(ShapeKind.CYLINDER, radius=0.5, height=6.0, orientation=QUARTER_TURN_X)
    )
    extent = lying.vertices.max(axis=0) - lying.vertices.min(axis=0)
    np.testing.assert_allclose(extent, [1.0, 6.0, 1.0], atol=1e-3)


# ---------------------------------------------------------------- the default run


@pytest.fixture(scope="module")
def default_scene(default_run):
    _, _, out = default_run
    records = read_run(out)
    return records, build_scene(records)


def group(scene, name):
    return next(g for g in scene["bodies"] if g["trace"]["name"] == name)


def readout(scene, label):
    return next(r["values"] for r in scene["readouts"] if r["label"] == label)


@SHARES_DEFAULT_RUN
def test_the_default_run_s_scene_has_at_most_600_frames_over_the_whole_run(default_scene):
    records, scene = default_scene
    times = scene["times"]
    assert len(times) == 600
    assert times[0] == records.telemetry["time"][0] and times[-1] == records.telemetry["time"][-1]
    assert readout(scene, "time")[-1] == f"{times[-1]:.2f} s"


@SHARES_DEFAULT_RUN
def test_free_objects_are_where_their_motion_models_put_them(default_scene):
    records, scene = default_scene
    grabs = {e["target"]: e["t"] for e in records.events if e["event"] == "grab" and e["success"]}
    members = {m["label"]: m for g in scene["bodies"] for m in g["members"]}
    times = scene["times"]
    for obj in build_objects(records.scenario):
        prefix = "T" if obj.kind.value == "target" else "O"
        member = members[f"{prefix}{obj.id}"]
        free = times < grabs.get(obj.id, np.inf)
        assert free.sum() > 0
        expected = np.array([obj.motion.position_at(t) for t in times[free]])
        np.testing.assert_allclose(member["positions"][free], expected, atol=1e-9)


@SHARES_DEFAULT_RUN
def test_a_grabbed_target_rides_on_the_base_until_it_is_delivered(default_scene):
    records, scene = default_scene
    robot = group(scene, "robot")["members"][0]
    targets = {m["label"]: m for m in group(scene, "targets")["members"]}
    times = scene["times"]
    for event in (e for e in records.events if e["event"] == "grab" and e["success"]):
        target = targets[f"T{event['target']}"]
        delivered = next(
            e["t"]
            for e in records.events
            if e["event"] == "release" and event["target"] in e["delivered"]
        )
        carried = (times >= event["t"]) & (times < delivered)
        assert carried.sum() > 5
        base = Rotation.from_quat(robot["turns"][carried])
        offsets = base.inv().apply(target["positions"][carried] - robot["positions"][carried])
        np.testing.assert_allclose(offsets, np.broadcast_to(offsets[0], offsets.shape), atol=1e-9)
        gap = np.linalg.norm(offsets[0]) - records.scenario.robot.radius - 0.3
        assert 0.0 < gap <= records.scenario.robot.grab_distance
        turns = Rotation.from_quat(target["turns"][carried])
        since_first = base * base[0].inv()
        np.testing.assert_allclose(
            (turns * turns[0].inv()).as_matrix(), since_first.as_matrix(), atol=1e-9
        )
        assert target["hidden"][times >= delivered].all()
        assert not target["hidden"][times < delivered].any()


@SHARES_DEFAULT_RUN
def test_the_readouts_count_captures_and_deliveries_and_the_plan_starts_at_the_robot(default_scene):
    records, scene = default_scene
    assert readout(scene, "captured")[0] == "0 of 4" and readout(scene, "captured")[-1] == "4 of 4"
    assert readout(scene, "delivered")[-1] == "4 of 4"
    assert readout(scene, "mode")[0] == records.telemetry["mode"][0]
    fuel = records.telemetry["fuel_used"][-1]
    assert readout(scene, "propellant used")[-1] == f"{fuel:.3f} of 10 kg"
    (plans,) = scene["stages"]
    first = next(e for e in records.events if e["event"] == "plan")
    stage = plans["stages"][0]
    assert stage["t"] == first["t"]
    assert len(stage["points"]) == 1 + len(first["tasks"]) + len(first["drops"])
    row = np.searchsorted(records.telemetry["time"], first["t"], side="right") - 1
    start = [records.telemetry[axis][row] for axis in "xyz"]
    np.testing.assert_allclose(stage["points"][0], start)
    assert all(not e["text"].startswith("mode") for e in scene["events"])


@SHARES_DEFAULT_RUN
def test_the_work_area_holds_the_robot_and_every_object_and_the_scene_the_beacons(default_scene):
    records, scene = default_scene
    lower, upper = scene["extent"]["work"]
    for g in scene["bodies"]:
        for member in g["members"]:
            assert np.all(member["positions"] >= lower) and np.all(member["positions"] <= upper)
    beacons = np.array(records.scenario.beacons.positions)
    lower, upper = scene["extent"]["scene"]
    assert np.all(beacons >= lower) and np.all(beacons <= upper)
    names = {t["name"] for t in scene["static"]}
    assert {"beacons", "flown path (whole run)"} <= names


@SHARES_DEFAULT_RUN
def test_the_scene_s_json_is_plain_rounded_and_safe_inside_a_script(default_scene):
    _, scene = default_scene
    text = scene_json(scene)
    assert "<" not in text and "NaN" not in text and "Infinity" not in text
    data = json.loads(text)
    assert len(data["times"]) == 600
    assert data["bodies"][0]["members"][0]["positions"][-1] == pytest.approx(
        scene["bodies"][0]["members"][0]["positions"][-1], abs=1e-4
    )


# ---------------------------------------------------------------- a manipulator, a transfer


def run_into(out, scenario, *overrides):
    Runner(setup_run(scenario, overrides, registry=PluginRegistry.discover()), out).run()
    return read_run(out)


@pytest.fixture(scope="module")
def reach_records(tmp_path_factory):
    """The manipulator thesis's reach, its first 0.5 s."""
    out = tmp_path_factory.mktemp("reach")
    return run_into(out, REPO / "scenarios" / "space_manipulator_reach.yaml", "world.duration=0.5")


def test_a_manipulator_s_arm_runs_from_its_base_through_its_joints_to_its_end_effector(
    reach_records,
):
    scene = build_scene(reach_records, max_frames=20)
    (arm,) = [line["frames"] for line in scene["polylines"] if line["trace"]["name"] == "arm links"]
    rows = frame_rows(len(reach_records.telemetry["time"]), 20)
    telemetry = reach_records.telemetry
    robot = reach_records.scenario.robot
    assert arm.shape == (len(rows), len(robot.links) + 2, 3)
    base = np.column_stack([telemetry[a] for a in "xyz"])[rows]
    end_effector = np.column_stack([telemetry[f"ee_{a}"] for a in "xyz"])[rows]
    np.testing.assert_allclose(arm[:, 0], base, atol=1e-12)
    np.testing.assert_allclose(arm[:, -1], end_effector, atol=1e-9)
    attitude = Rotation.from_quat(
        np.column_stack([telemetry[q] for q in ("qx", "qy", "qz", "qw")])[rows]
    )
    np.testing.assert_allclose(arm[:, 1] - base, attitude.apply(robot.mount), atol=1e-9)
    lengths = np.linalg.norm(np.diff(arm[:, 1:], axis=1), axis=2)
    np.testing.assert_allclose(lengths, lengths[:1].repeat(len(rows), 0), atol=1e-9)
    assert np.ptp(arm[:, -1], axis=0).max() > 1e-4  # the end effector moved
    box = group(scene, "robot")["members"][0]["vertices"]
    np.testing.assert_allclose(box.max(axis=0), 0.5 * np.asarray(robot.size))
    names = {t["name"] for t in scene["static"]}
    assert {"reach target", "planned end-effector path"} <= names
    assert "base speed" in {r["label"] for r in scene["readouts"]}


@pytest.fixture(scope="module")
def capture_records(tmp_path_factory):
    """The shipped capture, cut short: grasped, latched and detumbled in 21 s."""
    out = tmp_path_factory.mktemp("capture")
    overrides = [f"{k}={json.dumps(v)}" for k, v in short_capture(0.5, 22.0).items()]
    return run_into(out, CAPTURE, *overrides)


def test_a_capture_shows_the_tumbling_body_as_it_turned_and_the_arm(capture_records):
    scene = build_scene(capture_records, max_frames=40)
    rows = frame_rows(len(capture_records.telemetry["time"]), 40)
    telemetry = capture_records.telemetry
    (body,) = group(scene, "targets")["members"]
    assert body["label"] == "T1"
    centre = np.column_stack([telemetry[f"target_{a}"] for a in "xyz"])[rows]
    attitude = np.column_stack([telemetry[f"target_q{a}"] for a in "xyzw"])[rows]
    np.testing.assert_allclose(body["positions"], centre, atol=1e-12)
    np.testing.assert_allclose(body["turns"], attitude, atol=1e-12)
    turned = Rotation.from_quat(attitude[-1]) * Rotation.from_quat(attitude[0]).inv()
    assert turned.magnitude() > np.radians(10.0)  # it tumbled while the run went on
    (arm,) = [line["frames"] for line in scene["polylines"] if line["trace"]["name"] == "arm links"]
    assert arm.shape[0] == len(rows)
    assert "reach target" not in {t["name"] for t in scene["static"]}


@pytest.fixture(scope="module")
def transfer_records(tmp_path_factory):
    """The Boeing paper's station inspection, flown to its goal 1."""
    out = tmp_path_factory.mktemp("transfer")
    return run_into(
        out,
        REPO / "scenarios" / "station_inspection.yaml",
        "mission.goal.position=[1.8288,3.9624,0.0]",
    )


def test_a_transfer_shows_its_planned_trajectory_goal_and_shaped_obstacles(transfer_records):
    scene = build_scene(transfer_records)
    static = {t["name"]: t for t in scene["static"]}
    planned = static["planned trajectory"]
    assert len(planned["x"]) == len(transfer_records.planned) > 1
    np.testing.assert_allclose(planned["x"], transfer_records.planned[:, 0])
    goal = static["goal region"]
    centre = np.mean([goal["x"], goal["y"], goal["z"]], axis=1)
    np.testing.assert_allclose(centre, [1.8288, 3.9624, 0.0], atol=0.05)
    assert "reference" in static
    obstacles = group(scene, "obstacles")
    assert obstacles["trace"]["flatshading"] is True  # boxes and cylinders
    assert len(obstacles["members"]) == len(transfer_records.scenario.obstacles)
    assert {"distance to goal", "tracking error"} <= {r["label"] for r in scene["readouts"]}
    assert not scene["stages"]


# ---------------------------------------------------------------- a free flyer on hardware


@pytest.fixture(scope="module")
def hardware_records(tmp_path_factory):
    """default_hardware's first 30 s: twelve thrusters fire, four wheels spin."""
    out = tmp_path_factory.mktemp("hardware")
    return run_into(out, REPO / "scenarios" / "default_hardware.yaml", "world.duration=30")


def test_the_scene_carries_the_thrusters_geometry_and_every_firing_between_frames(
    hardware_records,
):
    scene = build_scene(hardware_records, max_frames=40)
    thrusters = scene["thrusters"]
    specs = hardware_records.scenario.robot.actuators.thrusters
    assert len(specs) == 12
    np.testing.assert_array_equal(thrusters["positions"], [t.position for t in specs])
    directions = np.array([t.direction for t in specs], dtype=float)
    np.testing.assert_allclose(thrusters["directions"], directions)  # unit already
    telemetry = hardware_records.telemetry
    duty = np.column_stack([telemetry[f"duty_{i}"] for i in range(1, 13)])
    rows = frame_rows(len(telemetry["time"]), 40)
    assert thrusters["duty"].shape == (len(rows), 12)
    previous = -1
    for frame, row in enumerate(rows):  # the mean over the rows since the previous frame
        np.testing.assert_allclose(thrusters["duty"][frame], duty[previous + 1 : row + 1].mean(0))
        previous = row
    counts = np.diff(np.concatenate([[-1], rows]))
    np.testing.assert_allclose((thrusters["duty"] * counts[:, None]).sum(0), duty.sum(0))
    assert duty.max() > 0.3 and thrusters["duty"][0].max() == 0.0  # none fired before t = 0
    firing = readout(scene, "thrusters firing")
    for frame in range(len(rows)):
        fired = [str(n + 1) for n in np.flatnonzero(thrusters["duty"][frame] > 0)]
        assert firing[frame] == (", ".join(fired) or "none")
    error = readout(scene, "attitude error")
    assert error[-1] == f"{np.degrees(telemetry['attitude_error'][rows[-1]]):.3f} deg"


@SHARES_DEFAULT_RUN
def test_a_free_flyer_without_thrusters_has_no_plumes(default_scene):
    _, scene = default_scene
    assert scene["thrusters"] is None
    assert "thrusters firing" not in {r["label"] for r in scene["readouts"]}
