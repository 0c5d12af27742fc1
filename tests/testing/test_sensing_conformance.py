"""The sensor-model and tracker contracts: a plain model and the kalman tracker keep them,
and broken ones are caught by the check that names what they break."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from dcsim_plugins.trackers.kalman import KalmanTracker

from dcsim.api import (
    AttitudeReading,
    Detection,
    ObjectTrack,
    PluginParams,
    RateReading,
    SensorModel,
    quaternion_multiply,
)
from dcsim.testing import SensorModelContract, TrackerContract, check_plugin, checks_for


class TruthfulStarTracker(SensorModel):
    """The true attitude, with white noise about each axis, every tick."""

    name = "truthful"
    summary = "The true attitude with white noise (test)"
    measures = "star_tracker"
    Params = PluginParams

    def reset(self, setup):
        self.setup = setup

    def measure(self, truth):
        turn = self.rng.normal(0.0, 1e-5, 3)
        x, y, z = 0.5 * turn
        q = np.array([x, y, z, 1.0]) / np.sqrt(1.0 + x * x + y * y + z * z)
        attitude = quaternion_multiply(q, truth.attitude)
        return AttitudeReading(truth.time, attitude, np.full(3, 1e-5))


class TruthfulObjectSensor(SensorModel):
    """Every free object within range, exactly."""

    name = "truthful-objects"
    summary = "Every free object in range, exactly (test)"
    measures = "objects"
    Params = PluginParams

    def reset(self, setup):
        self.setup = setup

    def measure(self, truth):
        offsets = truth.object_positions - truth.position
        return tuple(
            Detection(
                time=truth.time,
                id=obj.id,
                kind=obj.kind,
                relative_position=offset,
                covariance=np.eye(3) * 1e-6,
                radius=obj.shape.bounding_radius,
                mass=obj.mass,
            )
            for obj, offset, free in zip(self.setup.objects, offsets, truth.free, strict=True)
            if free and np.linalg.norm(offset) <= self.setup.object_range
        )


class SlotlessSensor(TruthfulStarTracker):
    name = "slotless"
    summary = "Measures a sensor the robot does not carry (test)"
    measures = "sextant"


class MislabelledSensor(TruthfulStarTracker):
    name = "mislabelled"
    summary = "Says it is the gyros, reads the star tracker (test)"
    measures = "gyros"


class ProphetSensor(TruthfulStarTracker):
    name = "prophet"
    summary = "Dates its readings a tick ahead (test)"

    def measure(self, truth):
        reading = super().measure(truth)
        return dataclasses.replace(reading, time=truth.time + 0.1)


class SilentSensor(TruthfulStarTracker):
    name = "silent"
    summary = "Never gives a reading (test)"

    def measure(self, truth):
        return None


class UnseededGyros(SensorModel):
    name = "unseeded"
    summary = "Draws its noise from an unseeded generator (test)"
    measures = "gyros"
    Params = PluginParams

    def reset(self, setup):
        self.noise = np.random.default_rng()

    def measure(self, truth):
        return RateReading(truth.time, self.noise.normal(0.0, 1e-4, 3), 1e-4)


class ClairvoyantSensor(TruthfulObjectSensor):
    name = "clairvoyant"
    summary = "Sees held objects and objects beyond its range (test)"

    def measure(self, truth):
        offsets = truth.object_positions - truth.position
        return tuple(
            Detection(
                time=truth.time,
                id=obj.id,
                kind=obj.kind,
                relative_position=offset,
                covariance=np.eye(3) * 1e-6,
                radius=1.0,
            )
            for obj, offset in zip(self.setup.objects, offsets, strict=True)
        )


class ForgetfulTracker(KalmanTracker):
    name = "forgetful"
    summary = "Drops the tracks of odd identities (test)"

    def update(self, time, detections, robot):
        return tuple(t for t in super().update(time, detections, robot) if t.id % 2 == 0)


class VagueTracker(KalmanTracker):
    name = "vague"
    summary = "Gives tracks without covariances (test)"

    def update(self, time, detections, robot):
        tracks = super().update(time, detections, robot)
        return tuple(dataclasses.replace(t, covariance=None) for t in tracks)


class OverconfidentTracker(KalmanTracker):
    name = "overconfident"
    summary = "Claims a hundredth of its covariance (test)"

    def update(self, time, detections, robot):
        tracks = super().update(time, detections, robot)
        return tuple(dataclasses.replace(t, covariance=t.covariance / 100.0) for t in tracks)


class OverwideTracker(KalmanTracker):
    name = "overwide"
    summary = "Claims a shape margin wider than its tracks' radius (test)"

    def update(self, time, detections, robot):
        tracks = super().update(time, detections, robot)
        return tuple(
            ObjectTrack.trusted(**{**t.__dict__, "shape_margin": t.radius + 0.5}) for t in tracks
        )


class LaggingTracker(KalmanTracker):
    name = "lagging"
    summary = "Answers the previous tick's tracks (test)"

    def update(self, time, detections, robot):
        previous = getattr(self, "previous", ())
        self.previous = super().update(time, detections, robot)
        return previous


def failed_checks(plugin) -> dict[str, str]:
    return {r.check: r.message for r in check_plugin(plugin) if not r.passed}


@pytest.mark.parametrize("plugin", [TruthfulStarTracker, TruthfulObjectSensor, KalmanTracker])
def test_plain_plugins_keep_every_contract(plugin):
    assert failed_checks(plugin) == {}


@pytest.mark.parametrize(
    "plugin, failing",
    [
        (SlotlessSensor, {"measures_a_sensor_slot", "reads_its_sensor"}),
        (MislabelledSensor, {"reads_its_sensor", "outputs_well_formed"}),
        (ProphetSensor, {"reads_its_sensor"}),
        (SilentSensor, {"reads_its_sensor"}),
        (UnseededGyros, {"deterministic"}),
        (ClairvoyantSensor, {"reads_its_sensor"}),
        (ForgetfulTracker, {"keeps_the_detected_objects"}),
        (VagueTracker, {"keeps_the_detected_objects"}),
        (OverconfidentTracker, {"follows_within_its_covariance"}),
        (LaggingTracker, {"keeps_the_detected_objects"}),
        (OverwideTracker, {"keeps_the_detected_objects"}),
    ],
    ids=lambda value: getattr(value, "name", None) or "-".join(sorted(value)),
)
def test_broken_sensors_and_trackers_are_reported_by_the_right_check(plugin, failing):
    failed = failed_checks(plugin)
    assert failing <= set(failed), failed
    for name in failing:
        assert f"plugin '{plugin.name}' breaks '{name}'" in failed[name]


def test_the_overwide_tracker_is_told_its_margin_exceeds_the_radius():
    message = failed_checks(OverwideTracker)["keeps_the_detected_objects"]
    assert "has a shape margin of" in message and "for a radius of" in message


def test_the_clairvoyant_sensor_is_told_what_it_cannot_see():
    message = failed_checks(ClairvoyantSensor)["reads_its_sensor"]
    assert "beyond 30 m" in message or "not free" in message


class TestSensorContract(SensorModelContract):
    plugin = TruthfulStarTracker


class TestTrackerContract(TrackerContract):
    plugin = KalmanTracker


def test_the_contract_classes_have_one_test_per_check_of_their_kind():
    for cls, kind in ((TestSensorContract, "sensor"), (TestTrackerContract, "tracker")):
        names = {n for n in dir(cls) if n.startswith("test_")}
        assert names == {f"test_{c.name}" for c in checks_for(kind)}
