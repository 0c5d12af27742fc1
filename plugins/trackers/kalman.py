"""``kalman`` tracker: one linear Kalman filter per object, associated by identity.

Each track's state is the object's ``[position, velocity]`` in the world frame (m, m/s).
Detections carry the object's identity, so a detection updates the track of its ``id``
and an ``id`` without a track starts one.

Measurement
    The absolute position ``z = robot.position + detection.relative_position``, filtered
    with the detection's own covariance. The robot's error enters every detection of a
    tick alike and wanders slowly with the localiser, so filtering cannot average it
    away: it is left out of the filter, and each track carries apart the robot's
    covariance (position and velocity) at its latest accepted detection, moved by the
    frame's motion since, which is added to the filter's covariance when the track is
    answered (a "consider" covariance). Taken instead as white noise on each detection,
    it would be averaged away and leave the tracks overconfident.
Prediction
    The frame's free motion: the Clohessy–Wiltshire state transition with the frame's
    mean motion in an LVLH frame (under a ``two-body`` or ``j2`` world this is the
    linearisation of the world's dynamics about the chief), straight lines in an inertial
    frame; plus white acceleration noise of spectral density ``acceleration_noise²``
    (the parameter in m/s²/√Hz, i.e. m/s^1.5) on each axis, for what the model leaves
    out (the linearisation, bumps). The transition and its process noise are computed
    together, exactly for the linear model, by Van Loan's matrix exponential.
Track start
    At the first detection of an object: the measured position, zero velocity with
    ``initial_velocity_sigma`` (m/s) on each axis.
Gate
    A detection whose innovation's squared Mahalanobis distance exceeds the chi-square
    quantile of ``gate_probability`` (3 degrees of freedom) is rejected; ``rejected``
    counts them since :meth:`KalmanTracker.reset`.
Track loss
    A track without an accepted detection for more than ``lose_after`` (s) is dropped; a
    later detection of the object starts it again.
Rotation
    An object whose detections carry a measured attitude (a tumbling body seen by a
    sensor that estimates poses) has its attitude and angular velocity estimated too,
    by a :class:`~dcsim_plugins.trackers.rotation.RotationFilter` that predicts with the
    detection's catalogue inertia; its track carries them and that inertia.

Detections are taken as made at the ``time`` of the update that brings them. Every
track is predicted to that time whether or not it is detected, and all tracks are
filtered together as stacked arrays ((N, 6) states, (N, 6, 6) covariances).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from dcsim_plugins.trackers.rotation import RotationFilter, symmetric
from scipy.linalg import expm
from scipy.stats import chi2

from dcsim.api import (
    ClohessyWiltshireMotion,
    Detection,
    FrameDynamics,
    FrameKind,
    LinearMotion,
    MotionModel,
    ObjectKind,
    ObjectTrack,
    PluginParams,
    Shape,
    StateEstimate,
    Tracker,
    hookimpl,
    quantity,
)


class KalmanParams(PluginParams):
    """Parameters of :class:`KalmanTracker`."""

    acceleration_noise: float = quantity(
        1e-3,
        unit="m/s^1.5",
        gt=0,
        description="Square root of the white acceleration noise's spectral density per "
        "axis (m/s²/√Hz): what the frame's free motion leaves out.",
    )
    initial_velocity_sigma: float = quantity(
        0.5, unit="m/s", gt=0, description="Velocity standard deviation of a new track, per axis."
    )
    gate_probability: float = quantity(
        0.999,
        gt=0,
        lt=1,
        description="Probability that a detection of the tracked object passes the "
        "innovation gate (chi-square, 3 degrees of freedom).",
    )
    lose_after: float = quantity(
        10.0,
        unit="s",
        gt=0,
        description="Time without an accepted detection after which a track is dropped.",
    )
    angular_acceleration_noise: float = quantity(
        3e-5,
        unit="rad/s^1.5",
        gt=0,
        description="Square root of the white angular acceleration noise's spectral "
        "density per axis (rad/s²/√Hz) of a tracked rotation: what the torque-free model "
        "leaves out.",
    )
    initial_rate_sigma: float = quantity(
        10.0,
        unit="deg/s",
        gt=0,
        description="Angular velocity standard deviation of a new tracked rotation, per axis.",
    )
    shape_margin: float = quantity(
        0.1,
        unit="m",
        ge=0,
        description="Added to a detection's radius for the bounding sphere of an object "
        "whose shape the sensor does not see.",
    )


@dataclass(frozen=True)
class _Details:
    """What a track keeps from its latest accepted detection besides the state (its
    shape's bounding radius, m, worked out once, and the margin it holds, m)."""

    kind: ObjectKind
    mass: float
    shape: Shape
    radius: float
    margin: float


_H = np.hstack([np.eye(3), np.zeros((3, 3))])
"""The measurement matrix: the position part of the state."""


class KalmanTracker(Tracker):
    """Linear Kalman filter per object under the frame's free motion, gated, by identity.

    Attributes
    ----------
    rejected : int
        Detections the innovation gate rejected since the last :meth:`reset`.
    """

    name = "kalman"
    summary = "Linear Kalman filter per object under the frame's free motion, gated, by identity"
    robots = ("free-flyer", "manipulator")
    Params = KalmanParams
    params: KalmanParams

    def __init__(
        self,
        params: PluginParams | Mapping[str, Any] | None = None,
        rng: np.random.Generator | None = None,
    ) -> None:
        super().__init__(params, rng)
        self._gate = float(chi2.ppf(self.params.gate_probability, 3))
        self.reset(FrameDynamics(), 0.0)

    def reset(self, frame: FrameDynamics, time: float) -> None:
        """Drop every track; predict from now on by ``frame``'s free motion (``time``, s)."""
        clohessy_wiltshire = frame.kind is FrameKind.CLOHESSY_WILTSHIRE
        self._mean_motion = float(frame.mean_motion) if clohessy_wiltshire else 0.0
        self.time = float(time)
        self.rejected = 0
        self._ids = np.zeros(0, dtype=np.int64)
        self._states = _frozen(np.zeros((0, 6)))
        self._covariances = _frozen(np.zeros((0, 6, 6)))
        self._robot_parts = np.zeros((0, 6, 6))
        self._robot_now = np.zeros((6, 6))
        self._last_seen = np.zeros(0)
        self._details: list[_Details] = []
        self._spheres: dict[tuple[ObjectKind, float, float], _Details] = {}
        self._step: tuple[float, np.ndarray, np.ndarray] | None = None
        self._rotations: dict[int, RotationFilter] = {}

    def update(
        self, time: float, detections: Sequence[Detection], robot: StateEstimate
    ) -> tuple[ObjectTrack, ...]:
        """Predict every track to ``time`` (s), fold in ``detections`` made then from the
        robot at ``robot``, drop lost tracks; return the live tracks, ordered by id."""
        self._predict(float(time))
        if detections:
            self._fold(detections, robot)
        self._drop_lost()
        return self._tracks()

    # ------------------------------------------------------------------ filter
    def _predict(self, time: float) -> None:
        """Every track moved from :attr:`time` to ``time`` by the frame's free motion."""
        dt = time - self.time
        self.time = time
        if dt <= 0 or not len(self._ids):
            return
        for rotation in self._rotations.values():
            rotation.predict(dt)
        phi, noise = self._transition(dt)
        self._states = _frozen(self._states @ phi.T)
        self._covariances = _frozen(symmetric(phi @ self._covariances @ phi.T + noise))
        self._robot_parts = phi @ self._robot_parts @ phi.T

    def _transition(self, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """The state transition (6, 6) and process noise covariance (6, 6) over ``dt``
        (s), by Van Loan's method; the last period's are kept and serve any ``dt`` within
        1e-9 of it (control ticks' differences vary in the last bits)."""
        if self._step is not None and math.isclose(self._step[0], dt, rel_tol=1e-9):
            return self._step[1], self._step[2]
        n = self._mean_motion
        a = np.zeros((6, 6))
        a[:3, 3:] = np.eye(3)
        a[3, 0], a[5, 2] = 3.0 * n**2, -(n**2)
        a[3, 4], a[4, 3] = 2.0 * n, -2.0 * n
        blocks = np.zeros((12, 12))  # [[-A, G q Gᵀ], [0, Aᵀ]], G the velocity rows
        blocks[:6, :6] = -a
        blocks[3:6, 9:12] = self.params.acceleration_noise**2 * np.eye(3)
        blocks[6:, 6:] = a.T
        exponential = expm(blocks * dt)
        phi = exponential[6:, 6:].T
        noise = symmetric(phi @ exponential[:6, 6:])
        self._step = (dt, phi, noise)
        return phi, noise

    def _fold(self, detections: Sequence[Detection], robot: StateEstimate) -> None:
        """Update the detected tracks (gated), start tracks for new objects."""
        self._robot_now = _base_covariance(robot)
        ids, first = np.unique([d.id for d in detections], return_index=True)
        chosen = [detections[i] for i in first]  # one detection per object
        measured = robot.position + np.array([d.relative_position for d in chosen])
        noise = np.array([d.covariance for d in chosen])
        slots = np.searchsorted(self._ids, ids)
        known = slots < len(self._ids)
        known[known] = self._ids[slots[known]] == ids[known]
        self._correct(
            slots[known], measured[known], noise[known], [chosen[i] for i in np.flatnonzero(known)]
        )
        fresh = ~known
        self._start(
            ids[fresh], measured[fresh], noise[fresh], [chosen[i] for i in np.flatnonzero(fresh)]
        )
        self._turn(chosen)

    def _turn(self, detections: list[Detection]) -> None:
        """Fold the measured attitudes of ``detections`` into their objects' rotation
        filters, starting those not yet tracked."""
        for detection in detections:
            if detection.attitude is None or detection.attitude_covariance is None:
                continue
            rotation = self._rotations.get(detection.id)
            if rotation is None:
                self._rotations[detection.id] = RotationFilter(
                    detection.attitude,
                    detection.attitude_covariance,
                    detection.inertia,
                    math.radians(self.params.initial_rate_sigma),
                    self.params.angular_acceleration_noise,
                )
            else:
                rotation.correct(detection.attitude, detection.attitude_covariance)

    def _correct(
        self,
        slots: np.ndarray,
        measured: np.ndarray,
        noise: np.ndarray,
        detections: list[Detection],
    ) -> None:
        """Kalman update of the tracks at ``slots`` with positions ``measured`` (M, 3) of
        covariances ``noise`` (M, 3, 3), for those whose innovation passes the gate."""
        if not len(slots):
            return
        states, covariances = self._states[slots], self._covariances[slots]
        innovation = measured - states[:, :3]
        inverse = np.linalg.inv(covariances[:, :3, :3] + noise)
        distance = np.einsum("ni,nij,nj->n", innovation, inverse, innovation)
        accepted = distance <= self._gate
        self.rejected += int(np.count_nonzero(~accepted))
        if not accepted.any():
            return
        slots, innovation, noise = slots[accepted], innovation[accepted], noise[accepted]
        states, covariances = states[accepted], covariances[accepted]
        gain = covariances[:, :, :3] @ inverse[accepted]
        reduction = np.eye(6) - gain @ _H
        new_states = self._states.copy()
        new_states[slots] = states + np.einsum("nij,nj->ni", gain, innovation)
        new_covariances = self._covariances.copy()
        new_covariances[slots] = symmetric(  # Joseph form: stays positive definite
            reduction @ covariances @ reduction.transpose(0, 2, 1)
            + gain @ noise @ gain.transpose(0, 2, 1)
        )
        self._states, self._covariances = _frozen(new_states), _frozen(new_covariances)
        self._robot_parts[slots] = self._robot_now
        self._last_seen[slots] = self.time
        for slot, index in zip(slots.tolist(), np.flatnonzero(accepted).tolist(), strict=True):
            self._details[slot] = self._described(detections[index])

    def _start(
        self, ids: np.ndarray, measured: np.ndarray, noise: np.ndarray, detections: list[Detection]
    ) -> None:
        """New tracks for ``ids`` at positions ``measured`` (M, 3) of covariances
        ``noise`` (M, 3, 3), at rest with the initial velocity spread."""
        if not len(ids):
            return
        states = np.hstack([measured, np.zeros_like(measured)])
        covariances = np.zeros((len(ids), 6, 6))
        covariances[:, :3, :3] = noise
        covariances[:, 3:, 3:] = self.params.initial_velocity_sigma**2 * np.eye(3)
        all_ids = np.concatenate([self._ids, ids])
        order = np.argsort(all_ids, kind="stable")
        self._ids = all_ids[order]
        self._states = _frozen(np.concatenate([self._states, states])[order])
        self._covariances = _frozen(np.concatenate([self._covariances, covariances])[order])
        robot_parts = np.broadcast_to(self._robot_now, covariances.shape)
        self._robot_parts = np.concatenate([self._robot_parts, robot_parts])[order]
        self._last_seen = np.concatenate([self._last_seen, np.full(len(ids), self.time)])[order]
        details = self._details + [self._described(d) for d in detections]
        self._details = [details[i] for i in order.tolist()]

    def _drop_lost(self) -> None:
        """Drop the tracks without an accepted detection for more than ``lose_after``."""
        live = self.time - self._last_seen <= self.params.lose_after
        if live.all():
            return
        self._ids, self._last_seen = self._ids[live], self._last_seen[live]
        self._states = _frozen(self._states[live])
        self._covariances = _frozen(self._covariances[live])
        self._robot_parts = self._robot_parts[live]
        self._details = [d for d, keep in zip(self._details, live.tolist(), strict=True) if keep]
        kept = set(self._ids.tolist())
        self._rotations = {i: r for i, r in self._rotations.items() if i in kept}

    # ------------------------------------------------------------------ answers
    def _described(self, detection: Detection) -> _Details:
        """Kind, mass and shape of a detected object: the detection's shape, or a sphere
        of its radius plus the margin (shared while a detection repeats them)."""
        if detection.shape is not None:
            shape = detection.shape
            return _Details(detection.kind, detection.mass, shape, shape.bounding_radius, 0.0)
        key = (detection.kind, detection.mass, detection.radius)
        details = self._spheres.get(key)
        if details is None:
            margin = self.params.shape_margin
            sphere = Shape(radius=detection.radius + margin)
            details = self._spheres[key] = _Details(
                detection.kind, detection.mass, sphere, sphere.radius, margin
            )
        return details

    def _motion(self, state: list[float]) -> MotionModel:
        """The frame's free motion from ``state`` ``[position, velocity]`` at the current
        time."""
        position, velocity = tuple(state[:3]), tuple(state[3:])
        if self._mean_motion > 0:
            return ClohessyWiltshireMotion(position, velocity, self._mean_motion, epoch=self.time)
        return LinearMotion(position, velocity, epoch=self.time)

    def _tracks(self) -> tuple[ObjectTrack, ...]:
        """Every live track as a message, its covariance the filter's plus the robot's
        part (its state arrays read-only views of the filter's)."""
        states = self._states
        covariances = _frozen(self._covariances + self._robot_parts)
        return tuple(
            ObjectTrack.trusted(
                id=track_id,
                kind=details.kind,
                time=self.time,
                position=states[i, :3],
                velocity=states[i, 3:],
                mass=details.mass,
                radius=details.radius,
                motion=self._motion(state),
                shape=details.shape,
                covariance=covariances[i],
                attitude=None if rotation is None else _frozen(rotation.attitude.copy()),
                angular_velocity=(
                    None if rotation is None else _frozen(rotation.angular_velocity.copy())
                ),
                inertia=None if rotation is None else rotation.inertia,
                shape_margin=details.margin,
            )
            for i, (track_id, details, state) in enumerate(
                zip(self._ids.tolist(), self._details, states.tolist(), strict=True)
            )
            for rotation in (self._rotations.get(track_id),)
        )


def _base_covariance(robot: StateEstimate) -> np.ndarray:
    """The covariance (6, 6) of the robot base's position and velocity in ``robot``'s
    (its leading block; zeros where the estimate gives fewer states)."""
    covariance = np.zeros((6, 6))
    size = min(6, len(robot.covariance))
    covariance[:size, :size] = robot.covariance[:size, :size]
    return covariance


def _frozen(array: np.ndarray) -> np.ndarray:
    """``array``, made read-only (it is handed out in tracks and never written again)."""
    array.setflags(write=False)
    return array


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the Kalman tracker."""
    return [KalmanTracker]
