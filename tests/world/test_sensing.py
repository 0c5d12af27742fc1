"""The sensing seam: sensor models chosen per sensor, their readings gathered each tick,
the estimate's attitude from the sensors, failures named, the tracker's role."""

from __future__ import annotations

import numpy as np
import pytest
from dcsim_plugins.localisers.ekf import EKFLocaliser

from dcsim.api import (
    AttitudeReading,
    Observations,
    PluginRegistry,
    RateReading,
    SensorModel,
    quantity,
)
from dcsim.errors import ScenarioError
from dcsim.geometry import quaternion_multiply, rotate
from dcsim.missions import scenario_roles
from dcsim.params import PluginParams
from dcsim.registry.discovery import PluginOrigin
from dcsim.run.loop import Runner
from dcsim.run.setup import setup_run
from dcsim.scenario.model import SensorChoice, SensorsSection
from dcsim.scenario.sensors import REALISTIC, sensor_choices

ORIGIN = PluginOrigin("tests", "0", "tests")
TILT = np.array([np.sin(0.05), 0.0, 0.0, np.cos(0.05)])  # 0.1 rad about x


class EveryOtherTickParams(PluginParams):
    fails_at: float = quantity(-1.0, unit="s", description="Raise from this time on (< 0: never).")


class TiltedStarTracker(SensorModel):
    """Reports the truth turned 0.1 rad about body x, every other tick (test)."""

    name = "tilted"
    summary = "A star tracker tilted by 0.1 rad, every other tick (test)"
    measures = "star_tracker"
    Params = EveryOtherTickParams

    def reset(self, setup):
        self.ticks = 0

    def measure(self, truth):
        self.ticks += 1
        if 0 <= self.params.fails_at <= truth.time:
            raise RuntimeError("lens cap on")
        if self.ticks % 2 == 0:
            return None
        q = quaternion_multiply(truth.attitude, TILT)
        return AttitudeReading(truth.time, q, sigma=[1e-5] * 3)


class SpinningGyros(SensorModel):
    """Report a body rate of 0.01 rad/s about z whatever the truth (test)."""

    name = "spinning"
    summary = "Gyros stuck at 0.01 rad/s about z (test)"
    measures = "gyros"

    def reset(self, setup):
        pass

    def measure(self, truth):
        return RateReading(truth.time, [0.0, 0.0, 0.01], sigma=1e-6)


class SlowGyros(SpinningGyros):
    """Read on every other tick, as the tilted star tracker does (test)."""

    name = "slow"
    summary = "Gyros reading every other tick (test)"

    def reset(self, setup):
        self.ticks = 0

    def measure(self, truth):
        self.ticks += 1
        return super().measure(truth) if self.ticks % 2 else None


class WrongAnswerGyros(SpinningGyros):
    """Answer a bare array (test)."""

    name = "wrong-answer"
    summary = "Gyros that answer an array (test)"

    def measure(self, truth):
        return np.zeros(3)


class AttitudeEstimatingEKF(EKFLocaliser):
    """The EKF, declaring that it estimates attitude (keeps the prior's: identity)."""

    name = "ekf-attitude"
    summary = "EKF that says it estimates attitude (test)"
    estimates_attitude = True

    def update_attitude(self, attitude, rate):
        self.readings = getattr(self, "readings", 0) + (attitude is not None)


def registry() -> PluginRegistry:
    found = PluginRegistry.discover()
    for cls in (
        TiltedStarTracker,
        SpinningGyros,
        SlowGyros,
        WrongAnswerGyros,
        AttitudeEstimatingEKF,
    ):
        found.register_class(cls, ORIGIN)
    return found


def opened(*overrides: str) -> Runner:
    runner = Runner(setup_run(None, ["world.duration=1", *overrides], registry=registry()))
    runner.open()
    return runner


def test_ideal_sensing_reports_the_truth_and_exact_tracks():
    runner = opened()
    world = runner.world
    observations = world.observations()
    position, _, attitude, angular_velocity = world.base_state()
    assert np.array_equal(observations.attitude, attitude)
    assert np.array_equal(observations.angular_velocity, angular_velocity)
    assert observations.star_tracker is None and observations.gyros is None
    assert observations.detections == ()
    assert observations.tracks, "the default scenario's objects are in sensor range"
    for track in observations.tracks:
        obj = world.field.objects[world.field.index[track.id]]
        assert track.motion is obj.motion and track.covariance is None
        assert np.array_equal(track.position, obj.motion.state_at(world.time)[0])
    assert "tracker" not in runner.plugins
    runner.close()


def test_a_star_tracker_model_gives_the_attitude_held_between_its_readings():
    runner = opened("sensors.star_tracker={model: tilted}")
    world = runner.world
    truth = world.base_state()[2]
    assert not np.allclose(runner.estimate.attitude, truth), "the estimate is the reading"
    first = world.observations()  # the model's second call: no reading, the last one held
    second = world.observations()
    assert first.star_tracker is None and second.star_tracker is not None
    assert np.array_equal(first.attitude, runner.estimate.attitude)
    tilt = 2 * np.arccos(min(1.0, abs(float(np.dot(second.attitude, truth)))))
    assert tilt == pytest.approx(0.1, abs=1e-9)
    # without a gyro model the gyros report the truth, in the reading's frame
    body = rotate(truth * [-1, -1, -1, 1], world.base_state()[3])
    assert np.allclose(second.angular_velocity, rotate(second.attitude, body), atol=1e-15)
    runner.close()


def test_gyro_readings_become_the_estimate_s_rate_in_the_world_frame():
    runner = opened("sensors.gyros={model: spinning}")
    expected = rotate(runner.estimate.attitude, [0.0, 0.0, 0.01])
    assert np.allclose(runner.estimate.angular_velocity, expected)
    assert not np.allclose(runner.estimate.angular_velocity, runner.world.base_state()[3])
    runner.close()


def test_a_localiser_that_estimates_attitude_keeps_its_own():
    runner = opened(
        "sensors.star_tracker={model: tilted}",
        "sensors.gyros={model: slow}",
        "localiser.plugin=ekf-attitude",
    )
    assert np.array_equal(runner.estimate.attitude, [0.0, 0.0, 0.0, 1.0])
    runner.advance()  # a tick on which neither sensor reads: still its own
    assert np.array_equal(runner.estimate.attitude, [0.0, 0.0, 0.0, 1.0])
    assert runner.plugins["localiser"].readings == 1
    runner.close()


def test_a_sensor_model_that_raises_is_named():
    runner = Runner(
        setup_run(
            None,
            ["world.duration=2", "sensors.star_tracker={model: tilted, params: {fails_at: 0.5}}"],
            registry=registry(),
        )
    )
    summary = runner.run()
    assert summary["status"] == "failed"
    assert (
        "sensors.star_tracker plugin 'tilted' raised in measure() at t = 0.5 s"
        in (summary["reason"])
    )


def test_a_sensor_model_that_answers_wrongly_is_named():
    setup = setup_run(None, ["sensors.gyros={model: wrong-answer}"], registry=registry())
    summary = Runner(setup).run()
    assert summary["status"] == "failed"
    assert summary["reason"].startswith(
        "sensors.gyros plugin 'wrong-answer' broke its contract in measure() at t = 0 s: "
        "returned ndarray; expected the readings its sensor gives"
    )


@pytest.mark.parametrize(
    ("override", "message"),
    [
        ("sensors.gyros={model: tilted}", "sensor model 'tilted' measures star_tracker, not gyros"),
        ("sensors.gyros={model: nonesuch}", "nonesuch"),
        ("sensors.gyros={model: spinning, params: {nope: 1}}", "sensors.gyros.params.nope"),
    ],
)
def test_bad_sensor_choices_are_scenario_errors(override, message):
    with pytest.raises(ScenarioError, match=message):
        setup_run(None, [override], registry=registry())


def test_the_tracker_runs_only_under_an_object_sensor_model():
    ideal = setup_run(None, [], registry=registry())
    assert "tracker" not in scenario_roles(ideal.scenario)
    tracked = ideal.scenario.model_copy(
        update={"sensors": SensorsSection(objects=SensorChoice(model="object-sensor"))}
    )
    assert "tracker" in scenario_roles(tracked)


def test_a_sensor_given_with_its_profile_s_model_keeps_the_profile_s_numbers():
    section = SensorsSection(
        profile="realistic", gyros=SensorChoice(model="gyros", params={"initial_bias": 0.0})
    )
    choices = sensor_choices(section)
    assert choices["gyros"].params == {**REALISTIC["gyros"].params, "initial_bias": 0.0}
    assert choices["star_tracker"] == REALISTIC["star_tracker"]
    other = SensorsSection(profile="realistic", gyros=SensorChoice(model="spinning"))
    assert sensor_choices(other)["gyros"] == SensorChoice(model="spinning")
    assert sensor_choices(SensorsSection())["objects"] is None


def test_a_non_finite_number_in_any_track_or_reading_is_named():
    from dcsim.messages import BeaconRange, ObjectKind, ObjectTrack
    from dcsim.registry.answers import output_problem

    good = ObjectTrack(1, ObjectKind.OBSTACLE, 0.0, [0, 0, 0], [0, 0, 0], radius=1.0)
    bad = ObjectTrack(2, ObjectKind.OBSTACLE, 0.0, [0, np.nan, 0], [0, 0, 0], radius=1.0)
    assert output_problem("tracker", "update", (good, good)) is None
    assert output_problem("tracker", "update", (good, bad)) == (
        "returned non-finite numbers: position [0.0, nan, 0.0] in [1]"
    )
    far = BeaconRange(0, [1.0, 0.0, 0.0], range=np.inf, sigma=0.1)
    assert output_problem("sensor", "measure", (far,), measures="beacon_ranges") == (
        "returned non-finite numbers: range inf in [0]"
    )
    assert output_problem("sensor", "measure", [far], measures="beacon_ranges") == ("returned list")


def test_sensors_asked_twice_at_one_instant_give_nothing_new():
    runner = opened("sensors.profile=realistic")
    world = runner.world
    again = world.observations()  # the runner read the sensors at t = 0 already
    assert again.gyros is None and again.star_tracker is None
    assert np.array_equal(again.attitude, runner.estimate.attitude)
    runner.close()


@pytest.mark.parametrize("profile", ["ideal", "realistic"])
def test_observations_are_what_their_constructor_would_build_and_read_only(profile):
    runner = opened(f"sensors.profile={profile}")
    for _ in range(9):  # the star tracker and the gyros read at their own rates
        observations = runner.world.observations()
        assert Observations(**vars(observations)) == observations
        for value in vars(observations).values():
            assert not isinstance(value, np.ndarray) or not value.flags.writeable
        runner.advance()
    runner.close()
