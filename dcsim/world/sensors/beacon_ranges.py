"""``beacon-range``: ranges to the localisation beacons, with white noise.

The source thesis's Beacon topic. At each reading the sensor ranges the beacons within
``beacons.max_range`` and reports the ``beacons.report_nearest`` nearest, each the true
distance plus white Gaussian noise of ``beacons.noise_sigma`` (m).
"""

from __future__ import annotations

import numpy as np

from dcsim.api import (
    BeaconRange,
    PluginParams,
    SensedTruth,
    SensorModel,
    SensorSetup,
    hookimpl,
)
from dcsim.geometry import row_lengths


class BeaconRangeParams(PluginParams):
    """Parameters of :class:`BeaconRangeSensor`."""


class BeaconRangeSensor(SensorModel):
    """Noisy ranges to the nearest beacons in reach."""

    name = "beacon-range"
    summary = "Ranges to the nearest beacons with white Gaussian noise"
    measures = "beacon_ranges"
    Params = BeaconRangeParams
    params: BeaconRangeParams

    def reset(self, setup: SensorSetup) -> None:
        """Keep the beacons and the sensor's noise, reach and count."""
        self.setup = setup

    def measure(self, truth: SensedTruth) -> tuple[BeaconRange, ...]:
        """The ranges from the robot's true position now (m), nearest first."""
        setup = self.setup
        beacons = setup.beacons
        if len(beacons) == 0:
            return ()
        distances = row_lengths(beacons - truth.position)
        order = np.argsort(distances, kind="stable")
        if np.isfinite(setup.beacon_max_range):
            order = order[distances[order] <= setup.beacon_max_range]
        order = order[: setup.beacon_report_nearest]
        sigma = float(setup.beacon_noise)
        noise = self.rng.normal(0.0, sigma, len(order)) if sigma else 0.0
        measured = distances[order] + noise
        return tuple(
            BeaconRange.trusted(beacon_id=i, beacon_position=beacons[i], range=r, sigma=sigma)
            for i, r in zip(order.tolist(), np.atleast_1d(measured).tolist(), strict=True)
        )


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the beacon range sensor model."""
    return [BeaconRangeSensor]
