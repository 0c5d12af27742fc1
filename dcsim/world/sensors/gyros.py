"""``gyros``: the base's angular velocity with angle random walk and a drifting bias.

Farrenkopf's gyro model in its discrete form (Crassidis & Junkins, *Optimal Estimation
of Dynamic Systems*, 2nd ed., 2011, the gyro model of its attitude estimation): over a
sampling interval ``Δt`` (s) each axis reads

    ω_meas = ω_true + ½(β_k+1 + β_k) + √(σ_v²/Δt + σ_u²Δt/12) · N_v,
    β_k+1  = β_k + σ_u √Δt · N_u,

with ``ω_true`` the base's angular velocity in the body frame (rad/s), ``β`` the bias
(rad/s), ``N_v`` and ``N_u`` independent standard normal draws, ``σ_v`` the angle
random walk (rad/√s) and ``σ_u`` the rate random walk (rad/s/√s). The bias starts at
``β_0 ~ N(0, σ_β0²)`` per axis, drawn once when the run starts. ``Δt`` is the time since
the previous reading (the sampling interval, or the control period without a rate);
the first reading, at t = 0, takes the nominal interval. A reading's ``sigma`` is the
white part's standard deviation, ``√(σ_v²/Δt + σ_u²Δt/12)``.

Parameters come in datasheet units: ``angle_random_walk`` in °/√h
(``σ_v = ARW · π/180 / 60``), ``rate_random_walk`` in °/h/√h
(``σ_u = RRW · π/180 / 3600 / 60``), ``initial_bias`` in °/h (``σ_β0 = b · π/180 / 3600``).
"""

from __future__ import annotations

import math

from dcsim.api import (
    PluginParams,
    RateReading,
    SensedTruth,
    SensorModel,
    SensorSetup,
    hookimpl,
    quantity,
)
from dcsim.geometry import quaternion_conjugate, rotate
from dcsim.world.sensors.sampling import SampleClock, rate_field

DEG_PER_HOUR = math.pi / 180.0 / 3600.0
"""One degree per hour, rad/s."""
DEG_PER_ROOT_HOUR = math.pi / 180.0 / 60.0
"""One degree per √hour, rad/√s."""


class GyrosParams(PluginParams):
    """Parameters of :class:`Gyros`."""

    angle_random_walk: float = quantity(
        0.15, unit="deg/sqrt(h)", ge=0, description="Angle random walk (white rate noise)."
    )
    rate_random_walk: float = quantity(
        0.95, unit="deg/h/sqrt(h)", ge=0, description="Rate random walk of the bias."
    )
    initial_bias: float = quantity(
        0.5, unit="deg/h", ge=0, description="1σ per axis of the bias when the run starts."
    )
    rate: float | None = rate_field(None)


class Gyros(SensorModel):
    """The base's body-frame angular velocity, noisy and biased (Farrenkopf's model).

    Attributes
    ----------
    bias : ndarray (3,)
        The bias at the latest reading (at the start, before the first), body frame,
        rad/s.
    """

    name = "gyros"
    summary = "Body rates with angle random walk and a random-walk bias (Farrenkopf)"
    measures = "gyros"
    Params = GyrosParams
    params: GyrosParams

    def reset(self, setup: SensorSetup) -> None:
        """Draw the initial bias and start the clock (the first reading is at t = 0)."""
        params = self.params
        self._clock = SampleClock(params.rate)
        self._nominal = max(setup.control_period, 1.0 / params.rate if params.rate else 0.0)
        self._sigma_v = params.angle_random_walk * DEG_PER_ROOT_HOUR
        self._sigma_u = params.rate_random_walk * DEG_PER_HOUR / 60.0
        self.bias = self.rng.normal(0.0, params.initial_bias * DEG_PER_HOUR, 3)
        self._last: float | None = None

    def measure(self, truth: SensedTruth) -> RateReading | None:
        """The measured body-frame angular velocity now (rad/s), or None between
        readings (and when asked again at the instant of the latest reading)."""
        time = truth.time
        if (self._last is not None and time <= self._last) or not self._clock.due(time):
            return None
        dt = self._nominal if self._last is None else time - self._last
        self._last = time
        white, walk = self.rng.standard_normal((2, 3))
        bias = self.bias + self._sigma_u * math.sqrt(dt) * walk
        sigma = math.sqrt(self._sigma_v**2 / dt + self._sigma_u**2 * dt / 12.0)
        body = rotate(quaternion_conjugate(truth.attitude), truth.angular_velocity)
        rate = body + 0.5 * (self.bias + bias) + sigma * white
        self.bias = bias
        rate.setflags(write=False)
        return RateReading.trusted(time=time, angular_velocity=rate, sigma=sigma)


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the gyro model."""
    return [Gyros]
