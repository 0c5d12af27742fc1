"""Rest-to-rest motion with a speed and an acceleration limit (trapezoidal profiles).

Used by planners to tell how soon a collector with finite thrust can cover a distance,
and by the framework's documentation of plan feasibility. Infinite acceleration gives
the impulsive limit (constant speed from the first instant).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray


def rest_to_rest_time(
    distance: ArrayLike, max_speed: ArrayLike, max_acceleration: float
) -> NDArray:
    """Shortest time to cover ``distance`` from rest to rest.

    Parameters
    ----------
    distance : array_like
        Distance, m (non-negative).
    max_speed : array_like
        Speed limit, m/s (positive; broadcast against ``distance``).
    max_acceleration : float
        Acceleration limit, m/s² (``inf`` for impulsive burns).

    Returns
    -------
    ndarray
        Time, s: ``L/v + v/a`` when the speed limit is reached, ``2 sqrt(L/a)`` otherwise.
    """
    distance = np.asarray(distance, dtype=float)
    max_speed = np.asarray(max_speed, dtype=float)
    if np.isinf(max_acceleration):
        return distance / max_speed
    reaches_limit = distance >= max_speed**2 / max_acceleration
    return np.where(
        reaches_limit,
        distance / max_speed + max_speed / max_acceleration,
        2.0 * np.sqrt(distance / max_acceleration),
    )


def shortest_leg(
    distance: ArrayLike, max_speed: float, max_acceleration: float, min_duration: float
) -> NDArray:
    """Shortest duration of a plan leg: the rest-to-rest time, but at least ``min_duration``.

    Parameters
    ----------
    distance : array_like
        Leg length, m.
    max_speed, max_acceleration : float
        The leg's speed (m/s) and acceleration (m/s², ``inf`` for impulsive) limits.
    min_duration : float
        Least duration of any leg, s.

    Returns
    -------
    ndarray
        s.
    """
    return np.maximum(min_duration, rest_to_rest_time(distance, max_speed, max_acceleration))


def cruise_speed(distance: float, duration: float, max_acceleration: float) -> float:
    """Cruise speed of the trapezoid that covers ``distance`` in exactly ``duration``.

    Parameters
    ----------
    distance : float
        m.
    duration : float
        s (positive).
    max_acceleration : float
        Acceleration used in the ramps, m/s² (``inf`` for impulsive burns).

    Returns
    -------
    float
        The cruise speed, m/s, or ``nan`` if even a full-acceleration triangle is too
        slow (``distance > a T² / 4``).
    """
    if np.isinf(max_acceleration):
        return distance / duration
    a, T = max_acceleration, duration
    discriminant = (a * T) ** 2 - 4.0 * a * distance
    if discriminant < 0:
        return float("nan")
    return float(0.5 * (a * T - np.sqrt(discriminant)))
