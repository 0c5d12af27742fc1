"""The capture world checked from PyBullet's own body states: a free target tumbles
torque-free, the pads' friction holds a bar up to its limit, contact keeps the
system's momentum, the recorded impulse is the body's momentum change, and the latch
holds the body to the palm."""

from __future__ import annotations

import copy
from typing import Any

import numpy as np
import pytest
import yaml
from scipy.spatial.transform import Rotation

from dcsim.missions.capture.settings import CaptureMissionSection
from dcsim.scenario.model import scenario_model
from dcsim.world import World, WorldInputs
from dcsim.world.pybullet_client import pb
from tests.conftest import REPO
from tests.test_torque_free import axisymmetric_motion, error_angle

SHIPPED = yaml.safe_load((REPO / "scenarios" / "debris_capture.yaml").read_text())
FAR = [30.0, 0.0, 0.0]  # m: a target position the arm cannot reach
OBLIQUE_DEG_S = [3.0, 0.0, 4.0]  # deg/s, body axes: 5 deg/s between a transverse axis and the axis


def capture_world(
    physics_step: float = 5e-4,
    control_period: float = 0.01,
    sensors: dict[str, Any] | None = None,
    **target: Any,
) -> World:
    """A world of the shipped capture with the target's keys replaced by ``target`` and
    its ``sensors`` section by ``sensors`` (ideal sensing when None)."""
    data = copy.deepcopy(SHIPPED)
    data["world"].update(physics_step=physics_step, control_period=control_period)
    data["mission"]["target"].update(target)
    data.pop("sensors", None)
    if sensors is not None:
        data["sensors"] = sensors
    scenario = scenario_model(CaptureMissionSection).model_validate(data)
    return World(scenario, np.random.default_rng(0))


def matrix(quaternion: Any) -> np.ndarray:
    """Rotation matrix of a quaternion [x, y, z, w]."""
    return Rotation.from_quat(quaternion).as_matrix()


def grasp_pose(physics_step: float = 5e-4) -> tuple[np.ndarray, np.ndarray]:
    """Where the target must be for its bar to lie between the open pads at rest: the
    centre of mass (m) and the attitude [x, y, z, w] that put the bar's centre midway
    between the pads, the bar along z_n and the approach axis along -x_n."""
    with capture_world(physics_step, position=FAR) as w:
        palm = pb.getLinkState(
            w.robot_id, w.capture.gripper.palm, computeForwardKinematics=1, physicsClientId=w.client
        )
        spec = w.robot.gripper
    axes = matrix(palm[5])
    centre = np.asarray(palm[4]) + (spec.reach - 0.5 * spec.palm_size[0]) * axes[:, 0]
    fixture = SHIPPED["mission"]["target"]["fixture"]
    # the shipped bar is along body z, its approach axis body x
    assert fixture["bar_axis"] == [0.0, 0.0, 1.0] and fixture["approach_axis"] == [1.0, 0.0, 0.0]
    body = np.column_stack((-axes[:, 0], -axes[:, 1], axes[:, 2]))
    return centre - body @ np.asarray(fixture["position"]), Rotation.from_matrix(body).as_quat()


def gripped_world(rate_deg_s: Any = (0.0, 0.0, 0.0), **kwargs: float) -> World:
    """A world with the shipped target's bar between the open pads."""
    position, attitude = grasp_pose(kwargs.get("physics_step", 5e-4))
    return capture_world(
        position=position.tolist(),
        attitude=attitude.tolist(),
        angular_velocity_deg_s=list(rate_deg_s),
        **kwargs,
    )


def parts(w: World) -> list[tuple[int, int]]:
    """Every PyBullet body and link with mass: the base, each arm and gripper link, the
    target."""
    links = range(-1, pb.getNumJoints(w.robot_id, physicsClientId=w.client))
    return [(w.robot_id, link) for link in links] + [(w.capture.target.body, -1)]


def part_state(w: World, body: int, link: int) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass (kg), centre of mass (m) and momentum about it, linear (N·s) and angular
    (N·m·s) stacked (6,), of one part, from PyBullet's body state."""
    client = w.client
    mass, _, moments, *_ = pb.getDynamicsInfo(body, link, physicsClientId=client)
    if link == -1:
        position, attitude = pb.getBasePositionAndOrientation(body, physicsClientId=client)
        velocity, angular = pb.getBaseVelocity(body, physicsClientId=client)
    else:
        state = pb.getLinkState(
            body, link, computeLinkVelocity=1, computeForwardKinematics=1, physicsClientId=client
        )
        position, attitude, velocity, angular = state[0], state[1], state[6], state[7]
    rotation = matrix(attitude)
    spin = rotation @ np.diag(moments) @ rotation.T @ np.asarray(angular)
    return mass, np.asarray(position), np.r_[mass * np.asarray(velocity), spin]


def momentum(w: World, about: np.ndarray | None = None) -> np.ndarray:
    """Total linear (N·s) and angular momentum (N·m·s) of the base, the arm, the gripper
    and the target, (6,), about ``about`` (m; None: the system's centre of mass)."""
    states = [part_state(w, body, link) for body, link in parts(w)]
    if about is None:
        masses = np.array([mass for mass, _, _ in states])
        centres = np.array([centre for _, centre, _ in states])
        about = masses @ centres / masses.sum()
    total = np.zeros(6)
    for _, centre, own in states:
        total += np.r_[own[:3], own[3:] + np.cross(centre - about, own[:3])]
    return total


def close_until_held(w: World, settle: float = 0.0) -> None:
    """Close the pads and step until both press with about the grip force, then
    ``settle`` s more."""
    rig = w.capture
    rig.gripper.command(True)
    grip = w.robot.gripper.grip_force
    while rig.period.last is None or rig.period.last.normal.min() < 0.9 * grip:
        assert w.time < 2.0, "the pads did not close on the bar"
        w.step(WorldInputs())
    for _ in range(round(settle / w.control_period)):
        w.step(WorldInputs())


# ---------------------------------------------------------------- torque-free tumble
def test_a_free_axisymmetric_target_follows_the_closed_form():
    """Read back from PyBullet over 60 s (120,000 physics steps, 7-9 s of wall time here),
    the untouched cylinder's attitude is the closed form's for an axisymmetric
    torque-free body to 1e-6 rad."""
    rate = np.radians(OBLIQUE_DEG_S)
    with capture_world(position=FAR, angular_velocity_deg_s=OBLIQUE_DEG_S) as w:
        rig = w.capture
        inertia = rig.target.inertia
        transverse, axial = inertia[0, 0], inertia[2, 2]
        assert transverse == inertia[1, 1] and transverse != axial
        attitude0 = Rotation.from_quat(rig.target_state().attitude)
        motion = axisymmetric_motion(transverse, axial, attitude0, attitude0.apply(rate))
        worst = 0.0
        while w.time < 60.0 - 1e-9:
            w.step(WorldInputs())
            reference, _ = motion(w.time)
            worst = max(worst, error_angle(reference, rig.target_state().attitude))
        assert rig.target.free
    assert worst <= 1e-6


TRIAXIAL = [[4000.0, 200.0, -100.0], [200.0, 5000.0, 300.0], [-100.0, 300.0, 2000.0]]  # kg·m²


def test_a_free_triaxial_target_keeps_its_angular_momentum():
    """A target given a full inertia tensor: its angular momentum computed from
    PyBullet's body (principal moments, orientation, rates) is the scenario's initial
    one and stays so to 1e-9 relative over 20 s."""
    attitude = Rotation.from_rotvec([0.3, -0.5, 0.2])
    with capture_world(
        position=FAR,
        inertia=TRIAXIAL,
        attitude=attitude.as_quat().tolist(),
        angular_velocity_deg_s=OBLIQUE_DEG_S,
    ) as w:
        body, client = w.capture.target.body, w.client
        moments = np.diag(pb.getDynamicsInfo(body, -1, physicsClientId=client)[2])

        def angular_momentum() -> np.ndarray:
            rotation = matrix(pb.getBasePositionAndOrientation(body, physicsClientId=client)[1])
            rate = np.asarray(pb.getBaseVelocity(body, physicsClientId=client)[1])
            return rotation @ moments @ rotation.T @ rate

        rotation0 = attitude.as_matrix()
        expected = rotation0 @ np.asarray(TRIAXIAL) @ np.radians(OBLIQUE_DEG_S)
        worst = np.linalg.norm(angular_momentum() - expected)
        while w.time < 20.0 - 1e-9:
            w.step(WorldInputs())
            worst = max(worst, np.linalg.norm(angular_momentum() - expected))
    assert worst <= 1e-9 * np.linalg.norm(expected)


# ---------------------------------------------------------------- grip and slip
def pulled_slip(load: float) -> tuple[float, float]:
    """Slide of the bar along its axis relative to the pads (m) over 1 s of pulling
    the bar along its axis with ``load`` times the pads' friction limit, and the
    recorded contact force on the body along the pull at the end, as a fraction of the
    pull.

    The body is pulled at the bar's centre and the palm with the opposite force at the
    point between the pads: the pair adds no momentum, so the friction that keeps them
    together is the pull itself, whatever the free arm and base do.
    """
    with gripped_world(physics_step=5e-4, control_period=5e-4) as w:
        rig, client = w.capture, w.client
        close_until_held(w, settle=0.1)
        limit = w.robot.gripper.friction * rig.period.last.normal.sum()
        pull = load * limit * rig.target_state().bar_axis
        start = rig.fixture_from_pads()[0] @ rig.target_state().bar_axis
        for _ in range(round(1.0 / w.physics_step)):
            state = rig.target_state()
            centre = state.fixture - rig.fixture_from_pads()[0]
            pb.applyExternalForce(
                rig.target.body,
                -1,
                pull.tolist(),
                state.fixture.tolist(),
                pb.WORLD_FRAME,
                physicsClientId=client,
            )
            pb.applyExternalForce(
                w.robot_id,
                rig.gripper.palm,
                (-pull).tolist(),
                centre.tolist(),
                pb.WORLD_FRAME,
                physicsClientId=client,
            )
            w.step(WorldInputs())
        slide = rig.fixture_from_pads()[0] @ rig.target_state().bar_axis - start
        along = rig.period.last.force @ pull / (pull @ pull)
    return abs(slide), along


def test_the_grip_holds_below_its_friction_limit():
    """Half the friction limit: the bar slides less than 1 mm in 1 s, and the pads'
    force on the body is the pull's opposite."""
    slide, along = pulled_slip(0.5)
    assert slide < 1e-3
    assert along == pytest.approx(-1.0, abs=0.05)


def test_the_grip_slips_past_its_friction_limit():
    """1.5 times the friction limit: the bar slides more than 5 cm in 1 s."""
    slide, _ = pulled_slip(1.5)
    assert slide > 0.05


# ---------------------------------------------------------------- momentum across contact
TUMBLE_DEG_S = (3.0, 0.3, 0.0)  # deg/s, body axes: the shipped flat spin


def momentum_errors(physics_step: float) -> tuple[float, float, float]:
    """Largest change of the system's momentum over the whole closing, from the pads'
    command until 0.5 s after they first touch a tumbling bar (zero command, the arm's
    joints and the base free), read every control period: linear (relative to the
    target's mass times its bar's speed), angular about the world origin and about the
    system's centre of mass (each relative to the system's |L| there)."""
    origin = np.zeros(3)
    with gripped_world(TUMBLE_DEG_S, physics_step=physics_step) as w:
        rig = w.capture
        before = momentum(w, origin), momentum(w)
        scale = rig.target.mass * np.linalg.norm(rig.target_state().fixture_velocity)
        rig.gripper.command(True)
        worst, settled = np.zeros(3), np.inf
        while w.time < settled:
            w.step(WorldInputs())
            if not rig.target.free:
                settled = min(settled, w.time + 0.5)
            now = momentum(w, origin), momentum(w)
            linear = np.linalg.norm(now[0][:3] - before[0][:3]) / scale
            angular = [
                np.linalg.norm(a[3:] - b[3:]) / np.linalg.norm(b[3:])
                for a, b in zip(now, before, strict=True)
            ]
            worst = np.maximum(worst, [linear, *angular])
        assert rig.period.last.normal.min() > 0.9 * w.robot.gripper.grip_force
    return tuple(worst)


@pytest.mark.xfail(
    strict=True,
    reason="PyBullet's multibody step: at the scenario's 0.5 ms, while the pads close on "
    "the bar, the linear momentum moves by 1.3e-4, the angular by 2.6e-5 (about the "
    "origin) and 1.9e-6 (about the centre of mass); at 0.25 ms 6.3e-5, 1.3e-5, 1.2e-6; "
    "at 0.1 ms 2.5e-5, 5.3e-6, 1.0e-6. The step's part falls to first order and is not "
    "the contact's: joint torques alone move the momentum so (the test below); about the "
    "centre of mass a floor of about 1e-6 stays: PyBullet applies a contact's friction at "
    "the pad's and the bar's own contact points, 1-2e-5 m apart (the penetration); once "
    "the grip has settled, at 0.1 ms, that offset's torque accounts for the change to "
    "within 2e-8 of |L|",
)
def test_contact_keeps_the_momentum_to_the_target():
    """The target: linear and angular momentum kept to 1e-6 across the grasp."""
    assert max(momentum_errors(5e-4)) <= 1e-6


def test_contact_keeps_the_momentum_to_the_step_accuracy():
    """What PyBullet achieves at the scenario's step: 3e-4 of the momentum (a missing
    part or a wrong sign in the sums would give errors of order 1)."""
    assert max(momentum_errors(5e-4)) <= 3e-4


def linear_momentum_drift(physics_step: float, joint_torques: np.ndarray, grip: bool) -> float:
    """Largest change (N·s) of the system's linear momentum over 1 s with the target
    100 m away (no contact), under constant joint torques and, with ``grip``, the pads
    closing: every force internal."""
    with capture_world(physics_step=physics_step, position=[0.0, 100.0, 0.0]) as w:
        start = momentum(w, np.zeros(3))[:3]
        if grip:
            w.capture.gripper.command(True)
        worst = 0.0
        for _ in range(100):
            w.step(WorldInputs(joint_torques=joint_torques))
            worst = max(worst, float(np.linalg.norm(momentum(w, np.zeros(3))[:3] - start)))
        return worst


def test_the_momentum_drift_is_pybullet_s_step_under_joint_torques_not_the_contact():
    """Why the contact target is missed: with nothing touching, the arm's joint torques
    alone move the linear momentum at first order in the step (PyBullet integrates the
    floating arm in joint coordinates by an Euler step: 9.3e-3 N·s over 1 s at 0.5 ms,
    1.9e-3 at 0.1 ms; the closing on the bar moves it by 1.2e-3 N·s, 1.3e-4 of the
    target's mass times its bar's 6.7 mm/s), while the pads closing alone, driven by the
    same engine's motors, keep it to 1e-13."""
    torques = np.array([5.0, -3.0, 2.0, 1.0, -1.0, 0.5])  # N·m
    coarse = linear_momentum_drift(5e-4, torques, grip=False)
    fine = linear_momentum_drift(1e-4, torques, grip=False)
    assert coarse == pytest.approx(9.3e-3, rel=0.02) and fine == pytest.approx(1.9e-3, rel=0.05)
    assert 4.0 < coarse / fine < 6.0  # first order: five times less for a fifth of the step
    assert linear_momentum_drift(5e-4, np.zeros(6), grip=True) < 1e-12


# ---------------------------------------------------------------- recorded impulse
def test_the_recorded_impulse_is_the_targets_momentum_change():
    """Over each control period of a grasp (no latch), the contact impulse the rig
    records is the target's mass times its velocity change, to 1e-6 relative."""
    with gripped_world(TUMBLE_DEG_S) as w:
        rig, body = w.capture, w.capture.target.body
        rig.gripper.command(True)
        while rig.target.free:
            w.step(WorldInputs())
        for _ in range(50):
            start = np.asarray(pb.getBaseVelocity(body, physicsClientId=w.client)[0])
            w.step(WorldInputs())
            end = np.asarray(pb.getBaseVelocity(body, physicsClientId=w.client)[0])
            change = rig.target.mass * (end - start)
            np.testing.assert_allclose(
                rig.period.impulse, change, rtol=0, atol=1e-6 * np.linalg.norm(change)
            )
        assert not rig.latched


# ---------------------------------------------------------------- latch
def test_the_latch_holds_the_target_to_the_palm():
    """Latched, the tumbling stack turns as one: the target's pose in the palm's frame
    moves less than 1e-4 m (and 1e-4 rad) over 5 s, the robot's spec holds its mass and
    the robot changes once, however often the latch is asked."""
    with gripped_world(TUMBLE_DEG_S) as w:
        rig, client = w.capture, w.client
        close_until_held(w, settle=0.5)
        changes = w.robot_changes
        rig.latch()
        rig.latch()
        assert w.robot_changes == changes + 1
        assert w.robot_spec().held_mass == rig.target.mass

        def relative_pose() -> tuple[np.ndarray, Rotation]:
            palm = pb.getLinkState(
                w.robot_id, rig.gripper.palm, computeForwardKinematics=1, physicsClientId=client
            )
            position, attitude = pb.getBasePositionAndOrientation(
                rig.target.body, physicsClientId=client
            )
            turn = Rotation.from_quat(palm[1]).inv()
            return turn.apply(np.asarray(position) - palm[0]), turn * Rotation.from_quat(attitude)

        start, worst_shift, worst_turn = relative_pose(), 0.0, 0.0
        end = w.time + 5.0
        while w.time < end:
            w.step(WorldInputs())
            shift, turn = relative_pose()
            worst_shift = max(worst_shift, np.linalg.norm(shift - start[0]))
            worst_turn = max(worst_turn, (start[1].inv() * turn).magnitude())
        rate = np.linalg.norm(rig.target_state().angular_velocity)
    assert worst_shift < 1e-4 and worst_turn < 1e-4
    assert rate > np.radians(1.0)  # the stack still tumbles


# ---------------------------------------------------------------- the arm strikes the body
def test_a_body_drifting_into_the_base_strikes_it_and_the_reading_names_the_base():
    """The arm's base and its links other than the gripper's collide with the tumbling
    body: a body drifting at 0.1 m/s into the base (the shipped base, a 1 m cube, on the
    x axis; the cylinder's side 5 cm off its back face) stops being free, pushes with a
    recorded force, and the period's reading names the base and only it."""
    gap = 0.05
    base = SHIPPED["robot"]["initial"]["position"][0]
    start = [base - 0.5 - 1.2 - gap, 0.0, 0.0]  # behind the base, away from the arm
    with capture_world(position=start, velocity=[0.1, 0.0, 0.0]) as w:
        rig = w.capture
        struck: set[int] = set()
        while rig.target.free:
            assert w.time < 1.0, "the body passed through the base"
            w.step(WorldInputs())
            struck |= rig.period.struck
        assert struck == {-1}
        assert rig.link_name(-1) == "base"
        assert rig.period.peak_force > 0.0


# ---------------------------------------------------------------- the body as sensed
POSE_SENSOR = {
    "objects": {
        "model": "object-sensor",
        "params": {"attitude_noise": 1.0, "detection_probability": 1.0, "rate": None},
    }
}
"""An object sensor that estimates poses, reading every tick."""


def test_a_pose_sensor_sees_the_free_body_and_not_the_latched_one():
    """Under an object sensor model the world hands over no true track of the body: the
    sensor detects it, with a measured attitude and the catalogue inertia, while it is
    free, and no more once the latch holds it."""
    position, attitude = grasp_pose()
    with capture_world(
        sensors=POSE_SENSOR, position=position.tolist(), attitude=attitude.tolist()
    ) as w:
        seen = w.observations()
        assert seen.tracks == ()
        (detection,) = seen.detections
        assert detection.id == w.capture.target.spec.id
        assert np.array_equal(detection.inertia, w.capture.target.inertia)
        turn = Rotation.from_quat(detection.attitude) * Rotation.from_quat(attitude).inv()
        assert 0.0 < turn.magnitude() < np.radians(5.0)
        close_until_held(w, settle=0.2)
        w.capture.latch()
        w.step(WorldInputs())
        assert w.observations().detections == ()
