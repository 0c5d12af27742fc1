"""The world's sensing: every sensor model of the robot read once per control tick.

The scenario's ``sensors:`` section gives each sensor a model
(:func:`dcsim.scenario.sensors.sensor_choices`), or none where the sensor reports the
truth. :class:`Sensing` builds the truth the models read, calls them, and gathers their
readings into :class:`~dcsim.messages.Observations`: beacon ranges; the attitude and
angular velocity the star tracker and the gyros give (their latest readings, held
between readings); the object sensor's detections, or, under ideal object sensing, the
exact tracks of the objects in sensor range (each with its true shape and motion).

A world with a tumbling body (a capture's target) shows it to the object sensor as one
more object after the field's, with its attitude and catalogue inertia; under ideal
object sensing its exact track (rotation and inertia included) follows the field's
tracks, wherever the robot is.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping

import numpy as np

from dcsim.geometry import quaternion_conjugate, rotate, row_lengths
from dcsim.messages import (
    AttitudeReading,
    BeaconRange,
    Detection,
    KnownObject,
    ObjectKind,
    ObjectTrack,
    Observations,
    RateReading,
    SensedTruth,
    SensorSetup,
)
from dcsim.registry.calls import call_plugin
from dcsim.registry.discovery import PluginRegistry
from dcsim.registry.interfaces import SENSOR_SLOTS, SensorModel
from dcsim.run.seeding import component_rng
from dcsim.scenario.model import BeaconsSection, InitialStateSpec, Scenario, point_to_cartesian
from dcsim.scenario.sensors import sensor_choices, sensor_model_class
from dcsim.world.capture_rig import CaptureRig
from dcsim.world.objects import ObjectField


def build_sensor_models(
    scenario: Scenario, rng: np.random.Generator, registry: PluginRegistry | None = None
) -> dict[str, SensorModel]:
    """Construct the scenario's sensor models, by sensor (those that report the truth
    are left out), from ``registry`` (the installed plugins, found once, if None).

    Each has its own generator from the scenario seed (``sensors.<sensor>``), but the
    beacon range sensor draws from ``rng``, the world's generator, as beacon noise
    always has.

    Raises
    ------
    PluginNotFoundError
        If a model is not registered.
    PluginError
        If a model measures another sensor than the one it is given for, or its
        parameters are invalid.
    """
    registry = registry if registry is not None else _installed()
    models: dict[str, SensorModel] = {}
    for slot, choice in sensor_choices(scenario.sensors).items():
        if choice is None:
            continue
        cls = sensor_model_class(registry, slot, choice.model)
        generator = (
            rng
            if slot == "beacon_ranges"
            else component_rng(scenario.world.seed, f"sensors.{slot}")
        )
        models[slot] = cls(choice.params, generator)
    return models


@functools.cache
def _installed() -> PluginRegistry:
    """The installed plugins, discovered once per process for the worlds built without a
    registry (a run passes its own)."""
    return PluginRegistry.discover()


class Sensing:
    """Every sensor of the robot, reading a world's robot, objects and beacons.

    Parameters
    ----------
    field : ObjectField
        The world's objects.
    models : mapping of str to SensorModel
        The sensor models by sensor (:data:`~dcsim.registry.interfaces.SENSOR_SLOTS`);
        a sensor without one reports the truth (beacons: none).
    beacons : BeaconsSection
        The localisation beacons (``beacons:``).
    sensor_range : float
        Reach of the object sensor (``robot.sensor_range``), m.
    control_period : float
        Time between two readings of the models, s.
    initial : InitialStateSpec
        The robot's initial state (``robot.initial``): the attitude and rate the star
        tracker and the gyros hold before their first readings.
    capture : CaptureRig or None, optional
        The world's capture rig: its tumbling body is seen by the object sensor after
        the field's objects, free until the latch holds it.

    Attributes
    ----------
    beacons : ndarray (B, 3)
        Beacon positions, world frame, m (read-only).
    models : dict of str to SensorModel
        The sensor models by sensor.
    ideal_objects : bool
        Whether the object sensor reports the truth (exact tracks, no tracker).
    ideal_attitude : bool
        Whether the star tracker and the gyros both report the truth (no model).
    """

    def __init__(
        self,
        field: ObjectField,
        models: Mapping[str, SensorModel],
        *,
        beacons: BeaconsSection,
        sensor_range: float,
        control_period: float,
        initial: InitialStateSpec,
        capture: CaptureRig | None = None,
    ) -> None:
        self.beacons = (
            np.array([point_to_cartesian(p) for p in beacons.positions]).reshape(-1, 3).copy()
        )  # its own data, not a view of the list's array
        self.beacons.setflags(write=False)  # shared by every range message, not copied
        self._sensor_range = sensor_range
        self._field = field
        self._capture = capture
        self.models = {slot: models[slot] for slot in SENSOR_SLOTS if slot in models}
        self._roles = {f"sensors.{slot}": model for slot, model in self.models.items()}
        self.ideal_objects = "objects" not in self.models
        self.ideal_attitude = "star_tracker" not in self.models and "gyros" not in self.models
        self._attitude = np.array(initial.attitude, dtype=float)
        self._attitude.setflags(write=False)
        self._body_rate = rotate(
            quaternion_conjugate(self._attitude), np.array(initial.angular_velocity, dtype=float)
        )
        setup = SensorSetup(
            control_period=control_period,
            beacons=self.beacons,
            beacon_noise=float(beacons.noise_sigma),
            beacon_max_range=np.inf if beacons.max_range is None else float(beacons.max_range),
            beacon_report_nearest=beacons.report_nearest,
            object_range=float(self._sensor_range),
            objects=_known_objects(field, capture),
        )
        for role in self._roles:
            call_plugin(self._roles, role, "reset", setup)

    def truth(
        self,
        time: float,
        position: np.ndarray,
        velocity: np.ndarray,
        attitude: np.ndarray,
        angular_velocity: np.ndarray,
    ) -> SensedTruth:
        """The truth the sensor models read at ``time`` (s): the robot base's state (world
        frame, SI) and, when an object sensor has a model, every object's state."""
        attitudes = _NO_ATTITUDES
        if self.ideal_objects:
            positions = velocities = _NO_OBJECTS
            free = _NONE_FREE
        else:
            positions, velocities = self._field.free_states(time)
            free = self._field.free_mask()
            if self._capture is not None:
                positions, velocities, free, attitudes = _with_tumbling(
                    self._capture, positions, velocities, free
                )
        return SensedTruth.trusted(
            time=time,
            position=position,
            velocity=velocity,
            attitude=attitude,
            angular_velocity=angular_velocity,
            object_positions=positions,
            object_velocities=velocities,
            free=free,
            object_attitudes=attitudes,
        )

    def beacon_ranges(self, truth: SensedTruth) -> tuple[BeaconRange, ...]:
        """The beacon range sensor's reading (none without a model)."""
        if "beacon_ranges" not in self.models:
            return ()
        ranges: tuple[BeaconRange, ...] = call_plugin(
            self._roles, "sensors.beacon_ranges", "measure", truth
        )
        return ranges

    def object_tracks(self, time: float, position: np.ndarray) -> list[ObjectTrack]:
        """Exact tracks at ``time`` (s) of the free objects within sensor range of
        ``position`` (m): ideal object sensing.

        Each track carries its object's shape and motion and, as ``radius``, its
        bounding radius.
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
                covariance=None,
                attitude=None,
                angular_velocity=None,
                inertia=None,
                shape_margin=0.0,
            )
            for i in visible
            for obj in (self._field.objects[i],)
        ]

    def observations(
        self,
        time: float,
        position: np.ndarray,
        velocity: np.ndarray,
        attitude: np.ndarray,
        angular_velocity: np.ndarray,
    ) -> Observations:
        """Every sensor's reading at ``time`` (s) from the robot's true state.

        Parameters
        ----------
        time : float
            s.
        position, velocity : ndarray (3,)
            Base position (m) and velocity (m/s), world frame.
        attitude : ndarray (4,)
            Base attitude ``[x, y, z, w]``.
        angular_velocity : ndarray (3,)
            Base angular velocity, world frame, rad/s.

        Every array is read-only and owns its data, as the world's state readings do
        (:meth:`dcsim.world.World.base_state`): the observations keep them as they are.
        """
        truth = self.truth(time, position, velocity, attitude, angular_velocity)
        ranges = self.beacon_ranges(truth)
        if self.ideal_objects:
            tracks: tuple[ObjectTrack, ...] = tuple(self.object_tracks(time, position))
            if self._capture is not None:  # the tumbling body's exact track, rotation too
                tracks = (*tracks, self._capture.target_track(time))
            detections: tuple[Detection, ...] = ()
        else:
            tracks = ()
            detections = call_plugin(self._roles, "sensors.objects", "measure", truth)
        if self.ideal_attitude:
            star = rate = None
            seen_attitude, seen_rate = attitude, angular_velocity
        else:
            star, rate = self._attitude_readings(truth)
            seen_attitude, seen_rate = self._attitude, rotate(self._attitude, self._body_rate)
            seen_rate.setflags(write=False)
        return Observations.trusted(  # the world's and the readings' read-only arrays
            time=time,
            ranges=ranges,
            tracks=tracks,
            attitude=seen_attitude,
            angular_velocity=seen_rate,
            joint_positions=_NO_JOINTS,
            joint_velocities=_NO_JOINTS,
            detections=detections,
            star_tracker=star,
            gyros=rate,
        )

    def _attitude_readings(
        self, truth: SensedTruth
    ) -> tuple[AttitudeReading | None, RateReading | None]:
        """The star tracker's and the gyros' readings now (the truth for a sensor without
        a model), kept as the latest ones when given."""
        if "star_tracker" in self.models:
            star = call_plugin(self._roles, "sensors.star_tracker", "measure", truth)
        else:
            star = AttitudeReading(truth.time, truth.attitude)
        if star is not None:
            self._attitude = star.attitude
        if "gyros" in self.models:
            rate = call_plugin(self._roles, "sensors.gyros", "measure", truth)
        else:
            rate = RateReading(
                truth.time, rotate(quaternion_conjugate(truth.attitude), truth.angular_velocity)
            )
        if rate is not None:
            self._body_rate = rate.angular_velocity
        return star, rate


def _known_objects(field: ObjectField, capture: CaptureRig | None) -> tuple[KnownObject, ...]:
    """The objects the sensor models are told of: the field's, then the capture's
    tumbling body."""
    known = tuple(KnownObject(o.id, o.kind, o.mass, o.shape) for o in field.objects)
    if capture is None:
        return known
    tumbling = capture.target
    spec = tumbling.spec
    body = KnownObject(spec.id, ObjectKind.TARGET, spec.mass, spec.shape.build(), tumbling.inertia)
    return (*known, body)


def _with_tumbling(
    capture: CaptureRig, positions: np.ndarray, velocities: np.ndarray, free: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The field's object states with the tumbling body's appended: positions and
    velocities (N + 1, 3), free flags (N + 1,: the body is free until latched), attitudes
    (N + 1, 4) with NaN rows for the field's objects, whose rotation the world does not
    model; all read-only."""
    state = capture.target.state()
    attitudes = np.full((len(positions) + 1, 4), np.nan)
    attitudes[-1] = state.attitude
    arrays = (
        np.vstack([positions, state.position]),
        np.vstack([velocities, state.velocity]),
        np.append(free, not capture.latched),
        attitudes,
    )
    for array in arrays:
        array.setflags(write=False)
    return arrays


_NO_OBJECTS = np.zeros((0, 3))
_NO_OBJECTS.setflags(write=False)
_NONE_FREE = np.zeros(0, dtype=bool)
_NONE_FREE.setflags(write=False)
_NO_ATTITUDES = np.zeros((0, 4))
_NO_ATTITUDES.setflags(write=False)
_NO_JOINTS = np.zeros(0)
_NO_JOINTS.setflags(write=False)
