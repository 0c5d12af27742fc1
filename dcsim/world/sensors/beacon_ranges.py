"""``beacon-range``: ranges to the localisation beacons, with white noise, a bias,
outliers and dropouts.

The source thesis's Beacon topic. At each reading the sensor ranges the beacons within
``beacons.max_range`` and reports the ``beacons.report_nearest`` nearest. Beacon ``i``
at true distance ``d_i`` (m) gives

    r_i = d_i + b + n_i + o_i,   n_i ~ N(0, σ²),   o_i ~ N(0, s²) with probability p_o
                                                   (else 0),

with ``σ`` the scenario's ``beacons.noise_sigma``, ``b`` the ``bias``, ``p_o`` the
``outlier_probability`` and ``s`` the ``outlier_size``; each range is then lost with
probability ``dropout_probability`` (the beacon is not replaced by the next nearest).
A range's reported ``sigma`` is ``σ``: a localiser is told the white noise only.

With every parameter at its default the model draws ``N(0, σ)`` once per range and
reading and nothing else, so scenarios fly as before; outliers and dropouts draw only
when enabled.
"""

from __future__ import annotations

import math

import numpy as np

from dcsim.api import (
    BeaconRange,
    PluginParams,
    SensedTruth,
    SensorModel,
    SensorSetup,
    hookimpl,
    quantity,
)
from dcsim.geometry import row_lengths
from dcsim.world.sensors.sampling import SampleClock, rate_field


class BeaconRangeParams(PluginParams):
    """Parameters of :class:`BeaconRangeSensor`."""

    bias: float = quantity(
        0.0, unit="m", description="Constant added to every range (not told to the localiser)."
    )
    outlier_probability: float = quantity(
        0.0, ge=0, le=1, description="Probability that a range is an outlier."
    )
    outlier_size: float = quantity(
        1.0,
        unit="m",
        ge=0,
        description="Standard deviation of the extra Gaussian error an outlier gets.",
    )
    dropout_probability: float = quantity(
        0.0, ge=0, le=1, description="Probability that a range is lost."
    )
    rate: float | None = rate_field(None)


class BeaconRangeSensor(SensorModel):
    """Noisy ranges to the nearest beacons in reach."""

    name = "beacon-range"
    summary = "Ranges to the nearest beacons: white noise, bias, outliers, dropouts"
    measures = "beacon_ranges"
    Params = BeaconRangeParams
    params: BeaconRangeParams

    def reset(self, setup: SensorSetup) -> None:
        """Keep the beacons and the sensor's noise, reach and count; start the clock."""
        self.setup = setup
        self._rows = list(setup.beacons)  # each beacon's position, a read-only view
        self._clock = SampleClock(self.params.rate)

    def measure(self, truth: SensedTruth) -> tuple[BeaconRange, ...]:
        """The ranges from the robot's true position now (m), nearest first; none
        between readings."""
        setup = self.setup
        beacons = setup.beacons
        if len(beacons) == 0 or not self._clock.due(truth.time):
            return ()
        distances = row_lengths(beacons - truth.position)
        order = distances.argsort(kind="stable")
        if math.isfinite(setup.beacon_max_range):
            order = order[distances[order] <= setup.beacon_max_range]
        order = order[: setup.beacon_report_nearest]
        sigma = float(setup.beacon_noise)
        noise = self.rng.normal(0.0, sigma, len(order)) if sigma else 0.0
        measured = distances[order] + noise + self._errors(len(order))
        kept = self._kept(len(order))
        if kept is not None:
            order, measured = order[kept], measured[kept]
        rows = self._rows
        return tuple(
            [
                BeaconRange.trusted(beacon_id=i, beacon_position=rows[i], range=r, sigma=sigma)
                for i, r in zip(order.tolist(), measured.tolist(), strict=True)
            ]
        )

    def _errors(self, count: int) -> float | np.ndarray:
        """The bias plus each of ``count`` ranges' outlier error, m (drawn only when
        outliers may happen)."""
        params = self.params
        if params.outlier_probability == 0.0:
            return params.bias
        outlier = self.rng.random(count) < params.outlier_probability
        size = self.rng.normal(0.0, params.outlier_size, count)
        return params.bias + np.where(outlier, size, 0.0)

    def _kept(self, count: int) -> np.ndarray | None:
        """Which of ``count`` ranges survive dropouts, or None when none can be lost."""
        if self.params.dropout_probability == 0.0:
            return None
        return self.rng.random(count) >= self.params.dropout_probability


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the beacon range sensor model."""
    return [BeaconRangeSensor]
