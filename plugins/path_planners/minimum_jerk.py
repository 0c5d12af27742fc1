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
