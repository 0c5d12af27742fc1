"""The ``kalman`` tracker on synthetic detections of objects on known motions."""

from __future__ import annotations

import numpy as np
import pytest
from dcsim_plugins.trackers.kalman import KalmanTracker
from scipy.stats import chi2

from dcsim.api import (
    ClohessyWiltshireMotion,
    Detection,
    FrameDynamics,
    FrameKind,
    LinearMotion,
    ObjectKind,
    PluginRegistry,
    Shape,
    ShapeKind,
    StateEstimate,
    TorqueFreeRotation,
    mean_motion,
    quaternion_conjugate,
    quaternion_from_rotation_vector,
    quaternion_multiply,
    rotate,
    rotation_vector,
    run,
)
from dcsim.motion import MotionSet
from dcsim.testing import TrackerContract
from tests.conftest import make_distribution

N_400_KM = mean_motion(6_778_137.0)
"""Mean motion of a 400 km circular orbit, rad/s."""

CW_FRAME = FrameDynamics(kind=FrameKind.CLOHESSY_WILTSHIRE, mean_motion=N_400_KM)
INERTIAL_FRAME = FrameDynamics()
THREE_SIGMA = float(chi2.ppf(0.9973, 3))
"""Squared Mahalanobis distance within which a 3-dof Gaussian error lies 99.73 % of the time."""


class TestConformance(TrackerContract):
    """The tracker contract of the conformance suite."""

    plugin = KalmanTracker


def objects(frame: FrameDynamics, count: int, seed: int) -> MotionSet:
    """``count`` objects within about 60 m, drifting at cm/s, on the frame's free motion."""
    rng = np.random.default_rng(seed)
    starts, speeds = rng.normal(0.0, 30.0, (count, 3)), rng.normal(0.0, 0.03, (count, 3))
    if frame.kind is FrameKind.CLOHESSY_WILTSHIRE:
        return MotionSet(
            [
                ClohessyWiltshireMotion(p, v, frame.mean_motion)
                for p, v in zip(starts, speeds, strict=True)
            ]
        )
    return MotionSet([LinearMotion(p, v) for p, v in zip(starts, speeds, strict=True)])


def random_covariances(rng: np.random.Generator, count: int, sigma: float) -> np.ndarray:
    """``count`` random anisotropic covariances (3, 3) with standard deviations about ``sigma``."""
    axes = np.linalg.qr(rng.normal(size=(count, 3, 3)))[0]
    spreads = (sigma * rng.uniform(0.3, 2.0, (count, 3))) ** 2
    return axes @ (spreads[:, :, None] * axes.transpose(0, 2, 1))


ROBOT_ERROR_TIME = 100.0
"""Correlation time of the robot's position error, s: a localiser's error wanders slowly.
Over a minute it drifts by about 4e-4 m/s (σ √(2 / (τ W)) for σ = 2 cm, W = 50 s), the
velocity spread the robot's estimate states."""


class Sky:
    """Noisy detections of objects on known motions, seen from a robot whose position
    estimate is itself in error (both errors Gaussian with the covariances stated; the
    robot's error a first-order Gauss-Markov process, common to all objects seen at one
    instant and correlated over ``ROBOT_ERROR_TIME``, as a localiser's is)."""

    def __init__(self, frame: FrameDynamics, count: int = 12, seed: int = 5) -> None:
        self.truth = objects(frame, count, seed)
        self.count = count
        self.rng = np.random.default_rng(seed + 1)
        self.robot_covariance = np.diag([0.02, 0.02, 0.02, 4e-4, 4e-4, 4e-4]) ** 2
        self.robot_error = self.rng.multivariate_normal(np.zeros(3), self.robot_covariance[:3, :3])
        self.robot_time = 0.0

    def robot(self, t: float) -> tuple[np.ndarray, StateEstimate]:
        """The robot's true position at ``t`` (s) and its estimate."""
        position = np.array([2.0 * np.sin(0.01 * t), 0.05 * t, 0.0])
        kept = np.exp(-(t - self.robot_time) / ROBOT_ERROR_TIME)
        fresh = self.rng.multivariate_normal(np.zeros(3), self.robot_covariance[:3, :3])
        self.robot_error = kept * self.robot_error + np.sqrt(1.0 - kept**2) * fresh
        self.robot_time = t
        error = self.robot_error
        return position, StateEstimate(
            time=t, position=position + error, covariance=self.robot_covariance, converged=True
        )

    def detections(
        self, t: float, seen: np.ndarray | None = None
    ) -> tuple[tuple[Detection, ...], StateEstimate]:
        """Detections at ``t`` of the objects ``seen`` (indices; all if None)."""
        seen = np.arange(self.count) if seen is None else seen
        position, estimate = self.robot(t)
        positions = self.truth.state_at(t)[0][seen]
        covariances = random_covariances(self.rng, len(seen), 0.05)
        noise = np.einsum(
            "nij,nj->ni", np.linalg.cholesky(covariances), self.rng.normal(size=(len(seen), 3))
        )
        detections = tuple(
            Detection(
                time=t,
                id=int(i),
                kind=ObjectKind.OBSTACLE if i % 2 else ObjectKind.TARGET,
                relative_position=p - position + e,
                covariance=c,
                radius=0.5,
                mass=20.0,
            )
            for i, p, e, c in zip(seen, positions, noise, covariances, strict=True)
        )
        return detections, estimate


def squared_errors(sky: Sky, tracks, t: float) -> np.ndarray:
    """Each track's position error squared in its own covariance's metric."""
    truth = sky.truth.state_at(t)[0]
    errors = np.array([track.position - truth[track.id] for track in tracks])
    covariances = np.array([track.covariance[:3, :3] for track in tracks])
    return np.einsum("ni,ni->n", errors, np.linalg.solve(covariances, errors[:, :, None])[..., 0])


def tracker(frame: FrameDynamics, **params) -> KalmanTracker:
    plugin = KalmanTracker(params, np.random.default_rng(0))
    plugin.reset(frame, 0.0)
    return plugin


@pytest.mark.parametrize("frame", [CW_FRAME, INERTIAL_FRAME], ids=["lvlh", "inertial"])
def test_position_errors_stay_within_the_tracks_own_three_sigma(frame):
    sky, plugin = Sky(frame, count=40), tracker(frame)
    inside, dt = [], 0.5
    for k in range(1200):  # 600 s; objects seen every other tick
        t = k * dt
        detections, estimate = sky.detections(t) if k % 2 == 0 else ((), sky.robot(t)[1])
        tracks = plugin.update(t, detections, estimate)
        assert [track.id for track in tracks] == list(range(sky.count))
        if t >= 20.0:  # after start-up
            inside.extend(squared_errors(sky, tracks, t) <= THREE_SIGMA)
    assert np.mean(inside) >= 0.99, np.mean(inside)


def test_the_covariance_is_not_wildly_conservative_either():
    sky, plugin = Sky(CW_FRAME, count=40), tracker(CW_FRAME)
    nees = []
    for k in range(600):
        t = 0.5 * k
        tracks = plugin.update(t, *sky.detections(t))
        if t >= 20.0:
            nees.extend(squared_errors(sky, tracks, t))
    # A consistent filter's mean is 3; errors correlated over ticks and through the robot's
    # error spread one run's mean by about ±0.5 (2.8 to 3.5 over seeds 0-7). A filter
    # whose covariance were twice too wide would give 1.5.
    assert 2.0 < np.mean(nees) < 4.0, np.mean(nees)


def white_acceleration_noise(dt: float, density: float) -> np.ndarray:
    """The exact covariance (6, 6) a white acceleration of spectral density ``density``
    (m²/s³ per axis) adds to ``[position, velocity]`` over ``dt`` (s) in straight-line motion."""
    block = np.array([[dt**3 / 3.0, dt**2 / 2.0], [dt**2 / 2.0, dt]])
    return np.kron(block, np.eye(3)) * density


def test_the_prediction_adds_the_white_acceleration_noise():
    plugin = tracker(INERTIAL_FRAME, acceleration_noise=0.02, initial_velocity_sigma=0.3)
    robot = StateEstimate(
        time=0.0, position=np.zeros(3), covariance=np.zeros((6, 6)), converged=True
    )
    seen = Detection(
        time=0.0,
        id=4,
        kind=ObjectKind.TARGET,
        relative_position=[1.0, 2.0, 3.0],
        covariance=np.eye(3) * 0.01,
    )
    (start,) = plugin.update(0.0, [seen], robot)
    (later,) = plugin.update(2.5, [], robot)
    transition = np.eye(6) + np.kron([[0.0, 2.5], [0.0, 0.0]], np.eye(3))
    expected = transition @ start.covariance @ transition.T + white_acceleration_noise(2.5, 0.02**2)
    np.testing.assert_allclose(later.covariance, expected, rtol=1e-9, atol=1e-15)


def test_objects_driven_by_white_acceleration_are_followed_within_three_sigma():
    rng, dt, density, count = np.random.default_rng(11), 0.5, 0.01**2, 40
    plugin = tracker(INERTIAL_FRAME, acceleration_noise=0.01)
    transition = np.eye(6) + np.kron([[0.0, dt], [0.0, 0.0]], np.eye(3))
    kick = np.linalg.cholesky(white_acceleration_noise(dt, density))
    states = np.hstack([rng.normal(0.0, 30.0, (count, 3)), rng.normal(0.0, 0.03, (count, 3))])
    robot = StateEstimate(
        time=0.0, position=np.zeros(3), covariance=np.zeros((6, 6)), converged=True
    )
    covariance = np.eye(3) * 0.05**2
    inside = []
    for k in range(600):
        t = k * dt
        if k:
            states = states @ transition.T + rng.normal(size=(count, 6)) @ kick.T
        detections = [
            Detection(
                time=t,
                id=i,
                kind=ObjectKind.OBSTACLE,
                covariance=covariance,
                relative_position=states[i, :3] + rng.normal(0.0, 0.05, 3),
            )
            for i in range(count)
        ]
        tracks = plugin.update(t, detections, robot)
        if t >= 20.0:
            errors = np.array([track.position for track in tracks]) - states[:, :3]
            spreads = np.array([track.covariance[:3, :3] for track in tracks])
            distances = np.einsum(
                "ni,ni->n", errors, np.linalg.solve(spreads, errors[..., None])[..., 0]
            )
            inside.extend(distances <= THREE_SIGMA)
    assert np.mean(inside) >= 0.99, np.mean(inside)


def test_a_tick_without_detections_predicts_every_track_by_the_frame_s_motion():
    # Little process noise, so that 300 s of coasting tell the orbit's motion (metres off
    # a straight line at these distances) from anything else.
    sky, plugin = Sky(CW_FRAME), tracker(CW_FRAME, acceleration_noise=1e-6, lose_after=400.0)
    for k in range(100):
        tracks = plugin.update(0.5 * k, *sky.detections(0.5 * k))
    before = {track.id: track for track in tracks}
    later = 49.5 + 300.0
    coasted = plugin.update(later, (), sky.robot(later)[1])
    assert [track.time for track in coasted] == [later] * sky.count
    assert (squared_errors(sky, coasted, later) <= THREE_SIGMA).mean() >= 0.9
    for track in coasted:
        previous = before[track.id]
        expected = previous.motion.state_at(later)
        np.testing.assert_allclose(track.position, expected[0], atol=1e-6)
        np.testing.assert_allclose(track.velocity, expected[1], atol=1e-9)
        assert np.trace(track.covariance) > np.trace(previous.covariance)


@pytest.mark.parametrize(
    "frame, motion", [(CW_FRAME, ClohessyWiltshireMotion), (INERTIAL_FRAME, LinearMotion)]
)
def test_a_track_s_motion_is_the_frame_s_free_motion_from_its_state(frame, motion):
    sky, plugin = Sky(frame, count=2), tracker(frame)
    track = plugin.update(3.0, *sky.detections(3.0))[0]
    assert type(track.motion) is motion and track.motion.epoch == 3.0
    position, velocity = track.motion.state_at(3.0)
    np.testing.assert_allclose(position, track.position, atol=1e-12)
    np.testing.assert_allclose(velocity, track.velocity, atol=1e-15)


def test_a_track_starts_at_the_first_detection_with_unknown_velocity():
    plugin = tracker(INERTIAL_FRAME, initial_velocity_sigma=0.2, shape_margin=0.25)
    covariance = np.diag([0.01, 0.02, 0.03])
    robot = StateEstimate(
        time=1.0, position=[10.0, 0.0, 0.0], covariance=np.eye(6) * 1e-4, converged=True
    )
    seen = Detection(
        time=1.0,
        id=7,
        kind=ObjectKind.TARGET,
        relative_position=[1.0, 2.0, 3.0],
        covariance=covariance,
        radius=0.4,
        mass=12.0,
    )
    (track,) = plugin.update(1.0, [seen], robot)
    assert (track.id, track.kind, track.time, track.mass) == (7, ObjectKind.TARGET, 1.0, 12.0)
    np.testing.assert_array_equal(track.position, [11.0, 2.0, 3.0])
    np.testing.assert_array_equal(track.velocity, np.zeros(3))
    expected = np.zeros((6, 6))
    expected[:3, :3] = covariance + 1e-4 * np.eye(3)
    expected[3:, 3:] = (0.04 + 1e-4) * np.eye(3)  # and the robot's velocity spread
    np.testing.assert_allclose(track.covariance, expected)
    assert track.shape.kind is ShapeKind.SPHERE and track.radius == pytest.approx(0.65)
    assert track.shape_margin == 0.25 and track.sensed_radius == pytest.approx(0.4)
    for array in (track.position, track.velocity, track.covariance):
        assert not array.flags.writeable


def test_a_detection_s_shape_is_kept_when_the_sensor_sees_one():
    plugin = tracker(INERTIAL_FRAME)
    box = Shape(kind=ShapeKind.BOX, half_extents=[1.0, 0.5, 0.2])
    robot = StateEstimate(time=0.0, position=np.zeros(3), converged=True)
    seen = Detection(
        time=0.0,
        id=1,
        kind=ObjectKind.OBSTACLE,
        relative_position=[5.0, 0, 0],
        covariance=np.eye(3) * 1e-3,
        radius=1.2,
        shape=box,
    )
    (track,) = plugin.update(0.0, [seen], robot)
    assert track.shape is box and track.radius == pytest.approx(box.bounding_radius)
    assert track.shape_margin == 0.0 and track.sensed_radius == track.radius


def test_the_gate_rejects_planted_outliers_and_counts_them():
    sky, plugin = Sky(CW_FRAME, count=6), tracker(CW_FRAME)
    planted, offset = 0, np.array([3.0, -2.0, 1.0])
    pulled, nees = [], []
    for k in range(200):
        t = 0.5 * k
        detections, estimate = sky.detections(t)
        if k >= 40 and k % 7 == 0:  # every seventh tick after start-up, object 3 is far off
            outlier = detections[3]
            detections = (
                detections[:3]
                + (
                    Detection(
                        time=t,
                        id=3,
                        kind=outlier.kind,
                        relative_position=outlier.relative_position + offset,
                        covariance=outlier.covariance,
                        radius=outlier.radius,
                        mass=outlier.mass,
                    ),
                )
                + detections[4:]
            )
            planted += 1
        tracks = plugin.update(t, detections, estimate)
        if k >= 40:
            pulled.append(np.linalg.norm(tracks[3].position - sky.truth.state_at(t)[0][3]))
            nees.append(squared_errors(sky, tracks, t)[3])
    # The outliers (3.7 m off) never pull the track: it stays within centimetres and, but
    # for the robot's slowly wandering error common to every tick, within its 3 sigma.
    assert max(pulled) < 0.2, max(pulled)
    assert np.mean(np.array(nees) <= THREE_SIGMA) >= 0.95
    assert planted <= plugin.rejected <= planted + 2  # 0.1 % of 960 true ones may fail too
    plugin.reset(CW_FRAME, 0.0)
    assert plugin.rejected == 0


def test_a_track_unseen_for_longer_than_lose_after_is_dropped_and_starts_again():
    sky, plugin = Sky(INERTIAL_FRAME, count=3), tracker(INERTIAL_FRAME, lose_after=4.0)
    for k in range(20):
        plugin.update(0.5 * k, *sky.detections(0.5 * k))  # last seen at 9.5 s
    others = np.array([0, 2])
    ids = {}
    for k in range(20, 40):
        t = 0.5 * k
        ids[t] = [track.id for track in plugin.update(t, *sky.detections(t, others))]
    assert ids[13.5] == [0, 1, 2]  # 4 s unseen: kept
    assert ids[14.0] == [0, 2]  # 4.5 s unseen: dropped
    (_, restarted, _) = plugin.update(20.0, *sky.detections(20.0))
    np.testing.assert_array_equal(restarted.velocity, np.zeros(3))  # a new track


NOISY_OBJECT_SENSOR = """
    import numpy as np
    from dcsim.api import Detection, PluginParams, SensorModel, hookimpl

    class NoisyObjects(SensorModel):
        name = "noisy-objects"
        summary = "Free objects in range with 5 cm of white noise"
        measures = "objects"
        Params = PluginParams

        def reset(self, setup):
            self.setup = setup

        def measure(self, truth):
            offsets = truth.object_positions - truth.position
            return tuple(
                Detection(
                    time=truth.time, id=obj.id, kind=obj.kind,
                    relative_position=offset + self.rng.normal(0.0, 0.05, 3),
                    covariance=np.eye(3) * 0.05**2, radius=obj.shape.bounding_radius,
                    mass=obj.mass,
                )
                for obj, offset, free in zip(self.setup.objects, offsets, truth.free)
                if free and np.linalg.norm(offset) <= self.setup.object_range
            )

    @hookimpl
    def dcsim_plugin_classes():
        return [NoisyObjects]
"""


def test_a_run_with_an_object_sensor_model_flies_the_kalman_tracker(tmp_path, monkeypatch):
    site = make_distribution(
        tmp_path / "site",
        "noisy-objects",
        "0.1",
        {"noisy_objects": NOISY_OBJECT_SENSOR},
        {"noisy-objects": "noisy_objects"},
        group="dcsim.sensors",
    )
    monkeypatch.syspath_prepend(str(site))
    overrides = {"world.duration": 10.0, "sensors.objects": {"model": "noisy-objects"}}
    result = run(None, overrides, tmp_path / "run", plots=False, registry=PluginRegistry.discover())
    assert result.summary["status"] == "completed", result.summary["reason"]
    assert result.summary["plugins"]["tracker"]["name"] == "kalman"
    assert result.summary["wall_time_by_phase_s"]["tracker"] > 0.0


# --- rotation -------------------------------------------------------------------------

TUMBLING_INERTIA = np.array([[5433.0, 0.0, 0.0], [0.0, 5433.0, 0.0], [0.0, 0.0, 1008.0]])
"""The capture scenario's cylinder, kg·m² (body axes)."""


def tumbling_detections(
    inertia_known: bool, seconds: float, seed: int = 3
) -> tuple[list[tuple[Detection, ...]], list[tuple[np.ndarray, np.ndarray]]]:
    """Detections at 10 Hz of a body 4 m away tumbling in a flat spin with nutation
    (3 deg/s about body x, 0.3 about y, 0.2 about its own axis z), its attitude measured
    with 1 deg about each axis; and the true ``(attitude, angular velocity)`` at each."""
    rng = np.random.default_rng(seed)
    start = quaternion_from_rotation_vector([0.3, -0.2, 0.5])
    rate = rotate(start, np.radians([3.0, 0.3, 0.2]))
    body = TorqueFreeRotation(TUMBLING_INERTIA, start, rate)
    sigma = np.radians(1.0)
    detections, truths = [], []
    for _ in range(round(seconds * 10)):
        attitude, omega = np.array(body.attitude), np.array(body.angular_velocity)
        error = quaternion_from_rotation_vector(sigma * rng.standard_normal(3))
        detections.append(
            (
                Detection(
                    time=body.time,
                    id=7,
                    kind=ObjectKind.TARGET,
                    relative_position=np.array([4.0, 0.0, 0.0]) + rng.normal(0.0, 0.01, 3),
                    covariance=1e-4 * np.eye(3),
                    radius=3.3,
                    mass=1400.0,
                    attitude=quaternion_multiply(error, attitude),
                    attitude_covariance=sigma**2 * np.eye(3),
                    inertia=TUMBLING_INERTIA if inertia_known else None,
                ),
            )
        )
        truths.append((attitude, omega))
        body.advance(0.1)
    return detections, truths


def rotation_errors(track, attitude: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """A track's ``[δθ, δω]`` (rad, rad/s, world axes) from the truth."""
    turn = rotation_vector(quaternion_multiply(attitude, quaternion_conjugate(track.attitude)))
    return np.concatenate([turn, omega - track.angular_velocity])


def test_a_tumbling_body_s_attitude_and_rate_are_tracked_within_their_covariance():
    """Over 60 s of 1 deg pose estimates the rotation filter's errors average about 6
    in its own covariance's metric (6 dof, after a 10 s start; the samples are
    correlated over seconds, hence the wide band), and its rate ends within 0.03 deg/s
    of the truth; the track carries the filter's state and the inertia."""
    detections, truths = tumbling_detections(inertia_known=True, seconds=60.0)
    plugin = tracker(INERTIAL_FRAME)
    robot = StateEstimate(time=0.0, position=np.zeros(3), converged=True)
    nees = []
    for made, (attitude, omega) in zip(detections, truths, strict=True):
        (track,) = plugin.update(made[0].time, made, robot)
        rotation = plugin._rotations[7]
        error = rotation_errors(track, attitude, omega)
        if made[0].time >= 10.0:
            nees.append(error @ np.linalg.solve(rotation.covariance, error))
    assert np.array_equal(track.inertia, TUMBLING_INERTIA)
    assert np.array_equal(track.attitude, rotation.attitude)  # a read-only copy of it
    assert track.attitude is not rotation.attitude and not track.attitude.flags.writeable
    assert 6.0 * 0.5 < np.mean(nees) < 6.0 * 1.5
    assert np.degrees(np.linalg.norm(error[3:])) < 0.03


def test_the_catalogue_inertia_predicts_the_nutation_a_constant_rate_misses():
    """Without the inertia the filter predicts a constant rate; the body's rate turns
    (nutation), so its rate error after 60 s is several times larger."""
    errors = {}
    for known in (True, False):
        detections, truths = tumbling_detections(inertia_known=known, seconds=60.0)
        plugin = tracker(INERTIAL_FRAME)
        robot = StateEstimate(time=0.0, position=np.zeros(3), converged=True)
        for made in detections:
            (track,) = plugin.update(made[0].time, made, robot)
        errors[known] = np.linalg.norm(rotation_errors(track, *truths[-1])[3:])
    assert track.inertia is None
    assert errors[False] > 3.0 * errors[True]
