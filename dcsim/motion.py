"""Motion models of space objects, each exact for its own equations.

A motion model gives an object's position and velocity at any scenario time ``t``
(seconds since the scenario's start). Models are immutable values: the world moves
objects with them, and object tracks carry them so that planners can predict where a
target or obstacle will be.

Every ``state_at`` accepts a scalar time or an array of times and returns arrays of
shape ``(..., 3)``.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, overload

import numpy as np
from numpy.typing import ArrayLike

from dcsim.geometry import Vector

STANDARD_GRAVITATIONAL_PARAMETER_EARTH = 3.986004418e14
"""Earth's gravitational parameter μ, m³/s²."""


def mean_motion(orbit_radius: float, mu: float = STANDARD_GRAVITATIONAL_PARAMETER_EARTH) -> float:
    """Mean motion n = sqrt(μ / a³) of a circular orbit, rad/s.

    Parameters
    ----------
    orbit_radius : float
        Radius of the circular reference orbit, m.
    mu : float
        Gravitational parameter of the central body, m³/s².
    """
    return float(np.sqrt(mu / orbit_radius**3))


class MotionModel(ABC):
    """An object's motion: position and velocity as functions of scenario time."""

    @abstractmethod
    def state_at(self, t: ArrayLike) -> tuple[Vector, Vector]:
        """Return ``(position, velocity)`` at time(s) ``t``.

        Parameters
        ----------
        t : float or array_like
            Scenario time, s.

        Returns
        -------
        position, velocity : ndarray, shape (..., 3)
            In m and m/s, world frame.
        """

    def position_at(self, t: ArrayLike) -> Vector:
        """Return the position (m) at time(s) ``t`` (s)."""
        return self.state_at(t)[0]

    @classmethod
    def stack(cls, models: Sequence[MotionModel]) -> Any:
        """Gather the parameters of many models of this class for :meth:`stacked_state`.

        Subclasses stack their parameters into arrays once, so that evaluating the
        whole group at any time is one vectorised call; the default keeps the models.
        """
        return list(models)

    @classmethod
    def stacked_state(cls, stacked: Any, t: float) -> tuple[Vector, Vector]:
        """Positions and velocities at time ``t`` (s) of models gathered by :meth:`stack`:
        new float arrays of shape (N, 3), in the order of the models."""
        states = [m.state_at(t) for m in stacked]
        return np.array([p for p, _ in states]), np.array([v for _, v in states])


class MotionSet:
    """Many motion models of any classes, evaluated together.

    Models are grouped by class and each group's parameters are stacked once; each
    :meth:`state_at` is then one vectorised call per class.

    Parameters
    ----------
    models : sequence of MotionModel
        The models, in the order results are returned.
    """

    def __init__(self, models: Sequence[MotionModel]) -> None:
        self.size = len(models)
        indices: dict[type[MotionModel], list[int]] = {}
        for index, model in enumerate(models):
            indices.setdefault(type(model), []).append(index)
        self._groups = [
            (cls, np.array(group), cls.stack([models[i] for i in group]))
            for cls, group in indices.items()
        ]

    def state_at(self, t: float) -> tuple[Vector, Vector]:
        """Positions and velocities (N, 3) of all models at time ``t`` (s)."""
        if len(self._groups) == 1:  # one class: its group is every model, in order
            cls, _, stacked = self._groups[0]
            return cls.stacked_state(stacked, t)
        positions = np.zeros((self.size, 3))
        velocities = np.zeros((self.size, 3))
        for cls, group, stacked in self._groups:
            positions[group], velocities[group] = cls.stacked_state(stacked, t)
        return positions, velocities


def batch_states(models: Sequence[MotionModel], t: float) -> tuple[Vector, Vector]:
    """Positions and velocities (N, 3) of any mix of motion models at time ``t`` (s)."""
    return MotionSet(models).state_at(t)


_Scalars = float | Vector
"""One value (a float) or many (an array) of a quantity that broadcasts element-wise."""


def _stack(models: Sequence[Any], name: str) -> np.ndarray:
    return np.array([getattr(m, name) for m in models], dtype=float)


def _vec3(values: ArrayLike) -> tuple[float, float, float]:
    """Three floats from ``values`` (a tuple of three floats is kept as it is)."""
    if type(values) is tuple and len(values) == 3:
        x, y, z = values
        if type(x) is float and type(y) is float and type(z) is float:
            return values
    x, y, z = np.asarray(values, dtype=float).reshape(3).tolist()
    return (x, y, z)


@dataclass(frozen=True)
class StaticMotion(MotionModel):
    """An object at rest at ``position`` (m)."""

    position: tuple[float, float, float]

    def __init__(self, position: ArrayLike) -> None:
        object.__setattr__(self, "position", _vec3(position))

    def state_at(self, t: ArrayLike) -> tuple[Vector, Vector]:
        """Return the fixed position and zero velocity at time(s) ``t``."""
        shape = np.shape(t) + (3,)
        return np.broadcast_to(np.array(self.position), shape).copy(), np.zeros(shape)

    @classmethod
    def stack(cls, models: Sequence[MotionModel]) -> Any:
        """The fixed positions, (N, 3)."""
        return _stack(models, "position")

    @classmethod
    def stacked_state(cls, stacked: Any, t: float) -> tuple[Vector, Vector]:
        """Fixed positions and zero velocities."""
        return stacked.copy(), np.zeros_like(stacked)


@dataclass(frozen=True)
class LinearMotion(MotionModel):
    """Force-free straight-line motion: ``p(t) = position + velocity (t - epoch)``.

    Parameters
    ----------
    position : (3,) float
        Position at ``epoch``, m.
    velocity : (3,) float
        Constant velocity, m/s.
    epoch : float
        Time at which ``position`` holds, s.
    """

    position: tuple[float, float, float]
    velocity: tuple[float, float, float]
    epoch: float = 0.0

    def __init__(self, position: ArrayLike, velocity: ArrayLike, epoch: float = 0.0) -> None:
        object.__setattr__(self, "position", _vec3(position))
        object.__setattr__(self, "velocity", _vec3(velocity))
        object.__setattr__(self, "epoch", epoch)

    def state_at(self, t: ArrayLike) -> tuple[Vector, Vector]:
        """Return position and velocity at time(s) ``t``."""
        tau = np.asarray(t, dtype=float) - self.epoch
        return _linear_state(np.array(self.position), np.array(self.velocity), tau)

    @classmethod
    def stack(cls, models: Sequence[MotionModel]) -> Any:
        """Positions, velocities and epochs as arrays."""
        return tuple(_stack(models, name) for name in ("position", "velocity", "epoch"))

    @classmethod
    def stacked_state(cls, stacked: Any, t: float) -> tuple[Vector, Vector]:
        """Vectorised :meth:`state_at` of many linear motions at time ``t``."""
        position, velocity, epoch = stacked
        return _linear_state(position, velocity, t - epoch)


def _linear_state(p0: np.ndarray, v0: np.ndarray, tau: np.ndarray) -> tuple[Vector, Vector]:
    """``p0 + v0 τ``; ``p0``, ``v0`` of shape (3,) or (N, 3), τ broadcastable to (...)."""
    tau = np.asarray(tau)[..., None]
    return p0 + v0 * tau, np.broadcast_to(v0, np.broadcast_shapes(np.shape(p0), tau.shape)).copy()


@dataclass(frozen=True)
class SphericalMotion(MotionModel):
    """The source thesis's linear spherical orbit model (its eq. 2.1).

    ``(r, θ, φ)(t) = (r0 + v τ, θ0 + α τ, φ0 + β τ)`` with ``τ = t - epoch``, converted
    to Cartesian coordinates (polar angle θ from +z, azimuth φ from +x).

    Parameters
    ----------
    r : float
        Radial distance at ``epoch``, m.
    polar_deg, azimuth_deg : float
        Angles at ``epoch``, degrees.
    v : float
        Radial speed, m/s.
    alpha_deg_s, beta_deg_s : float
        Polar and azimuthal rates, deg/s.
    epoch : float
        Time at which the initial values hold, s.
    """

    r: float
    polar_deg: float
    azimuth_deg: float
    v: float = 0.0
    alpha_deg_s: float = 0.0
    beta_deg_s: float = 0.0
    epoch: float = 0.0

    def state_at(self, t: ArrayLike) -> tuple[Vector, Vector]:
        """Return position and velocity at time(s) ``t``, from the exact derivative."""
        tau = np.asarray(t, dtype=float) - self.epoch
        return _spherical_state([getattr(self, n) for n in _SPHERICAL_PARAMETERS], tau)

    @classmethod
    def stack(cls, models: Sequence[MotionModel]) -> Any:
        """The six parameters and the epochs as arrays."""
        return tuple(_stack(models, name) for name in (*_SPHERICAL_PARAMETERS, "epoch"))

    @classmethod
    def stacked_state(cls, stacked: Any, t: float) -> tuple[Vector, Vector]:
        """Vectorised :meth:`state_at` of many spherical motions at time ``t``."""
        *parameters, epoch = stacked
        return _spherical_state(parameters, t - epoch)


_SPHERICAL_PARAMETERS = ("r", "polar_deg", "azimuth_deg", "v", "alpha_deg_s", "beta_deg_s")


def _spherical_state(parameters: Sequence[ArrayLike], tau: Vector) -> tuple[Vector, Vector]:
    """Eq. 2.1 and its time derivative; ``parameters`` are the values named by
    ``_SPHERICAL_PARAMETERS``, in that order, and broadcast against ``tau`` (s)."""
    r0, polar_deg, azimuth_deg, v, alpha_deg_s, beta_deg_s = parameters
    r = r0 + np.multiply(v, tau)
    theta = np.radians(polar_deg + np.multiply(alpha_deg_s, tau))
    phi = np.radians(azimuth_deg + np.multiply(beta_deg_s, tau))
    st, ct, sp, cp = np.sin(theta), np.cos(theta), np.sin(phi), np.cos(phi)
    e_r = np.stack([st * cp, st * sp, ct], axis=-1)
    e_theta = np.stack([ct * cp, ct * sp, -st], axis=-1)
    e_phi = np.stack([-sp, cp, np.zeros_like(sp)], axis=-1)
    speed_r = np.broadcast_to(v, np.shape(r))
    speed_theta = r * np.radians(alpha_deg_s)
    speed_phi = r * st * np.radians(beta_deg_s)
    velocity = (
        speed_r[..., None] * e_r + speed_theta[..., None] * e_theta + speed_phi[..., None] * e_phi
    )
    return r[..., None] * e_r, velocity


@dataclass(frozen=True)
class ClohessyWiltshireMotion(MotionModel):
    """Closed-form Clohessy–Wiltshire relative motion in the LVLH frame.

    Axes: x radial (away from the central body), y along-track, z orbit normal.
    Equations: ẍ = 3n²x + 2nẏ, ÿ = −2nẋ, z̈ = −n²z.

    Parameters
    ----------
    position, velocity : (3,) float
        Relative state at ``epoch``, m and m/s.
    mean_motion : float
        Mean motion n of the circular reference orbit, rad/s.
    epoch : float
        Time at which the initial state holds, s.
    """

    position: tuple[float, float, float]
    velocity: tuple[float, float, float]
    mean_motion: float
    epoch: float = 0.0

    def __init__(
        self, position: ArrayLike, velocity: ArrayLike, mean_motion: float, epoch: float = 0.0
    ) -> None:
        object.__setattr__(self, "position", _vec3(position))
        object.__setattr__(self, "velocity", _vec3(velocity))
        object.__setattr__(self, "mean_motion", mean_motion)
        object.__setattr__(self, "epoch", epoch)
        if not self.mean_motion > 0:
            raise ValueError("mean_motion must be positive")

    def state_at(self, t: ArrayLike) -> tuple[Vector, Vector]:
        """Return the exact relative position and velocity at time(s) ``t``."""
        return _cw_state(self.position, self.velocity, self.mean_motion, _elapsed(t, self.epoch))

    @classmethod
    def stack(cls, models: Sequence[MotionModel]) -> Any:
        """Initial states (transposed), mean motions and epochs as arrays.

        Mean motions and epochs that every model shares (one orbit, one epoch: the usual
        field) are kept as floats instead, so the trigonometry and the coefficients of
        the closed form are computed once per time rather than once per model.
        """
        means, epochs = _stack(models, "mean_motion"), _stack(models, "epoch")
        n: _Scalars = means
        epoch: _Scalars = epochs
        if (means == means[0]).all() and (epochs == epochs[0]).all():
            n, epoch = float(means[0]), float(epochs[0])
        return _stack(models, "position").T, _stack(models, "velocity").T, n, epoch

    @classmethod
    def stacked_state(cls, stacked: Any, t: float) -> tuple[Vector, Vector]:
        """Vectorised :meth:`state_at` of many Clohessy–Wiltshire motions at time ``t``."""
        position, velocity, n, epoch = stacked
        return _cw_state(position, velocity, n, float(t) - epoch)


def _elapsed(t: ArrayLike, epoch: float) -> _Scalars:
    """Time (s) from ``epoch`` (s) to ``t`` (s): a float for a scalar ``t``, else an array."""
    if isinstance(t, (int, float)):
        return float(t) - epoch
    times = np.asarray(t, dtype=float)
    return float(times) - epoch if times.ndim == 0 else times - epoch


def _cw_state(
    position: Sequence[_Scalars] | Vector,
    velocity: Sequence[_Scalars] | Vector,
    n: _Scalars,
    tau: _Scalars,
) -> tuple[Vector, Vector]:
    """The Clohessy–Wiltshire closed form; components of ``position`` (m) and ``velocity``
    (m/s) at the epoch broadcast with τ (s); ``n`` is the mean motion, rad/s.

    Each coordinate is a sum of the initial components times coefficients of ``nτ``,
    added in one order whatever the layout (a difference is the sum of the negated
    term, the same IEEE operation). With floats for ``n`` and ``τ`` (one model, or models
    sharing them, at one time) the coefficients stay in Python floats: the same
    operations as numpy's element by element, without its per-call overhead; many
    models at one time are then summed as rows of two arrays (:func:`_cw_rows`).
    """
    nt = n * tau
    s, c = _sin_cos(nt)
    k = 2 / n * (1 - c)
    # coefficients of x0, u0 and v0 in x, y, vx and vy (y adds y0 after its x0 term)
    plane = (
        (4 - 3 * c, s / n, k),
        (6 * (s - nt), -k, (4 * s - 3 * nt) / n),
        (3 * n * s, c, 2 * s),
        (-6 * n * (1 - c), -(2 * s), 4 * c - 3),
    )
    normal = ((c, s / n), (-n * s, c))  # coefficients of z0 and w0 in z and vz
    if isinstance(nt, float) and isinstance(position, np.ndarray):
        return _cw_rows(plane, normal, position, np.asarray(velocity))
    x0, y0, z0 = position
    u0, v0, w0 = velocity
    (ax, bx, cx), (ay, by, cy), (au, bu, cu), (av, bv, cv) = plane
    (az, bz), (aw, bw) = normal
    x = ax * x0 + bx * u0 + cx * v0
    y = ay * x0 + y0 + by * u0 + cy * v0
    z = az * z0 + bz * w0
    vx = au * x0 + bu * u0 + cu * v0
    vy = av * x0 + bv * u0 + cv * v0
    vz = aw * z0 + bw * w0
    return _columns(x, y, z), _columns(vx, vy, vz)


def _cw_rows(
    plane: tuple[tuple[_Scalars, ...], ...],
    normal: tuple[tuple[_Scalars, ...], ...],
    position: Vector,
    velocity: Vector,
) -> tuple[Vector, Vector]:
    """:func:`_cw_state`'s sums for N models at one time: ``position`` and ``velocity``
    (3, N) at the epoch, m and m/s, and the coefficients as floats; positions and
    velocities (N, 3), each element the same sum in the same order as one model's."""
    x0, y0, z0 = position
    u0, v0, w0 = velocity
    a, b, c = np.array(plane).T[:, :, None]  # (4, 1) each: x, y, vx, vy
    rows = a * x0
    rows[1] += y0
    rows += b * u0
    rows += c * v0
    d, e = np.array(normal).T[:, :, None]  # (2, 1) each: z, vz
    across = d * z0
    across += e * w0
    states = np.empty((2, x0.shape[-1], 3))
    states[:, :, :2] = rows.reshape(2, 2, -1).transpose(0, 2, 1)
    states[:, :, 2] = across
    return states[0], states[1]


@overload
def _sin_cos(angle: float) -> tuple[float, float]: ...
@overload
def _sin_cos(angle: Vector) -> tuple[Vector, Vector]: ...
def _sin_cos(angle: _Scalars) -> tuple[float, float] | tuple[Vector, Vector]:
    """``sin`` and ``cos`` of ``angle`` (rad): floats for a float, arrays otherwise."""
    if isinstance(angle, float):
        return float(np.sin(angle)), float(np.cos(angle))
    return np.sin(angle), np.cos(angle)


def _columns(x: _Scalars, y: _Scalars, z: _Scalars) -> Vector:
    """``x``, ``y`` and ``z`` (broadcast together) as the last axis of one array."""
    if isinstance(x, float) and isinstance(y, float) and isinstance(z, float):
        return np.array((x, y, z))
    shape = np.shape(x)
    if np.shape(y) != shape or np.shape(z) != shape:  # broadcast only when needed
        shape = np.broadcast_shapes(shape, np.shape(y), np.shape(z))
    out = np.empty(shape + (3,))
    out[..., 0], out[..., 1], out[..., 2] = x, y, z
    return out
