"""Shared pieces of the range-based filters: the constant-velocity model and range geometry.

The state is ``[position, velocity]`` (m, m/s). Over a step ``dt`` the commanded
acceleration ``a`` moves it as ``x' = F x + B a``; thrust uncertainty enters as white
acceleration noise of standard deviation ``σ_a``, giving ``Q = σ_a² B Bᵀ``.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache

import numpy as np

from dcsim.api import BeaconRange


@lru_cache(maxsize=16)
def transition(dt: float) -> tuple[np.ndarray, np.ndarray]:
    """State transition ``F`` (6×6) and acceleration input ``B`` (6×3) over ``dt`` s.

    Filters ask for the same step every control period, so the read-only matrices are
    made once per step length.
    """
    eye = np.eye(3)
    f = np.block([[eye, dt * eye], [np.zeros((3, 3)), eye]])
    b = np.vstack([0.5 * dt**2 * eye, dt * eye])
    return _read_only(f), _read_only(b)


@lru_cache(maxsize=16)
def process_noise(dt: float, acceleration_sigma: float) -> np.ndarray:
    """``Q = σ_a² B Bᵀ`` for white acceleration noise over ``dt`` s (6×6, read-only)."""
    _, b = transition(dt)
    return _read_only(acceleration_sigma**2 * b @ b.T)


def _read_only(matrix: np.ndarray) -> np.ndarray:
    matrix.setflags(write=False)
    return matrix


def beacon_arrays(ranges: Sequence[BeaconRange]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Beacon positions (m×3), measured ranges (m) and their variances (m)."""
    beacons = np.array([r.beacon_position for r in ranges]).reshape(-1, 3)
    measured = np.array([r.range for r in ranges])
    variances = np.array([max(r.sigma, 1e-6) ** 2 for r in ranges])
    return beacons, measured, variances


def predicted_ranges(position: np.ndarray, beacons: np.ndarray) -> np.ndarray:
    """Distances from ``position`` to each beacon."""
    return np.linalg.norm(beacons - position, axis=-1)


def range_jacobian(state: np.ndarray, beacons: np.ndarray) -> np.ndarray:
    """Jacobian (m×6) of the ranges with respect to ``[position, velocity]``."""
    offsets = state[:3] - beacons
    jacobian = np.zeros((len(offsets), 6))
    jacobian[:, :3] = offsets / np.maximum(np.linalg.norm(offsets, axis=1), 1e-9)[:, None]
    return jacobian


def least_squares_fix(
    start: np.ndarray,
    beacons: np.ndarray,
    measured: np.ndarray,
    variances: np.ndarray,
    iterations: int = 20,
) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Newton position fix from ``start`` and its covariance; needs three beacons or more.

    Returns
    -------
    position : ndarray (3,)
        The fix, m.
    covariance : ndarray (3, 3)
        ``(Jᵀ R⁻¹ J)⁻¹`` at the fix, m² (pseudo-inverse if the geometry is degenerate).
    """
    position = np.array(start, dtype=float)
    for _ in range(iterations):
        jacobian = range_jacobian(np.concatenate([position, np.zeros(3)]), beacons)[:, :3]
        residual = measured - predicted_ranges(position, beacons)
        step, *_ = np.linalg.lstsq(jacobian, residual, rcond=None)
        position = position + step
        if np.linalg.norm(step) < 1e-9:
            break
    jacobian = range_jacobian(np.concatenate([position, np.zeros(3)]), beacons)[:, :3]
    return position, np.linalg.pinv(jacobian.T @ (jacobian / variances[:, None]))
