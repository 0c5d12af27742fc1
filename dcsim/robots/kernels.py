"""The space manipulator model's compiled core: one pass over the arm for every frame,
centre of mass, inertia and Jacobian (the source thesis's eqs 3.1–3.10, 4.18, 4.20), and
the mass and Coriolis matrices from the bodies' Jacobians (eqs 4.10–4.33).

Compiled with numba, ``cache=True``: each function is compiled on its first call in an
installation and loaded from numba's cache afterwards. Every compiled function of the
model lives in this one file, because numba's cache notices a change in the file of the
function it loads but not in the files of the functions that one calls.

Arguments (see :class:`dcsim.robots.kinematics.DHArrays`): ``q = [r_b, quaternion x, y,
z, w, θ]`` (7 + n,), ``qd = [v_b, ω_b, θ̇]`` (6 + n,), world frame, base at its centre
of mass; ``links`` (n, 5) rows ``[a, d, cos α, sin α, θ offset]``; ``bodies`` (n + 1, 4)
rows ``[mass, principal moments (3)]``, base first; ``mount`` the origin of frame 0
from the base's centre of mass, base frame. SI units throughout.

**Turning columns.** Every column of ``qd`` after ``v_b``'s turns the bodies it carries
about an axis through a pivot: ``ω_b``'s three columns about the world axes through
``r_b`` (they carry every body), joint ``j``'s about ``k̂_j`` through the origin of frame
``j − 1`` (they carry links ``j … n``). A point ``r`` on a body moves with
``v = v_b + Σ_c k̂_c × (r − p_c) q̇_c`` and the body turns with ``ω = Σ_c k̂_c q̇_c``,
summed over the columns that carry it. So the Jacobian ``[v; ω] = 𝒩_i qd`` of body
``i`` at its centre of mass (the thesis's natural orthogonal complement ``𝒩``, eqs
4.27–4.33, with the linear rows first) and the end effector's (eq. 3.8) are one formula.

**Dynamics.** With ``𝓜_i = diag(m_i 1, I_i)`` (eq. 4.25, rows in the same order),

    M = Σ_i 𝒩_iᵀ 𝓜_i 𝒩_i,      C = Σ_i 𝒩_iᵀ (𝓜_i d𝒩_i/dt + 𝒲_i 𝓜_i 𝒩_i)      (4.23)

and ``𝒲_i 𝓜_i = diag(0, ω_i× I_i)`` (eq. 4.26). ``M`` is the matrix of the thesis's
block formulas (eqs 4.10–4.21), with the base–base coupling ``B`` the transpose of eq.
4.12's, as the kinetic energy's cross term ``v_bᵀ (ω_b × m_tot r_{s−g})`` gives it. With
this ``C``, ``Ṁ − 2C`` is skew-symmetric and ``C q̇`` is the exact velocity-dependent
generalised force. A column ``[k̂ × (r_i − p); k̂]`` of ``𝒩_i`` changes at
``[k̂̇ × (r_i − p) + k̂ × (ṙ_i − ṗ); k̂̇]``: the world axes are fixed and their pivot
``r_b`` moves with ``v_b``; joint ``j``'s axis and pivot are fixed in link ``j`` and
move with it.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

Array = NDArray[np.float64]

# The compiled functions below index arrays element by element and keep to loops, math
# and plain slicing: numba compiles numpy's array expressions, array unpacking and
# matrix products into far more code, which costs seconds of compilation each.


@njit(cache=True)
def quaternion_rotation(quaternion: Array, out: Array) -> None:
    """Fill ``out`` (3, 3) with the rotation matrix, body to world, of a quaternion
    ``[x, y, z, w]``, normalised first."""
    x, y, z, w = quaternion[0], quaternion[1], quaternion[2], quaternion[3]
    norm = math.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / norm, y / norm, z / norm, w / norm
    out[0, 0] = 1 - 2 * (y * y + z * z)
    out[0, 1] = 2 * (x * y - z * w)
    out[0, 2] = 2 * (x * z + y * w)
    out[1, 0] = 2 * (x * y + z * w)
    out[1, 1] = 1 - 2 * (x * x + z * z)
    out[1, 2] = 2 * (y * z - x * w)
    out[2, 0] = 2 * (x * z - y * w)
    out[2, 1] = 2 * (y * z + x * w)
    out[2, 2] = 1 - 2 * (x * x + y * y)


@njit(cache=True)
def world_kinematics(
    q: Array, links: Array, bodies: Array, mount: Array
) -> tuple[Array, Array, Array, Array, Array, Array, Array, Array]:
    """Every world-frame quantity of state ``q``, in the order of
    :class:`dcsim.robots.kinematics.Kinematics` after its ``base_position``: rotations
    (n + 1, 3, 3) and origins (n + 1, 3) of frames 0 … n, body centres of mass (n + 1, 3)
    and inertia tensors (n + 1, 3, 3), turning axes and pivots (3 + n, 3), body
    Jacobians (n + 1, 6, 6 + n) and the end effector's Jacobian (6, 6 + n)."""
    rotations, origins = _frames(q, links, mount)
    coms = _body_coms(q, origins)
    turn_axes, pivots = _turns(q, rotations, origins)
    body_jacobians = np.zeros((coms.shape[0], 6, 3 + turn_axes.shape[0]))
    for i in range(coms.shape[0]):  # the base: ω_b's columns; link i: joints 1 … i too
        _point_jacobian(turn_axes, pivots, 3 + i, coms[i], body_jacobians[i])
    jacobian = np.zeros((6, 3 + turn_axes.shape[0]))
    _point_jacobian(turn_axes, pivots, turn_axes.shape[0], origins[-1], jacobian)
    inertias = _body_inertias(rotations, bodies)
    return rotations, origins, coms, inertias, turn_axes, pivots, body_jacobians, jacobian


@njit(cache=True)
def mass_matrix(q: Array, links: Array, bodies: Array, mount: Array) -> Array:
    """``M(q)`` (6 + n, 6 + n), exactly symmetric: kg, kg·m, kg·m²."""
    _, _, _, inertias, _, _, body_jacobians, _ = world_kinematics(q, links, bodies, mount)
    return _symmetric(_summed(body_jacobians, _weighted(body_jacobians, inertias, bodies)))


@njit(cache=True)
def mass_and_coriolis(
    q: Array, qd: Array, links: Array, bodies: Array, mount: Array
) -> tuple[Array, Array]:
    """``M(q)`` and ``C(q, q̇)`` (each 6 + n, 6 + n) of eq. 4.23 from one pass."""
    _, _, coms, inertias, turn_axes, pivots, body_jacobians, _ = world_kinematics(
        q, links, bodies, mount
    )
    weighted = _weighted(body_jacobians, inertias, bodies)
    rates, omegas = _jacobian_rates(turn_axes, pivots, coms, body_jacobians, qd)
    weighted_rates = _weighted(rates, inertias, bodies)
    column_momentum = np.empty(3)
    for i in range(body_jacobians.shape[0]):  # + ω_i × I_i 𝒩_i's angular rows
        for column in range(body_jacobians.shape[2]):
            for row in range(3):
                column_momentum[row] = weighted[i, 3 + row, column]
            spin = _cross(omegas[i], column_momentum)
            for row in range(3):
                weighted_rates[i, 3 + row, column] += spin[row]
    m = _symmetric(_summed(body_jacobians, weighted))
    return m, _summed(body_jacobians, weighted_rates)


@njit(cache=True)
def _frames(q: Array, links: Array, mount: Array) -> tuple[Array, Array]:
    """Rotations (n + 1, 3, 3) and origins (n + 1, 3) of DH frames 0 … n."""
    n = links.shape[0]
    rotations, origins = np.empty((n + 1, 3, 3)), np.empty((n + 1, 3))
    quaternion_rotation(q[3:7], rotations[0])
    for row in range(3):
        origins[0, row] = q[row] + _dot(rotations[0, row], mount)
    for i in range(n):  # eq. 3.2: turn θ about z_{i−1}, shift d along it, a along x_i, twist α
        a, d, cos_alpha, sin_alpha = links[i, 0], links[i, 1], links[i, 2], links[i, 3]
        angle = q[7 + i] + links[i, 4]
        ct, st = math.cos(angle), math.sin(angle)
        for row in range(3):
            x, y, z = rotations[i, row, 0], rotations[i, row, 1], rotations[i, row, 2]
            x_new, y_turned = ct * x + st * y, ct * y - st * x
            rotations[i + 1, row, 0] = x_new
            rotations[i + 1, row, 1] = cos_alpha * y_turned + sin_alpha * z
            rotations[i + 1, row, 2] = cos_alpha * z - sin_alpha * y_turned
            origins[i + 1, row] = origins[i, row] + d * z + a * x_new
    return rotations, origins


@njit(cache=True)
def _body_coms(q: Array, origins: Array) -> Array:
    """Centres of mass (n + 1, 3): ``r_b``, then each link's DH segment's midpoint."""
    coms = np.empty_like(origins)
    for row in range(3):
        coms[0, row] = q[row]
        for i in range(1, origins.shape[0]):
            coms[i, row] = 0.5 * (origins[i - 1, row] + origins[i, row])
    return coms


@njit(cache=True)
def _body_inertias(rotations: Array, bodies: Array) -> Array:
    """World-axes inertia tensors ``R diag(moments) Rᵀ`` (n + 1, 3, 3)."""
    inertias = np.zeros_like(rotations)
    for i in range(rotations.shape[0]):
        for k in range(3):
            for row in range(3):
                for column in range(3):
                    inertias[i, row, column] += (
                        rotations[i, row, k] * bodies[i, 1 + k] * rotations[i, column, k]
                    )
    return inertias


@njit(cache=True)
def _turns(q: Array, rotations: Array, origins: Array) -> tuple[Array, Array]:
    """Turning axes and pivots (3 + n, 3) of the turning columns (the module's)."""
    n = rotations.shape[0] - 1
    turn_axes, pivots = np.zeros((3 + n, 3)), np.empty((3 + n, 3))
    for row in range(3):
        turn_axes[row, row] = 1.0
        for c in range(3):
            pivots[c, row] = q[row]
        for j in range(n):
            turn_axes[3 + j, row] = rotations[j, row, 2]
            pivots[3 + j, row] = origins[j, row]
    return turn_axes, pivots


@njit(cache=True)
def _point_jacobian(
    turn_axes: Array, pivots: Array, carried: int, point: Array, out: Array
) -> None:
    """Fill the zeroed ``out`` (6, 6 + n) with the ``[v; ω]`` Jacobian of ``point`` on a
    body that the first ``carried`` turning columns carry."""
    for c in range(3):
        out[c, c] = 1.0
    for c in range(carried):
        lever = _lever(turn_axes[c], point, pivots[c])
        for row in range(3):
            out[row, 3 + c] = lever[row]
            out[3 + row, 3 + c] = turn_axes[c, row]


@njit(cache=True)
def _jacobian_rates(
    turn_axes: Array, pivots: Array, coms: Array, body_jacobians: Array, qd: Array
) -> tuple[Array, Array]:
    """``d𝒩_i/dt`` along ``qd`` (n + 1, 6, 6 + n) and the bodies' angular velocities
    (n + 1, 3)."""
    n_bodies, n_turns = coms.shape[0], turn_axes.shape[0]
    velocities, omegas = np.empty((n_bodies, 3)), np.empty((n_bodies, 3))
    for i in range(n_bodies):
        for row in range(3):
            velocities[i, row] = _dot(body_jacobians[i, row], qd)
            omegas[i, row] = _dot(body_jacobians[i, 3 + row], qd)
    axis_rates, pivot_velocities = np.zeros((n_turns, 3)), np.empty((n_turns, 3))
    for c in range(3):
        for row in range(3):
            pivot_velocities[c, row] = velocities[0, row]
    for c in range(3, n_turns):
        link = c - 2  # joint j = c − 3 is fixed in link j + 1
        axis_rate = _cross(omegas[link], turn_axes[c])
        swing = _lever(omegas[link], pivots[c], coms[link])
        for row in range(3):
            axis_rates[c, row] = axis_rate[row]
            pivot_velocities[c, row] = velocities[link, row] + swing[row]
    rates = np.zeros_like(body_jacobians)
    for i in range(n_bodies):
        for c in range(3 + i):
            turning = _lever(axis_rates[c], coms[i], pivots[c])
            sliding = _lever(turn_axes[c], velocities[i], pivot_velocities[c])
            for row in range(3):
                rates[i, row, 3 + c] = turning[row] + sliding[row]
                rates[i, 3 + row, 3 + c] = axis_rates[c, row]
    return rates, omegas


@njit(cache=True)
def _weighted(blocks: Array, inertias: Array, bodies: Array) -> Array:
    """``𝓜_i blocks_i`` of every body: ``[m_i top_i; I_i bottom_i]`` (n + 1, 6, 6 + n)."""
    out = np.empty_like(blocks)
    for i in range(blocks.shape[0]):
        for column in range(blocks.shape[2]):
            for row in range(3):
                out[i, row, column] = bodies[i, 0] * blocks[i, row, column]
                out[i, 3 + row, column] = (
                    inertias[i, row, 0] * blocks[i, 3, column]
                    + inertias[i, row, 1] * blocks[i, 4, column]
                    + inertias[i, row, 2] * blocks[i, 5, column]
                )
    return out


@njit(cache=True)
def _summed(left: Array, right: Array) -> Array:
    """``Σ_i left_iᵀ right_i`` of per-body blocks (n + 1, 6, 6 + n) → (6 + n, 6 + n)."""
    columns = left.shape[2]
    out = np.zeros((columns, columns))
    for i in range(left.shape[0]):
        for k in range(left.shape[1]):
            for row in range(columns):
                factor = left[i, k, row]
                if factor != 0.0:  # most of a body's columns are empty
                    for column in range(columns):
                        out[row, column] += factor * right[i, k, column]
    return out


@njit(cache=True)
def _symmetric(m: Array) -> Array:
    """``(m + mᵀ) / 2``."""
    out = np.empty_like(m)
    for row in range(m.shape[0]):
        for column in range(m.shape[1]):
            out[row, column] = 0.5 * (m[row, column] + m[column, row])
    return out


@njit(cache=True)
def _dot(a: Array, b: Array) -> float:
    """``a · b`` of two vectors of one size."""
    total = 0.0
    for k in range(a.shape[0]):
        total += a[k] * b[k]
    return total


@njit(cache=True)
def _cross(a: Array, b: Array) -> tuple[float, float, float]:
    """``a × b`` of two 3-vectors."""
    return a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]


@njit(cache=True)
def _lever(axis: Array, point: Array, pivot: Array) -> tuple[float, float, float]:
    """``axis × (point − pivot)``: the velocity of ``point`` turning about ``axis`` through
    ``pivot`` at unit rate."""
    x, y, z = point[0] - pivot[0], point[1] - pivot[1], point[2] - pivot[2]
    return axis[1] * z - axis[2] * y, axis[2] * x - axis[0] * z, axis[0] * y - axis[1] * x
