"""``object-sensor``: a lidar or camera that measures range and bearing to the objects.

The sensor sees the free objects (not held, not delivered) whose centre lies within
``robot.sensor_range`` of the robot and inside its field of view, a cone of full angle
``field_of_view`` about the body axis ``boresight`` (360° sees all round). It detects
each with probability ``detection_probability`` and recognises it: a detection carries
the object's catalogue id, kind and mass, its bounding radius and, when the sensor
``sees_shapes``, its true shape.

It measures the object's centre relative to the robot's base, ``p = c − x``, in the
body frame, as a range and two bearing angles in the spherical coordinates of
:mod:`dcsim.geometry` (polar angle θ from body +z, azimuth φ from body +x towards +y):

    r_m = r + σ_r N_r,   θ_m = θ + σ_b N_θ,   φ_m = φ + σ_b N_φ,

with ``σ_r`` the ``range_noise`` and ``σ_b`` the ``bearing_noise``, and independent
standard normal draws. The measured point ``p_b = r_m [sin θ_m cos φ_m,
sin θ_m sin φ_m, cos θ_m]`` is turned into the world's axes by the robot's true
attitude ``R``: the star tracker's error (arcseconds) is far below the bearing noise
(tenths of a degree), so the sensor's pointing is taken as known. Its covariance is the
first-order one at the measured point,

    P = R J diag(σ_r², σ_b², σ_b²) Jᵀ Rᵀ,   J = ∂p_b/∂(r, θ, φ) at (r_m, θ_m, φ_m),

so the cross-range spread is ``σ_b r`` along θ and ``σ_b r sin θ`` along φ (an
azimuth's error moves a point near the body z axis little).

With an ``attitude_noise`` σ_a the sensor also estimates the pose of each detected
object whose rotation the world models (a tumbling body; a camera's model-based pose
estimate): the measured attitude is the true one turned by a small rotation whose
rotation vector about the world axes has independent normal components of standard
deviation σ_a, ``q_m = exp(σ_a N / 2) ⊗ q``, reported with the covariance σ_a² I
(rad²). Such a detection also carries the object's catalogue inertia.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable

import numpy as np
from pydantic import field_validator

from dcsim.api import (
    Detection,
    PluginParams,
    SensedTruth,
    SensorModel,
    SensorSetup,
    hookimpl,
    quantity,
    quaternion_from_rotation_vector,
    quaternion_multiply,
)
from dcsim.geometry import row_lengths
from dcsim.world.sensors.sampling import SampleClock, rate_field

_NONE: tuple[Detection, ...] = ()
_Pose = tuple[np.ndarray | None, np.ndarray | None, np.ndarray | None]
"""A detection's measured attitude, its covariance and the catalogue inertia."""
_NO_POSE: _Pose = (None, None, None)
"""What a detection carries of an object whose attitude the sensor does not measure."""


class ObjectSensorParams(PluginParams):
    """Parameters of :class:`ObjectSensor`."""

    range_noise: float = quantity(0.05, unit="m", ge=0, description="1σ of the range noise.")
    bearing_noise: float = quantity(
        0.2, unit="deg", ge=0, description="1σ of the noise of each bearing angle."
    )
    detection_probability: float = quantity(
        0.95, ge=0, le=1, description="Probability that a visible object is detected."
    )
    rate: float | None = rate_field(10.0)
    field_of_view: float = quantity(
        360.0,
        unit="deg",
        gt=0,
        le=360,
        description="Full angle of the cone about the boresight in which objects are "
        "seen; 360 sees all round.",
    )
    boresight: tuple[float, float, float] = quantity(
        (1.0, 0.0, 0.0), description="Axis of the field of view, body frame (any length)."
    )
    sees_shapes: bool = quantity(
        False, description="Whether a detection carries the object's true shape."
    )
    attitude_noise: float | None = quantity(
        None,
        unit="deg",
        gt=0,
        description="1σ of the error of a measured attitude about each world axis, for "
        "the objects whose rotation the world models (a tumbling body); null: the sensor "
        "measures no attitudes.",
    )

    @field_validator("boresight")
    @classmethod
    def _pointing(cls, value: tuple[float, float, float]) -> tuple[float, float, float]:
        """The boresight must have a direction."""
        if math.hypot(*value) == 0.0:
            raise ValueError("the boresight must not be zero: give a body axis like [1, 0, 0]")
        return value


class ObjectSensor(SensorModel):
    """Range and bearings to the objects in view, with their first-order covariance."""

    name = "object-sensor"
    summary = "Range and bearing detections of the objects in view (lidar, camera)"
    measures = "objects"
    Params = ObjectSensorParams
    params: ObjectSensorParams

    def reset(self, setup: SensorSetup) -> None:
        """Learn the catalogue of objects and the sensor's reach; start the clock."""
        params = self.params
        self._clock = SampleClock(params.rate)
        self._reach = setup.object_range
        self._catalogue = [
            (o.id, o.kind, o.shape.bounding_radius, o.mass, o.shape if params.sees_shapes else None)
            for o in setup.objects
        ]
        self._inertias = [o.inertia for o in setup.objects]
        noise = params.attitude_noise
        self._attitude_sigma = None if noise is None else math.radians(noise)
        self._attitude_covariance = np.eye(3) * (self._attitude_sigma or 0.0) ** 2
        self._attitude_covariance.setflags(write=False)
        self._boresight = np.array(params.boresight, dtype=float) / math.hypot(*params.boresight)
        half = math.radians(params.field_of_view) / 2.0
        self._cos_half = None if params.field_of_view >= 360.0 else math.cos(half)
        self._sigmas = np.array(
            [
                params.range_noise,
                math.radians(params.bearing_noise),
                math.radians(params.bearing_noise),
            ]
        )

    def measure(self, truth: SensedTruth) -> tuple[Detection, ...]:
        """The detections now, in the order of the setup's objects; none between
        readings."""
        if len(truth.object_positions) == 0 or not self._clock.due(truth.time):
            return _NONE
        world_to_body = _body_axes(truth.attitude)
        relative = truth.object_positions - truth.position
        body = relative @ world_to_body.T
        seen = self._detected(body, row_lengths(relative), truth.free)
        if len(seen) == 0:
            return _NONE
        positions, covariances = self._measured(body[seen], world_to_body)
        poses = self._poses(seen, truth.object_attitudes)
        catalogue, time = self._catalogue, truth.time
        return tuple(
            Detection.trusted(
                time=time,
                id=id_,
                kind=kind,
                relative_position=position,
                covariance=covariance,
                radius=radius,
                mass=mass,
                shape=shape,
                attitude=attitude,
                attitude_covariance=attitude_covariance,
                inertia=inertia,
            )
            for (id_, kind, radius, mass, shape), position, covariance, (
                attitude,
                attitude_covariance,
                inertia,
            ) in zip(
                (catalogue[i] for i in seen.tolist()), positions, covariances, poses, strict=True
            )
        )

    def _poses(self, seen: np.ndarray, attitudes: np.ndarray) -> Iterable[_Pose]:
        """For each object at the indices ``seen``: its measured attitude, that
        attitude's covariance and its catalogue inertia, or three Nones when the sensor
        measures no attitudes or the world does not model the object's rotation (a NaN
        row of the true ``attitudes`` (N, 4), or none at all)."""
        sigma = self._attitude_sigma
        if sigma is None or len(attitudes) == 0:
            return itertools.repeat(_NO_POSE, len(seen))
        poses: list[_Pose] = []
        for index in seen.tolist():
            if np.isnan(attitudes[index, 0]):
                poses.append(_NO_POSE)
                continue
            error = quaternion_from_rotation_vector(sigma * self.rng.standard_normal(3))
            measured = quaternion_multiply(error, attitudes[index])
            measured.setflags(write=False)
            poses.append((measured, self._attitude_covariance, self._inertias[index]))
        return poses

    def _detected(self, body: np.ndarray, distances: np.ndarray, free: np.ndarray) -> np.ndarray:
        """Indices of the objects detected now: free, in reach, in view and not missed.

        ``body`` (N, 3) holds their positions relative to the robot in the body frame
        (m), ``distances`` (N,) their lengths (m).
        """
        visible = free & (distances <= self._reach)
        if self._cos_half is not None:
            visible &= body @ self._boresight >= self._cos_half * distances
        seen = np.flatnonzero(visible)
        probability = self.params.detection_probability
        if probability < 1.0:
            seen = seen[self.rng.random(len(seen)) < probability]
        return seen

    def _measured(
        self, body: np.ndarray, world_to_body: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Measured relative positions (K, 3) along the world axes (m) of the objects at
        body-frame positions ``body`` (K, 3), and their covariances (K, 3, 3) (m²);
        both read-only."""
        x, y, z = body.T
        noise = self.rng.standard_normal(body.shape) * self._sigmas
        r = row_lengths(body) + noise[:, 0]
        theta = np.arctan2(np.hypot(x, y), z) + noise[:, 1]
        phi = np.arctan2(y, x) + noise[:, 2]
        sin_t, cos_t, sin_p, cos_p = np.sin(theta), np.cos(theta), np.sin(phi), np.cos(phi)
        # The unit vectors along r, θ and φ at the measured point, body frame.
        axes = np.empty((3, len(r), 3))
        axes[0, :, 0], axes[0, :, 1], axes[0, :, 2] = sin_t * cos_p, sin_t * sin_p, cos_t
        axes[1, :, 0], axes[1, :, 1], axes[1, :, 2] = cos_t * cos_p, cos_t * sin_p, -sin_t
        axes[2, :, 0], axes[2, :, 1], axes[2, :, 2] = -sin_p, cos_p, 0.0
        along, across_theta, across_phi = axes @ world_to_body  # along the world axes
        # The columns of J diag(σ_r, σ_b, σ_b); P is the sum of their outer products.
        spread = self._sigmas[1] * r
        columns = (
            along * self._sigmas[0],
            across_theta * spread[:, None],
            across_phi * (spread * sin_t)[:, None],
        )
        covariances = sum(c[:, :, None] * c[:, None, :] for c in columns)
        positions = r[:, None] * along
        positions.setflags(write=False)
        covariances.setflags(write=False)
        return positions, covariances


def _body_axes(q: np.ndarray) -> np.ndarray:
    """The body axes along the world's, one per row, of a body with attitude ``q``
    ``[x, y, z, w]`` (a unit quaternion): the transpose of its rotation matrix, which
    turns world vectors into the body frame."""
    x, y, z, w = q.tolist()
    return np.array(
        [
            [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + z * w), 2.0 * (x * z - y * w)],
            [2.0 * (x * y - z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z + x * w)],
            [2.0 * (x * z + y * w), 2.0 * (y * z - x * w), 1.0 - 2.0 * (x * x + y * y)],
        ]
    )


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the object sensor model."""
    return [ObjectSensor]
