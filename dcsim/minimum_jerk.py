"""Rest-to-rest straight moves with the minimum-jerk (quintic) time law.

Along a segment of length ``L`` travelled in ``T``,

    s(τ) = L (10 τ³ − 15 τ⁴ + 6 τ⁵),      τ = t / T,

velocity and acceleration are zero at both ends and continuous in between; the peak
speed is ``15 L / (8 T)`` and the peak acceleration ``10 L / (√3 T²)``. Used by the path
planners that give a manipulator's end effector its path, and by the capture mission for
its base's approach.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike

PEAK_SPEED = 15.0 / 8.0
"""Peak speed of the quintic law, in units of L / T."""
PEAK_ACCELERATION = 10.0 / np.sqrt(3.0)
"""Peak acceleration of the quintic law, in units of L / T²."""


def shortest_duration(
    length: float, max_speed: float, max_acceleration: float, min_duration: float = 0.0
) -> float:
    """Least ``T`` (s) that keeps a move of ``length`` (m) within ``max_speed`` (m/s) and
    ``max_acceleration`` (m/s²), never below ``min_duration``."""
    return max(
        min_duration,
        PEAK_SPEED * length / max_speed,
        float(np.sqrt(PEAK_ACCELERATION * length / max_acceleration)),
    )


def minimum_jerk_profile(tau: ArrayLike, duration: float) -> tuple[Any, Any, Any]:
    """The quintic law's fraction of the way ``s``, its rate (1/s) and its second
    derivative (1/s²) at ``tau``, the fraction of ``duration`` (s) gone, clipped to
    [0, 1] (at rest before and after); floats for a float, arrays for an array."""
    tau = np.clip(tau, 0.0, 1.0)
    shape = tau**3 * (10.0 - 15.0 * tau + 6.0 * tau**2)
    rate = 30.0 * tau**2 * (1.0 - tau) ** 2 / duration
    curve = 60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau) / duration**2
    return shape, rate, curve


def minimum_jerk_move(
    origin: np.ndarray, target: np.ndarray, duration: float, samples: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Times since the move's start (s), positions (m) and velocities (m/s) of
    ``samples`` evenly timed points of the move from ``origin`` to ``target`` (3,) in
    ``duration`` (s)."""
    offset = np.asarray(target, dtype=float) - np.asarray(origin, dtype=float)
    tau = np.linspace(0.0, 1.0, samples)
    shape = tau**3 * (10.0 - 15.0 * tau + 6.0 * tau**2)
    rate = 30.0 * tau**2 * (1.0 - tau) ** 2 / duration
    return duration * tau, origin + np.outer(shape, offset), np.outer(rate, offset)


def minimum_jerk_legs(
    points: np.ndarray, max_speed: float, max_acceleration: float, samples: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rest to rest from point to point of ``points`` (k, 3), m: one minimum-jerk move per
    leg, each as short as the limits allow, about ``samples`` points in all (at least two
    per leg). Repeated points are dropped; a single point gives a rest of 0.1 s.

    Returns
    -------
    times, positions, velocities : ndarray
        s since the start, m and m/s; each corner appears once, at rest.
    """
    steps = np.linalg.norm(np.diff(points, axis=0), axis=1)
    points = points[np.concatenate([[True], steps > 0.0])]  # no leg of zero length
    if len(points) == 1:  # already there: rest for a moment
        return np.array([0.0, 0.1]), np.vstack([points, points]), np.zeros((2, 3))
    lengths = np.linalg.norm(np.diff(points, axis=0), axis=1)
    shares = np.maximum(2, np.ceil(samples * lengths / lengths.sum()).astype(int))
    times, positions, velocities = [np.zeros(1)], [points[:1]], [np.zeros((1, 3))]
    clock = 0.0
    for origin, end, length, count in zip(points[:-1], points[1:], lengths, shares, strict=True):
        duration = shortest_duration(float(length), max_speed, max_acceleration)
        t, x, v = minimum_jerk_move(origin, end, duration, int(count))
        times.append(clock + t[1:])
        positions.append(x[1:])
        velocities.append(v[1:])
        clock += duration
    return np.concatenate(times), np.vstack(positions), np.vstack(velocities)
