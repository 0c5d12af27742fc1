"""An inertial reference for relative motion about a chief orbit, independent of the world.

The world's orbit models (Clohessy–Wiltshire, two-body, J2) move bodies in the LVLH frame
of a chief. This module computes the same relative motion the long way round, with numpy
and scipy only and nothing from the world: the chief and its deputies are mapped to
inertial states, integrated there under the full (nonlinear) gravity model, and mapped
back. It also gives the Clohessy–Wiltshire closed form, the linear limit for a circular
chief. The tests check it against a third-party propagator (brahe).

Conventions
-----------
- Inertial frame: Earth-centred inertial (ECI); metres, seconds, radians. Defaults
  :data:`MU_EARTH` = 3.986004418e14 m³/s², :data:`R_EARTH` = 6378137.0 m,
  :data:`J2_EARTH` = 1.08262668e-3; every function that uses them takes them as
  parameters.
- Orbit elements: semi-major axis ``a`` (m), eccentricity ``e``, inclination ``i``,
  right ascension of the ascending node ``raan`` (Ω), argument of perigee ``argp`` (ω),
  true anomaly ``nu`` (ν). Perifocal to ECI is ``R3(−Ω) R1(−i) R3(−ω)``.
- Gravity: two-body ``a = −μ r/|r|³``; J2 adds
  ``−(3/2) J2 μ R²/|r|⁵ [x(1 − 5z²/r²), y(1 − 5z²/r²), z(3 − 5z²/r²)]``.
- LVLH frame of a chief at ``r_c, v_c`` (ECI): ``x̂ = r_c/|r_c|`` (radial),
  ``ẑ = h/|h|`` with ``h = r_c × v_c`` (orbit normal), ``ŷ = ẑ × x̂`` (along-track).
  ``C = [x̂ ŷ ẑ]`` (columns) maps LVLH components to ECI. The frame turns at
  ``ω = (ω_x, 0, ω_z)`` in LVLH components, ``ω_z = |h|/|r_c|²`` and
  ``ω_x = |r_c| (a_c · ẑ)/|h|`` with ``a_c`` the chief's total acceleration (zero under
  two-body; the orbit plane turns under J2).
- A deputy's relative state: ``ρ = Cᵀ(r_d − r_c)`` and ``ρ̇ = Cᵀ(v_d − v_c) − ω × ρ``, the
  velocity seen in the rotating frame; inversely ``r_d = r_c + Cρ``,
  ``v_d = v_c + C(ρ̇ + ω × ρ)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import solve_ivp

Array = NDArray[np.float64]

MU_EARTH = 3.986004418e14
"""Earth's gravitational parameter μ, m³/s²."""
R_EARTH = 6378137.0
"""Earth's equatorial radius R, m (the J2 term's reference radius)."""
J2_EARTH = 1.08262668e-3
"""Earth's second zonal harmonic J2, dimensionless."""

OrbitModel = Literal["two-body", "j2"]
ORBIT_MODELS: tuple[OrbitModel, ...] = ("two-body", "j2")
"""The gravity models :func:`propagate_inertial` integrates."""


@dataclass(frozen=True)
class OrbitElements:
    """Classical (osculating) orbit elements of an elliptic orbit.

    Parameters
    ----------
    a : float
        Semi-major axis, m.
    e : float
        Eccentricity, 0 ≤ e < 1.
    i : float
        Inclination, rad.
    raan : float
        Right ascension of the ascending node Ω, rad.
    argp : float
        Argument of perigee ω, rad.
    nu : float
        True anomaly ν, rad.
    """

    a: float
    e: float
    i: float
    raan: float
    argp: float
    nu: float


def _r1(angle: float) -> Array:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, s], [0.0, -s, c]])


def _r3(angle: float) -> Array:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])


def perifocal_to_eci(elements: OrbitElements) -> Array:
    """The rotation ``R3(−Ω) R1(−i) R3(−ω)`` (3, 3) from perifocal to ECI components."""
    return _r3(-elements.raan) @ _r1(-elements.i) @ _r3(-elements.argp)


def elements_to_state(elements: OrbitElements, mu: float = MU_EARTH) -> tuple[Array, Array]:
    """The ECI state of a body on the orbit ``elements``.

    Parameters
    ----------
    elements : OrbitElements
        The orbit and the body's true anomaly on it.
    mu : float
        Gravitational parameter, m³/s².

    Returns
    -------
    position, velocity : ndarray (3,)
        ECI position (m) and velocity (m/s).
    """
    p = elements.a * (1.0 - elements.e**2)
    cos_nu, sin_nu = np.cos(elements.nu), np.sin(elements.nu)
    radius = p / (1.0 + elements.e * cos_nu)
    position = radius * np.array([cos_nu, sin_nu, 0.0])
    velocity = np.sqrt(mu / p) * np.array([-sin_nu, elements.e + cos_nu, 0.0])
    rotation = perifocal_to_eci(elements)
    return rotation @ position, rotation @ velocity


def state_to_elements(position: Array, velocity: Array, mu: float = MU_EARTH) -> OrbitElements:
    """The osculating elements of an ECI state, inverse of :func:`elements_to_state`.

    Parameters
    ----------
    position, velocity : ndarray (3,)
        ECI position (m) and velocity (m/s) of a body on an elliptic orbit.
    mu : float
        Gravitational parameter, m³/s².

    Returns
    -------
    OrbitElements
        Angles Ω, ω, ν in [0, 2π).

    Raises
    ------
    ValueError
        When the orbit is circular (e < 1e-10) or equatorial (sin i < 1e-10): ω, or Ω
        and ω, are undefined there.
    """
    r, v = np.asarray(position, float), np.asarray(velocity, float)
    h = np.cross(r, v)
    node = np.cross([0.0, 0.0, 1.0], h)
    eccentricity = ((v @ v - mu / np.linalg.norm(r)) * r - (r @ v) * v) / mu
    e = float(np.linalg.norm(eccentricity))
    h_hat = h / np.linalg.norm(h)
    if e < 1e-10 or np.linalg.norm(node) < 1e-10 * np.linalg.norm(h):
        raise ValueError("state_to_elements needs an eccentric, inclined orbit (ω, Ω defined)")
    node_hat, e_hat = node / np.linalg.norm(node), eccentricity / e
    return OrbitElements(
        a=float(1.0 / (2.0 / np.linalg.norm(r) - (v @ v) / mu)),
        e=e,
        i=float(np.arccos(np.clip(h_hat[2], -1.0, 1.0))),
        raan=float(np.arctan2(node_hat[1], node_hat[0]) % (2 * np.pi)),
        argp=float(np.arctan2(np.cross(node_hat, e_hat) @ h_hat, node_hat @ e_hat) % (2 * np.pi)),
        nu=float(np.arctan2(np.cross(e_hat, r) @ h_hat, e_hat @ r) % (2 * np.pi)),
    )


def _check_model(model: str) -> None:
    if model not in ORBIT_MODELS:
        raise ValueError(f"unknown orbit model {model!r}; use one of {', '.join(ORBIT_MODELS)}")


def gravity(
    position: Array,
    model: OrbitModel = "two-body",
    mu: float = MU_EARTH,
    radius: float = R_EARTH,
    j2: float = J2_EARTH,
) -> Array:
    """Gravitational acceleration at ECI positions.

    Parameters
    ----------
    position : ndarray (..., 3)
        ECI positions, m.
    model : {"two-body", "j2"}
        Point mass, or point mass plus the J2 zonal term.
    mu : float
        Gravitational parameter, m³/s².
    radius : float
        Reference radius of the J2 term, m.
    j2 : float
        Second zonal harmonic, dimensionless.

    Returns
    -------
    ndarray (..., 3)
        ECI acceleration, m/s².
    """
    _check_model(model)
    r2 = np.sum(position**2, axis=-1, keepdims=True)
    r = np.sqrt(r2)
    acceleration = -mu * position / (r2 * r)
    if model == "j2":
        z2_over_r2 = position[..., 2:3] ** 2 / r2
        factor = np.concatenate([1.0 - 5.0 * z2_over_r2] * 2 + [3.0 - 5.0 * z2_over_r2], axis=-1)
        acceleration = acceleration - 1.5 * j2 * mu * radius**2 / (r2 * r2 * r) * position * factor
    return acceleration


@dataclass(frozen=True)
class LvlhFrame:
    """The LVLH frame of a chief, at one instant or at many.

    Build it with :meth:`of_chief`. Arrays carry a leading time axis ``...`` (empty for
    one instant); deputies add an axis ``n`` before the last.

    Parameters
    ----------
    position, velocity : ndarray (..., 3)
        The chief's ECI position (m) and velocity (m/s).
    rotation : ndarray (..., 3, 3)
        ``C = [x̂ ŷ ẑ]``: LVLH components to ECI components.
    rate : ndarray (..., 3)
        The frame's angular velocity ``(ω_x, 0, ω_z)`` relative to ECI, in LVLH
        components, rad/s.
    """

    position: Array
    velocity: Array
    rotation: Array
    rate: Array

    @classmethod
    def of_chief(cls, position: Array, velocity: Array, acceleration: Array) -> LvlhFrame:
        """The frame of a chief at ECI ``position`` (m), ``velocity`` (m/s) and total
        ``acceleration`` (m/s²), each (..., 3)."""
        position, velocity = np.asarray(position, float), np.asarray(velocity, float)
        h = np.cross(position, velocity)
        h_norm = np.linalg.norm(h, axis=-1)
        r_norm = np.linalg.norm(position, axis=-1)
        x_hat = position / r_norm[..., None]
        z_hat = h / h_norm[..., None]
        rotation = np.stack([x_hat, np.cross(z_hat, x_hat), z_hat], axis=-1)
        omega_x = r_norm * np.sum(acceleration * z_hat, axis=-1) / h_norm
        rate = np.stack([omega_x, np.zeros_like(omega_x), h_norm / r_norm**2], axis=-1)
        return cls(position, velocity, rotation, rate)

    def to_inertial(self, rho: Array, rhodot: Array) -> tuple[Array, Array]:
        """Deputies' ECI states from their relative states.

        Parameters
        ----------
        rho, rhodot : ndarray (..., n, 3)
            Relative position (m) and velocity seen in the rotating frame (m/s), LVLH
            components.

        Returns
        -------
        position, velocity : ndarray (..., n, 3)
            ``r_c + Cρ`` (m) and ``v_c + C(ρ̇ + ω × ρ)`` (m/s), ECI.
        """
        rotation = self.rotation[..., None, :, :]
        relative_velocity = rhodot + np.cross(self.rate[..., None, :], rho)
        position = self.position[..., None, :] + _apply(rotation, rho)
        return position, self.velocity[..., None, :] + _apply(rotation, relative_velocity)

    def from_inertial(self, position: Array, velocity: Array) -> tuple[Array, Array]:
        """Deputies' relative states from their ECI states, inverse of :meth:`to_inertial`.

        Parameters
        ----------
        position, velocity : ndarray (..., n, 3)
            ECI position (m) and velocity (m/s).

        Returns
        -------
        rho, rhodot : ndarray (..., n, 3)
            ``Cᵀ(r_d − r_c)`` (m) and ``Cᵀ(v_d − v_c) − ω × ρ`` (m/s), LVLH components.
        """
        transpose = np.swapaxes(self.rotation, -1, -2)[..., None, :, :]
        rho = _apply(transpose, position - self.position[..., None, :])
        seen = _apply(transpose, velocity - self.velocity[..., None, :])
        return rho, seen - np.cross(self.rate[..., None, :], rho)


def _apply(matrix: Array, vectors: Array) -> Array:
    """``matrix @ vector`` over the leading axes: (..., 3, 3) and (..., 3) to (..., 3)."""
    return (matrix @ vectors[..., None])[..., 0]


def propagate_inertial(
    position: Array,
    velocity: Array,
    times: Array,
    model: OrbitModel = "two-body",
    *,
    mu: float = MU_EARTH,
    radius: float = R_EARTH,
    j2: float = J2_EARTH,
    rtol: float = 1e-12,
    atol: float = 1e-9,
) -> tuple[Array, Array]:
    """Integrate bodies in ECI under ``model`` with scipy's DOP853, all in one system.

    One system means one step sequence for every body, so the integration errors of
    nearby bodies are nearly the same and their differences (relative states) keep far
    more accuracy than each absolute state.

    Parameters
    ----------
    position, velocity : ndarray (n, 3)
        ECI positions (m) and velocities (m/s) at t = 0.
    times : ndarray (m,)
        Non-decreasing output times ≥ 0, the last > 0, s.
    model : {"two-body", "j2"}
        Gravity model, see :func:`gravity`.
    mu, radius, j2 : float
        Gravitational parameter (m³/s²), J2 reference radius (m) and J2.
    rtol : float
        Relative tolerance of the integrator.
    atol : float
        Absolute tolerance, m for positions and m/s for velocities.

    Returns
    -------
    position, velocity : ndarray (m, n, 3)
        ECI positions (m) and velocities (m/s) at ``times``.
    """
    times = np.asarray(times, float)
    if times.ndim != 1 or times.size == 0 or times[0] < 0 or times[-1] <= 0:
        raise ValueError("times must be a 1-D array of times ≥ 0 s ending after 0 s")
    if np.any(np.diff(times) < 0):
        raise ValueError("times must be non-decreasing")
    _check_model(model)
    position, velocity = np.asarray(position, float), np.asarray(velocity, float)
    n = position.shape[0]

    def derivative(_t: float, state: Array) -> Array:
        acceleration = gravity(state[: 3 * n].reshape(n, 3), model, mu, radius, j2)
        return np.concatenate([state[3 * n :], acceleration.ravel()])

    y0 = np.concatenate([position.ravel(), velocity.ravel()])
    solution = solve_ivp(
        derivative,
        (0.0, times[-1]),
        y0,
        method="DOP853",
        t_eval=times,
        rtol=rtol,
        atol=atol,
    )
    if not solution.success:
        raise RuntimeError(f"the inertial propagation failed: {solution.message}")
    states = solution.y.T
    return states[:, : 3 * n].reshape(-1, n, 3), states[:, 3 * n :].reshape(-1, n, 3)


@dataclass(frozen=True)
class RelativeTrajectory:
    """Deputies' relative motion about a chief, sampled at ``times``.

    Parameters
    ----------
    times : ndarray (m,)
        Sample times, s.
    rho, rhodot : ndarray (m, n, 3)
        Deputies' relative positions (m) and velocities seen in the rotating frame (m/s),
        LVLH components of the chief's frame at each time.
    frame : LvlhFrame
        The chief's frame at each time (arrays with a leading axis m).
    """

    times: Array
    rho: Array
    rhodot: Array
    frame: LvlhFrame


def propagate_relative(
    elements: OrbitElements,
    rho0: Array,
    rhodot0: Array,
    times: Array,
    model: OrbitModel = "two-body",
    *,
    mu: float = MU_EARTH,
    radius: float = R_EARTH,
    j2: float = J2_EARTH,
    rtol: float = 1e-12,
    atol: float = 1e-9,
) -> RelativeTrajectory:
    """Relative motion of deputies about a chief, integrated in ECI under ``model``.

    The chief starts at ``elements``; the deputies' relative states are mapped to ECI in
    the chief's LVLH frame (its rate from the chief's acceleration under ``model``),
    chief and deputies are integrated together by :func:`propagate_inertial`, and the
    deputies are mapped back to the chief's frame at every time.

    Parameters
    ----------
    elements : OrbitElements
        The chief's orbit at t = 0 (osculating under ``model``).
    rho0, rhodot0 : ndarray (n, 3)
        Deputies' relative positions (m) and velocities seen in the rotating frame (m/s)
        at t = 0, LVLH components.
    times : ndarray (m,)
        Non-decreasing output times ≥ 0, the last > 0, s.
    model : {"two-body", "j2"}
        Gravity model acting on chief and deputies alike.
    mu, radius, j2 : float
        Gravitational parameter (m³/s²), J2 reference radius (m) and J2.
    rtol, atol : float
        Integrator tolerances (``atol`` in m and m/s).

    Returns
    -------
    RelativeTrajectory
    """
    constants = {"mu": mu, "radius": radius, "j2": j2}
    chief_position, chief_velocity = elements_to_state(elements, mu)
    start = LvlhFrame.of_chief(
        chief_position, chief_velocity, gravity(chief_position, model, **constants)
    )
    deputy_position, deputy_velocity = start.to_inertial(
        np.asarray(rho0, float), np.asarray(rhodot0, float)
    )
    position, velocity = propagate_inertial(
        np.vstack([chief_position, deputy_position]),
        np.vstack([chief_velocity, deputy_velocity]),
        times,
        model,
        rtol=rtol,
        atol=atol,
        **constants,
    )
    frame = LvlhFrame.of_chief(
        position[:, 0], velocity[:, 0], gravity(position[:, 0], model, **constants)
    )
    rho, rhodot = frame.from_inertial(position[:, 1:], velocity[:, 1:])
    return RelativeTrajectory(np.asarray(times, float), rho, rhodot, frame)


def cw_transition(mean_motion: float, times: Array) -> Array:
    """The Clohessy–Wiltshire state-transition matrices at ``times``.

    The linearised relative motion about a circular chief of mean motion n,
    ``ẍ − 2nẏ − 3n²x = 0``, ``ÿ + 2nẋ = 0``, ``z̈ + n²z = 0`` in this module's LVLH frame
    (x radial, y along-track, z orbit normal), solved in closed form.

    Parameters
    ----------
    mean_motion : float
        n = sqrt(μ/a³), rad/s.
    times : ndarray (m,)
        Times since the initial state, s.

    Returns
    -------
    ndarray (m, 6, 6)
        Φ(t) with ``[ρ, ρ̇](t) = Φ(t) [ρ, ρ̇](0)``; states in m and m/s.
    """
    n = mean_motion
    nt = n * np.asarray(times, float)
    c, s = np.cos(nt), np.sin(nt)
    zero, one = np.zeros_like(nt), np.ones_like(nt)
    rows = [
        [4 - 3 * c, zero, zero, s / n, 2 * (1 - c) / n, zero],
        [6 * (s - nt), one, zero, -2 * (1 - c) / n, (4 * s - 3 * nt) / n, zero],
        [zero, zero, c, zero, zero, s / n],
        [3 * n * s, zero, zero, c, 2 * s, zero],
        [-6 * n * (1 - c), zero, zero, -2 * s, 4 * c - 3, zero],
        [zero, zero, -n * s, zero, zero, c],
    ]
    return np.moveaxis(np.array(rows), -1, 0)


def cw_relative(
    a: float, rho0: Array, rhodot0: Array, times: Array, mu: float = MU_EARTH
) -> tuple[Array, Array]:
    """Deputies' relative motion about a circular chief by the Clohessy–Wiltshire
    closed form (:func:`cw_transition`).

    Parameters
    ----------
    a : float
        The chief's orbit radius, m; n = sqrt(μ/a³).
    rho0, rhodot0 : ndarray (n, 3)
        Relative positions (m) and velocities seen in the rotating frame (m/s) at t = 0,
        LVLH components.
    times : ndarray (m,)
        Times, s.
    mu : float
        Gravitational parameter, m³/s².

    Returns
    -------
    rho, rhodot : ndarray (m, n, 3)
        Relative positions (m) and velocities (m/s) at ``times``, LVLH components.
    """
    transition = cw_transition(np.sqrt(mu / a**3), times)
    start = np.concatenate([np.asarray(rho0, float), np.asarray(rhodot0, float)], axis=-1)
    states = np.einsum("tij,nj->tni", transition, start)
    return states[..., :3], states[..., 3:]
