"""The collector's sensors: beacon ranges, object tracks, star tracker and gyros.

They follow the source thesis's topics (Beacon, Objects). Readings are taken from the
true state the world passes in; only the beacon ranges are noisy, drawn from the
world's generator.
"""

from __future__ import annotations

import numpy as np

from dcsim.geometry import row_lengths
from dcsim.messages import BeaconRange, ObjectTrack, Observations
from dcsim.scenario.model import BeaconsSection, point_to_cartesian
from dcsim.world.objects import ObjectField


class Sensors:
    """Every sensor of the collector, reading a world's objects and beacons.

    Parameters
    ----------
    beacons : BeaconsSection
        The beacons and their range sensor (noise, reach, readings per step).
    sensor_range : float
        Range of the object sensor, m.
    field : ObjectField
        The world's objects.
    rng : numpy.random.Generator
        The world's generator (range noise).

    Attributes
    ----------
    beacons : ndarray (B, 3)
        Beacon positions, world frame, m (read-only).
    """

    def __init__(
        self,
        beacons: BeaconsSection,
        sensor_range: float,
        field: ObjectField,
        rng: np.random.Generator,
    ) -> None:
        self.beacons = (
            np.array([point_to_cartesian(p) for p in beacons.positions]).reshape(-1, 3).copy()
        )  # its own data, not a view of the list's array
        self.beacons.setflags(write=False)  # shared by every range message, not copied
        self._settings = beacons
        self._sensor_range = sensor_range
        self._field = field
        self._rng = rng

    def beacon_ranges(self, position: np.ndarray) -> list[BeaconRange]:
        """Noisy ranges from ``position`` (m, world frame) to the nearest beacons within range."""
        if len(self.beacons) == 0:
            return []
        settings = self._settings
        distances = row_lengths(self.beacons - position)
        order = np.argsort(distances, kind="stable")
        if settings.max_range is not None:
            order = order[distances[order] <= settings.max_range]
        order = order[: settings.report_nearest]
        noise = (
            self._rng.normal(0.0, settings.noise_sigma, len(order)) if settings.noise_sigma else 0.0
        )
        measured = distances[order] + noise
        sigma = float(settings.noise_sigma)
        return [
            BeaconRange.trusted(beacon_id=i, beacon_position=self.beacons[i], range=r, sigma=sigma)
            for i, r in zip(order.tolist(), np.atleast_1d(measured).tolist(), strict=True)
        ]

    def object_tracks(self, time: float, position: np.ndarray) -> list[ObjectTrack]:
        """Tracks at ``time`` (s) of the free objects within sensor range of ``position`` (m).

        Each track carries its object's shape and, as ``radius``, its bounding radius.
        """
        positions, velocities = self._field.free_states(time)
        if len(positions) == 0:
            return []
        distances = row_lengths(positions - position)
        visible = np.flatnonzero(self._field.free_mask() & (distances <= self._sensor_range))
        return [
            ObjectTrack.trusted(
                id=obj.id,
                kind=obj.kind,
                time=time,
                position=positions[i],
                velocity=velocities[i],
                mass=obj.mass,
                radius=obj.radius,
                motion=obj.motion,
                shape=obj.shape,
            )
            for i in visible
            for obj in (self._field.objects[i],)
        ]

    def observations(
        self,
        time: float,
        position: np.ndarray,
        attitude: np.ndarray,
        angular_velocity: np.ndarray,
    ) -> Observations:
        """Every sensor's reading at ``time`` (s) from the collector's true state.

        Parameters
        ----------
        time : float
            s.
        position : ndarray (3,)
            Collector position, world frame, m.
        attitude : ndarray (4,)
            Collector attitude ``[x, y, z, w]``, reported as is by the star tracker.
        angular_velocity : ndarray (3,)
            Collector angular velocity, world frame, rad/s, reported as is by the gyros.
        """
        return Observations(
            time=time,
            ranges=tuple(self.beacon_ranges(position)),
            tracks=tuple(self.object_tracks(time, position)),
            attitude=attitude,
            angular_velocity=angular_velocity,
        )
