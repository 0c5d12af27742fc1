"""Rest-to-rest straight moves with the minimum-jerk (quintic) time law.

Along a segment of length ``L`` travelled in ``T``,

    s(τ) = L (10 τ³ − 15 τ⁴ + 6 τ⁵),      τ = t / T,

velocity and acceleration are zero at both ends and continuous in between; the peak
speed is ``15 L / (8 T)`` and the peak acceleration ``10 L / (√3 T²)``. Used by the path
planners that give a manipulator's end effector its path.
"""

from __future__ import annotations

import numpy as np

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


def minimum_jerk_curve(
    points: np.ndarray, max_speed: float, max_acceleration: float, samples: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rest to rest along a smooth curve through ``points`` (k, 3), m.

    The curve is the piecewise-cubic Hermite interpolant through the points over their
    cumulative chord length ``σ`` that keeps every coordinate monotone between points
    (PCHIP: it never overshoots a corner; a straight line for two points), travelled with
    the minimum-jerk law ``σ(t) = L (10 τ³ − 15 τ⁴ + 6 τ⁵)``. The duration starts from
    the straight move's and grows until the speed ``|x'(σ)| σ̇`` and the acceleration
    ``|x''(σ) σ̇² + x'(σ) σ̈|`` on the samples are within the limits.

    Returns
    -------
    times, positions, velocities : ndarray
        ``samples`` points: s since the start, m and m/s.
    """
    from scipy.interpolate import PchipInterpolator

    chords = np.linalg.norm(np.diff(points, axis=0), axis=1)
    sigma = np.concatenate([[0.0], np.cumsum(chords)])
    length = float(sigma[-1])
    curve = PchipInterpolator(sigma, points)
    tau = np.linspace(0.0, 1.0, samples)
    shape = tau**3 * (10.0 - 15.0 * tau + 6.0 * tau**2)
    rate = 30.0 * tau**2 * (1.0 - tau) ** 2
    bend = 60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau)
    along = length * shape
    tangent, curvature = curve(along, 1), curve(along, 2)
    duration = shortest_duration(length, max_speed, max_acceleration)
    for _ in range(60):
        speed = np.linalg.norm(tangent * (length * rate / duration)[:, None], axis=1).max()
        acceleration = np.linalg.norm(
            curvature * ((length * rate / duration) ** 2)[:, None]
            + tangent * (length * bend / duration**2)[:, None],
            axis=1,
        ).max()
        stretch = max(speed / max_speed, np.sqrt(acceleration / max_acceleration))
        if stretch <= 1.0 + 1e-9:
            break
        duration *= stretch * (1.0 + 1e-6)
    velocities = tangent * (length * rate / duration)[:, None]
    return duration * tau, curve(along), velocities
