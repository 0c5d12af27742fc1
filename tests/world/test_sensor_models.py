"""The built-in sensor models' error statistics against their parameters, on long samples.

Each model is built as the world builds it (parameters and its own generator), told
about a world (:class:`SensorSetup`) and fed the truth (:class:`SensedTruth`). Bounds
are a few standard errors of the estimate wide: a wrong variance, a missing factor or a
draw in the wrong frame falls outside them; a correct model, at these seeds, inside.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from dcsim.api import (
    BeaconRange,
    KnownObject,
    ObjectKind,
    PluginParameterError,
    SensedTruth,
    SensorSetup,
    Shape,
    ShapeKind,
    quaternion_conjugate,
    quaternion_from_rotation_vector,
    quaternion_multiply,
    rotate,
    rotation_vector,
)
from dcsim.run.scripting import close_run, open_run
from dcsim.world.sensors.beacon_ranges import BeaconRangeSensor
from dcsim.world.sensors.gyros import DEG_PER_HOUR, DEG_PER_ROOT_HOUR, Gyros
from dcsim.world.sensors.object_sensor import ObjectSensor
from dcsim.world.sensors.star_tracker import ARCSEC, StarTracker

PERIOD = 0.1
"""Control period of the shipped scenarios, s."""
TURNED = quaternion_from_rotation_vector([0.4, -0.7, 1.1])
"""A base attitude well away from the identity."""


def truth(time: float, attitude=TURNED, angular_velocity=(0.0, 0.0, 0.0), **objects):
    """The robot at the origin with ``attitude`` and ``angular_velocity`` (world, rad/s)."""
    return SensedTruth(
        time=time,
        position=np.zeros(3),
        velocity=np.zeros(3),
        attitude=attitude,
        angular_velocity=angular_velocity,
        **objects,
    )


def ticks(seconds: float, period: float = PERIOD) -> np.ndarray:
    """Control tick times from 0 over ``seconds``, as sums of one period (as a run's)."""
    return np.cumsum(np.r_[0.0, np.full(round(seconds / period) - 1, period)])


def within(value: float, expected: float, standard_error: float, k: float = 4.0) -> bool:
    """Whether ``value`` is within ``k`` standard errors of ``expected``."""
    return abs(value - expected) <= k * standard_error


# --- beacon ranges ---------------------------------------------------------------------

BEACONS = np.array([[10.0, 0, 0], [0, 20.0, 0], [0, 0, 30.0], [-40.0, 0, 0], [0, -50.0, 0]])


def beacon_model(seed: int = 1, sigma: float = 0.1, **params) -> BeaconRangeSensor:
    """A beacon range model in a world of five beacons, reporting the four nearest."""
    model = BeaconRangeSensor(params, np.random.default_rng(seed))
    model.reset(
        SensorSetup(
            control_period=PERIOD, beacons=BEACONS, beacon_noise=sigma, beacon_report_nearest=4
        )
    )
    return model


def range_errors(model: BeaconRangeSensor, count: int) -> tuple[np.ndarray, int]:
    """Every range's error (m) over ``count`` ticks at the origin, and how many ranges
    were expected (four per tick)."""
    true = np.linalg.norm(BEACONS, axis=1)
    errors = [
        r.range - true[r.beacon_id] for t in ticks(count * PERIOD) for r in model.measure(truth(t))
    ]
    return np.array(errors), 4 * count


def test_default_beacon_ranges_draw_exactly_one_normal_per_range_and_tick():
    model, reference = beacon_model(seed=7), np.random.default_rng(7)
    true = np.linalg.norm(BEACONS, axis=1)
    for t in ticks(20.0):
        ranges = model.measure(truth(t))
        assert [r.beacon_id for r in ranges] == [0, 1, 2, 3]
        expected = true[:4] + reference.normal(0.0, 0.1, 4)
        assert [r.range for r in ranges] == expected.tolist()
    assert model.rng.bit_generator.state == reference.bit_generator.state


def test_beacon_ranges_are_what_their_constructor_would_build_and_read_only():
    ranges = beacon_model().measure(truth(0.0))
    for r in ranges:
        assert r == BeaconRange(r.beacon_id, BEACONS[r.beacon_id], r.range, r.sigma)
        assert type(r.range) is float and type(r.beacon_id) is int
        assert not r.beacon_position.flags.writeable and r.beacon_position.base is not None
        assert not r.beacon_position.base.flags.writeable  # a view of the setup's beacons
    assert len(ranges) == 4


def test_beacon_bias_shifts_every_range_and_is_not_reported():
    errors, _ = range_errors(beacon_model(bias=0.5), 5000)
    assert within(errors.mean(), 0.5, 0.1 / math.sqrt(errors.size))
    assert within(errors.std(), 0.1, 0.1 / math.sqrt(2 * errors.size))
    assert {r.sigma for r in beacon_model(bias=0.5).measure(truth(0.0))} == {0.1}


def test_beacon_outliers_come_at_their_rate_with_their_size():
    p, size, bias = 0.05, 10.0, 0.2
    model = beacon_model(bias=bias, outlier_probability=p, outlier_size=size)
    errors, count = range_errors(model, 10000)
    assert errors.size == count
    assert within(np.median(errors), bias, 2 * 0.1 / math.sqrt(count))
    # Beyond 1 m (10 sigma) only outliers fall: those of |N(0, 10)| > 1 m.
    far = np.abs(errors) > 1.0
    expected = p * 2 * stats.norm.sf(1.0, scale=size)
    assert within(far.mean(), expected, math.sqrt(expected * (1 - expected) / count))
    assert within(np.var(errors), 0.1**2 + p * size**2, p * size**2 * math.sqrt(6 / (p * count)))


def test_beacon_dropouts_lose_ranges_at_their_rate():
    errors, count = range_errors(beacon_model(dropout_probability=0.3), 10000)
    lost = 1 - errors.size / count
    assert within(lost, 0.3, math.sqrt(0.3 * 0.7 / count))
    assert within(errors.std(), 0.1, 0.1 / math.sqrt(2 * errors.size))


@pytest.mark.parametrize("rate", [2.0, 3.0, 0.7])
def test_a_sensor_with_a_rate_reads_at_the_first_tick_after_each_instant(rate):
    model = beacon_model(rate=rate)
    times = ticks(60.0)
    read = [t for t in times if model.measure(truth(t))]
    expected = [times[np.argmax(times >= k / rate - 1e-9)] for k in range(math.ceil(59.9 * rate))]
    assert read == pytest.approx(expected)
    assert read[0] == 0.0


@pytest.mark.parametrize(
    "params",
    [{"outlier_probability": 1.5}, {"dropout_probability": -0.1}, {"rate": 0}],
)
def test_beacon_parameters_out_of_bounds_are_refused_by_name(params):
    with pytest.raises(PluginParameterError, match=next(iter(params))):
        BeaconRangeSensor(params)


# --- star tracker ----------------------------------------------------------------------


def star_errors(seed: int, count: int, **params) -> tuple[np.ndarray, list]:
    """The error rotation vectors (rad, body frame) of ``count`` readings taken every
    tick at random attitudes, and the readings."""
    model = StarTracker({"rate": None, **params}, np.random.default_rng(seed))
    model.reset(SensorSetup(control_period=PERIOD))
    attitudes = np.random.default_rng(seed + 100).normal(size=(count, 4))
    attitudes /= np.linalg.norm(attitudes, axis=1, keepdims=True)
    readings = [
        model.measure(truth(t, q)) for t, q in zip(ticks(count * PERIOD), attitudes, strict=True)
    ]
    measured = np.array([r.attitude for r in readings])
    errors = rotation_vector(quaternion_multiply(quaternion_conjugate(attitudes), measured))
    assert np.allclose(np.linalg.norm(measured, axis=1), 1.0, atol=1e-15)
    assert np.all(np.sum(measured * attitudes, axis=1) > 0.0)  # the truth's hemisphere
    return errors, readings


def test_star_tracker_error_per_body_axis_is_its_noise_about_its_misalignment():
    noise, misalignment = np.array([6.0, 6.0, 40.0]), np.array([30.0, -20.0, 50.0])
    errors, readings = star_errors(
        3, 20000, noise=noise.tolist(), misalignment=misalignment.tolist()
    )
    sigma = noise * ARCSEC
    n = len(errors)
    assert np.all(np.abs(errors.mean(axis=0) - misalignment * ARCSEC) < 4 * sigma / math.sqrt(n))
    assert np.all(np.abs(errors.std(axis=0) / sigma - 1) < 4 / math.sqrt(2 * n))
    assert abs(np.corrcoef(errors.T)[0, 2]) < 4 / math.sqrt(n)
    assert np.array_equal(readings[0].sigma, sigma)


def test_star_tracker_without_noise_reads_the_misaligned_truth():
    errors, _ = star_errors(4, 50, noise=[0, 0, 0], misalignment=[10.0, 0.0, -20.0])
    assert np.allclose(errors, np.array([10.0, 0.0, -20.0]) * ARCSEC, rtol=0, atol=1e-12)


def test_star_tracker_reads_at_five_hertz_by_default():
    model = StarTracker({}, np.random.default_rng(0))
    model.reset(SensorSetup(control_period=PERIOD))
    read = [t for t in ticks(10.0) if model.measure(truth(t)) is not None]
    assert read == pytest.approx(np.arange(0.0, 10.0, 0.2))


# --- gyros -----------------------------------------------------------------------------

RATE_WORLD = np.array([0.01, -0.02, 0.03])
"""A true angular velocity, world frame, rad/s."""


def gyro_models(count: int, period: float = PERIOD, **params) -> list[Gyros]:
    """``count`` independent gyro models, each with its own seed."""
    models = [Gyros(params, np.random.default_rng(seed)) for seed in range(count)]
    for model in models:
        model.reset(SensorSetup(control_period=period))
    return models


def test_gyros_white_noise_is_the_angle_random_walk_over_the_interval():
    (model,) = gyro_models(1, angle_random_walk=0.15, rate_random_walk=0.0, initial_bias=0.0)
    readings = [model.measure(truth(t, angular_velocity=RATE_WORLD)) for t in ticks(3000.0)]
    rates = np.array([r.angular_velocity for r in readings])
    body = rotate(quaternion_conjugate(TURNED), RATE_WORLD)
    sigma = 0.15 * DEG_PER_ROOT_HOUR / math.sqrt(PERIOD)
    n = len(rates)
    assert np.all(np.abs(rates.mean(axis=0) - body) < 4 * sigma / math.sqrt(n))
    assert np.all(np.abs(rates.std(axis=0) / sigma - 1) < 4 / math.sqrt(2 * n))
    assert readings[1].sigma == pytest.approx(sigma, rel=1e-12)


def test_gyros_averaged_rate_falls_as_the_angle_random_walk_over_root_time():
    """Allan deviation: the mean rate over a window of τ s has 1σ ARW/√τ."""
    (model,) = gyro_models(1, angle_random_walk=0.3, rate_random_walk=0.0, initial_bias=0.0)
    errors = np.array([model.measure(truth(t)).angular_velocity for t in ticks(10000.0)])
    for window in (1.0, 10.0, 100.0):
        per = round(window / PERIOD)
        means = errors[: len(errors) // per * per].reshape(-1, per, 3).mean(axis=1)
        allan = np.sqrt(0.5 * np.mean(np.diff(means, axis=0) ** 2, axis=0))
        clusters = len(means) - 1
        expected = 0.3 * DEG_PER_ROOT_HOUR / math.sqrt(window)
        assert np.all(np.abs(allan / expected - 1) < 4 / math.sqrt(2 * clusters)), window


def test_gyros_bias_walks_with_variance_growing_as_time():
    """Without angle random walk a reading's error is the bias averaged over its
    interval plus the white σ_u²Δt/12: its spread over many gyros grows as
    σ_u² (t + Δt/4 + Δt/12)."""
    rrw, period, count = 5.0, 2.0, 1000
    models = gyro_models(
        count, period, angle_random_walk=0.0, rate_random_walk=rrw, initial_bias=0.0
    )
    times = ticks(100.0, period)
    biases = np.array([[m.measure(truth(t)).angular_velocity for t in times] for m in models])
    sigma_u = rrw * DEG_PER_HOUR / 60.0
    for k in (0, 5, 20, 49):
        expected = sigma_u**2 * (times[k] + period / 3)
        variance = biases[:, k].var(axis=0)
        assert np.all(np.abs(variance / expected - 1) < 4 * math.sqrt(2 / count)), k
    assert np.allclose(biases.mean(axis=0), 0.0, atol=4 * sigma_u * 10 / math.sqrt(count))


def test_gyros_initial_bias_is_drawn_once_per_axis_at_its_size():
    models = gyro_models(4000, angle_random_walk=0.0, rate_random_walk=0.0, initial_bias=0.5)
    first = np.array([m.measure(truth(0.0)).angular_velocity for m in models])
    later = np.array([m.measure(truth(0.1)).angular_velocity for m in models])
    sigma = 0.5 * DEG_PER_HOUR
    assert np.all(np.abs(first.std(axis=0) / sigma - 1) < 4 / math.sqrt(2 * len(first)))
    assert np.array_equal(first, later)


def test_gyros_white_part_and_its_sigma_at_their_own_rate():
    """At 2 Hz the interval is 0.5 s: the reading less the averaged bias has the
    reported sigma, √(σ_v²/Δt + σ_u²Δt/12)."""
    (model,) = gyro_models(1, angle_random_walk=0.15, rate_random_walk=50.0, rate=2.0)
    whites, sigmas = [], []
    for t in ticks(2000.0):
        before = model.bias.copy()
        reading = model.measure(truth(t))
        if reading is not None:
            whites.append(reading.angular_velocity - 0.5 * (before + model.bias))
            sigmas.append(reading.sigma)
    sigma_v, sigma_u = 0.15 * DEG_PER_ROOT_HOUR, 50.0 * DEG_PER_HOUR / 60
    expected = math.sqrt(sigma_v**2 / 0.5 + sigma_u**2 * 0.5 / 12)
    assert len(whites) == 4000
    assert sigmas == pytest.approx(np.full(4000, expected), rel=1e-9)
    assert np.all(np.abs(np.std(whites, axis=0) / expected - 1) < 4 / math.sqrt(2 * 4000))


# --- object sensor ---------------------------------------------------------------------


def catalogue(count: int) -> tuple[KnownObject, ...]:
    """``count`` objects, alternately target spheres and obstacle boxes."""
    return tuple(
        KnownObject(
            id=100 + i,
            kind=ObjectKind.TARGET if i % 2 == 0 else ObjectKind.OBSTACLE,
            mass=1.0 + i,
            shape=Shape(ShapeKind.SPHERE, radius=0.5)
            if i % 2 == 0
            else Shape(ShapeKind.BOX, half_extents=(1.0, 2.0, 2.0)),
        )
        for i in range(count)
    )


def object_model(objects, seed: int = 5, reach: float = 100.0, **params) -> ObjectSensor:
    """An object sensor reading every tick unless ``params`` says otherwise."""
    model = ObjectSensor({"rate": None, **params}, np.random.default_rng(seed))
    model.reset(SensorSetup(control_period=PERIOD, object_range=reach, objects=objects))
    return model


def seen(model: ObjectSensor, t: float, positions, free=None, attitude=TURNED):
    """The detections at ``t`` of objects at world ``positions`` (m)."""
    positions = np.asarray(positions, dtype=float)
    free = np.ones(len(positions), dtype=bool) if free is None else np.asarray(free)
    return model.measure(
        truth(
            t,
            attitude,
            object_positions=positions,
            object_velocities=np.zeros_like(positions),
            free=free,
        )
    )


def test_detection_covariance_matches_the_scatter_of_the_measured_positions():
    """Normalised errors eᵀP⁻¹e average 3 and fall below χ²₃(0.95) 95 % of the time,
    for objects all round, near the body z axis too; each object's scatter matches
    its covariance."""
    robot = np.array([5.0, -3.0, 2.0])  # not at the origin
    near_body_z = rotate(TURNED, [1.0, 2.0, 70.0])
    positions = robot + np.array([[40.0, 0, 0], [0, -60.0, 5.0], [-30.0, 30.0, 20.0], near_body_z])
    model = object_model(
        catalogue(4), range_noise=0.05, bearing_noise=0.2, detection_probability=1.0
    )
    errors, covariances = [], []
    for t in ticks(1000.0):
        state = SensedTruth(
            time=t,
            position=robot,
            velocity=np.zeros(3),
            attitude=TURNED,
            angular_velocity=np.zeros(3),
            object_positions=positions,
            object_velocities=np.zeros_like(positions),
            free=np.ones(4, dtype=bool),
        )
        detections = model.measure(state)
        errors.append(
            [d.relative_position - (p - robot) for d, p in zip(detections, positions, strict=True)]
        )
        covariances.append([d.covariance for d in detections])
    errors_, covariances_ = np.array(errors), np.array(covariances)  # (T, 4, 3), (T, 4, 3, 3)
    nees = np.einsum("toi,toij,toj->to", errors_, np.linalg.inv(covariances_), errors_)
    n = nees.size
    assert within(nees.mean(), 3.0, math.sqrt(6.0 / n))
    inside = np.mean(nees < stats.chi2.ppf(0.95, 3))
    assert within(inside, 0.95, math.sqrt(0.95 * 0.05 / n))
    for o in range(4):
        scatter = np.cov(errors_[:, o].T)
        mean_covariance = covariances_[:, o].mean(axis=0)
        assert np.allclose(scatter, mean_covariance, rtol=0, atol=0.1 * np.trace(mean_covariance))


def test_detection_errors_are_range_and_bearing_in_the_body_frame():
    """Along the line of sight the error is the range noise; across it, the bearing
    noise times the range (the object is on body x, where both angles count fully)."""
    body_x = rotate(TURNED, [50.0, 0.0, 0.0])
    model = object_model(
        catalogue(1), range_noise=0.05, bearing_noise=0.2, detection_probability=1.0
    )
    errors = np.array(
        [seen(model, t, [body_x])[0].relative_position - body_x for t in ticks(1000.0)]
    )
    in_body = np.array([rotate(quaternion_conjugate(TURNED), e) for e in errors])
    expected = np.array([0.05, 50 * math.radians(0.2), 50 * math.radians(0.2)])
    n = len(in_body)
    assert np.all(np.abs(in_body.std(axis=0) / expected - 1) < 4 / math.sqrt(2 * n))
    assert np.all(np.abs(in_body.mean(axis=0)) < 4 * expected / math.sqrt(n))


def test_objects_are_detected_at_the_detection_probability():
    model = object_model(catalogue(10), detection_probability=0.8)
    positions = np.column_stack([np.linspace(10, 50, 10), np.zeros(10), np.zeros(10)])
    counts = [len(seen(model, t, positions)) for t in ticks(500.0)]
    trials = 10 * len(counts)
    assert within(sum(counts) / trials, 0.8, math.sqrt(0.8 * 0.2 / trials))


def test_the_sensor_sees_only_free_objects_in_reach_and_in_view():
    """A 90° cone about body z: objects within 45° of it are seen, in reach and free."""

    def at(degrees: float, distance: float) -> np.ndarray:
        """A point ``degrees`` from body z towards body x, ``distance`` m away."""
        angle = math.radians(degrees)
        return rotate(TURNED, distance * np.array([math.sin(angle), 0.0, math.cos(angle)]))

    positions = [at(0, 50), at(44, 50), at(46, 50), at(120, 50), at(10, 99), at(10, 101), at(5, 20)]
    free = [True, True, True, True, True, True, False]
    model = object_model(
        catalogue(7), field_of_view=90.0, boresight=[0.0, 0.0, 2.0], detection_probability=1.0
    )
    assert [d.id for d in seen(model, 0.0, positions, free)] == [100, 101, 104]
    all_round = object_model(catalogue(7), detection_probability=1.0)
    assert [d.id for d in seen(all_round, 0.0, positions, free)] == [100, 101, 102, 103, 104]


def test_detections_carry_the_catalogue_and_read_only_arrays():
    objects = catalogue(2)
    positions = [[20.0, 0, 0], [0, 30.0, 0]]
    plain = seen(object_model(objects, detection_probability=1.0), 0.0, positions)
    shapes = seen(
        object_model(objects, detection_probability=1.0, sees_shapes=True), 0.0, positions
    )
    assert [(d.id, d.kind, d.mass, d.shape) for d in plain] == [
        (100, ObjectKind.TARGET, 1.0, None),
        (101, ObjectKind.OBSTACLE, 2.0, None),
    ]
    assert [d.radius for d in plain] == [0.5, 3.0]
    assert [d.shape for d in shapes] == [o.shape for o in objects]
    for d in plain:
        assert d.relative_position.dtype == float and not d.relative_position.flags.writeable
        assert d.covariance.shape == (3, 3) and not d.covariance.flags.writeable
        assert np.array_equal(d.covariance, d.covariance.T)
        assert np.all(np.linalg.eigvalsh(d.covariance) > 0)


def test_a_tumbling_body_s_measured_attitude_errs_by_the_attitude_noise_about_each_axis():
    """The rotation from the true to the measured attitude has, about each world axis,
    a zero-mean error of the attitude noise; the detection reports that covariance and
    the catalogue inertia. An object whose rotation the world does not model (NaN row)
    gets no attitude, nor does any object when the sensor has no attitude noise."""
    inertia = np.diag([900.0, 1100.0, 1400.0])
    objects = (
        catalogue(1)[0],
        KnownObject(
            id=7, kind=ObjectKind.TARGET, mass=1400.0, shape=Shape(radius=3.3), inertia=inertia
        ),
    )
    positions = np.array([[20.0, 0.0, 0.0], [0.0, 4.0, 0.0]])
    attitudes = np.array([[np.nan] * 4, TURNED])

    def measured(model: ObjectSensor, t: float) -> tuple:
        state = truth(
            t,
            object_positions=positions,
            object_velocities=np.zeros_like(positions),
            free=np.ones(2, dtype=bool),
            object_attitudes=attitudes,
        )
        return model.measure(state)

    model = object_model(objects, detection_probability=1.0, attitude_noise=1.0)
    errors = []
    for t in ticks(1000.0):
        plain, tumbling = measured(model, t)
        assert plain.attitude is None and plain.inertia is None
        errors.append(
            rotation_vector(quaternion_multiply(tumbling.attitude, quaternion_conjugate(TURNED)))
        )
    assert np.array_equal(tumbling.attitude_covariance, math.radians(1.0) ** 2 * np.eye(3))
    assert np.array_equal(tumbling.inertia, inertia)
    errors_ = np.array(errors)
    n, sigma = len(errors_), math.radians(1.0)
    assert np.all(np.abs(errors_.std(axis=0) / sigma - 1) < 4 / math.sqrt(2 * n))
    assert np.all(np.abs(errors_.mean(axis=0)) < 4 * sigma / math.sqrt(n))
    blind = object_model(objects, detection_probability=1.0)
    assert [d.attitude for d in measured(blind, 0.0)] == [None, None]


def test_the_object_sensor_reads_at_ten_hertz_by_default():
    model = ObjectSensor({"detection_probability": 1.0}, np.random.default_rng(0))
    model.reset(SensorSetup(control_period=0.05, object_range=100.0, objects=catalogue(1)))
    read = [t for t in ticks(5.0, 0.05) if seen(model, t, [[10.0, 0, 0]])]
    assert read == pytest.approx(np.arange(0.0, 5.0, 0.1))


def test_a_zero_boresight_is_refused_with_advice():
    with pytest.raises(PluginParameterError, match="boresight must not be zero"):
        ObjectSensor({"boresight": [0, 0, 0]})


# --- in a run --------------------------------------------------------------------------


def test_the_default_scenario_flies_on_the_star_tracker_and_gyros():
    """Under the ideal profile with the realistic star tracker and gyros given, the
    estimate's attitude is the tracker's (arcseconds off the truth, held between its
    5 Hz readings) and its angular velocity the gyros' (noisy about the truth)."""
    runner = open_run(
        None,
        {
            "world.duration": 20.0,
            "sensors.star_tracker": {
                "model": "star-tracker",
                "params": {"misalignment": [10, 10, 10]},
            },
            "sensors.gyros": {"model": "gyros"},
        },
    )
    angles, rate_errors = [], []
    while not runner.ended:
        truth_now = runner.outputs
        estimate = runner.estimate
        if estimate.time == pytest.approx(truth_now["time"], abs=1e-9):
            error = quaternion_multiply(
                quaternion_conjugate(truth_now["attitude"]), estimate.attitude
            )
            angles.append(np.linalg.norm(rotation_vector(error)) / ARCSEC)
            rate_errors.append(estimate.angular_velocity - truth_now["angular_velocity"])
        runner.advance()
    result = close_run(runner)
    assert result.status == "completed"
    assert len(angles) > 150
    assert 5.0 < np.median(angles) < 200.0
    sigma = 0.15 * DEG_PER_ROOT_HOUR / math.sqrt(PERIOD)
    assert np.std(rate_errors) == pytest.approx(sigma, rel=0.2)
