"""``star-tracker``: the base's attitude with a fixed misalignment and white noise.

At each reading the star tracker gives

    q_meas = q_true ⊗ δq(m) ⊗ δq(n),   n ~ N(0, diag(σx², σy², σz²)),

quaternions ``[x, y, z, w]`` rotating body to world and ``⊗`` the Hamilton product
(``p ⊗ q`` turns by ``q`` first), so both error rotations act in the body frame:
``δq(v)`` is the rotation by the rotation vector ``v`` (axis times angle, rad) whose
components are about body x, y and z. ``m`` is the ``misalignment`` (fixed, the same in
every reading) and ``n`` the white noise drawn anew at each reading, with 1σ ``noise``
about each body axis (a star tracker looking along body z is poorest about z, its
boresight). The error rotation ``q_true* ⊗ q_meas`` is then ``m + n`` to first order.
The reading is a unit quaternion on the truth's side of the sphere
(``q_meas · q_true ≥ 0``), and its ``sigma`` is ``noise`` in rad: a user of it is told
the noise, not the misalignment.
"""

from __future__ import annotations

import numpy as np
from pydantic import NonNegativeFloat

from dcsim.api import (
    AttitudeReading,
    PluginParams,
    SensedTruth,
    SensorModel,
    SensorSetup,
    hookimpl,
    quantity,
)
from dcsim.geometry import quaternion_from_rotation_vector, quaternion_multiply
from dcsim.world.sensors.sampling import SampleClock, rate_field

ARCSEC = np.pi / (180.0 * 3600.0)
"""One arcsecond, rad."""


class StarTrackerParams(PluginParams):
    """Parameters of :class:`StarTracker`."""

    noise: tuple[NonNegativeFloat, NonNegativeFloat, NonNegativeFloat] = quantity(
        (6.0, 6.0, 40.0),
        unit="arcsec",
        description="1σ of the white error rotation about body x, y and z (each >= 0).",
    )
    rate: float | None = rate_field(5.0)
    misalignment: tuple[float, float, float] = quantity(
        (0.0, 0.0, 0.0),
        unit="arcsec",
        description="Fixed rotation about body x, y and z in every reading (a rotation "
        "vector's components).",
    )


class StarTracker(SensorModel):
    """The base's attitude, misaligned and noisy, at the tracker's rate."""

    name = "star-tracker"
    summary = "Attitude with white noise per body axis and a fixed misalignment"
    measures = "star_tracker"
    Params = StarTrackerParams
    params: StarTrackerParams

    def reset(self, setup: SensorSetup) -> None:
        """Start the clock (the first reading is at t = 0)."""
        self._clock = SampleClock(self.params.rate)
        self._sigma = np.array(self.params.noise, dtype=float) * ARCSEC
        self._sigma.setflags(write=False)
        self._misalignment = quaternion_from_rotation_vector(
            np.array(self.params.misalignment, dtype=float) * ARCSEC
        )

    def measure(self, truth: SensedTruth) -> AttitudeReading | None:
        """The measured attitude now, or None between readings."""
        if not self._clock.due(truth.time):
            return None
        noise = quaternion_from_rotation_vector(self.rng.normal(0.0, self._sigma))
        error = quaternion_multiply(self._misalignment, noise)
        attitude = quaternion_multiply(truth.attitude, error)
        attitude /= np.linalg.norm(attitude)
        if attitude @ truth.attitude < 0.0:
            attitude = -attitude
        attitude.setflags(write=False)
        return AttitudeReading.trusted(time=truth.time, attitude=attitude, sigma=self._sigma)


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the star tracker model."""
    return [StarTracker]
