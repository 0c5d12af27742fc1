"""Mass and Coriolis matrices of a DH space manipulator in the thesis's velocity order.

``qd = [v_b, ω_b, θ̇]`` (eq. 4.4): the base's centre-of-mass velocity and angular
velocity, world frame, then the joint rates. ``M`` follows the block formulas of eqs
4.10–4.21; ``C`` the decoupled natural orthogonal complement of eqs 4.23–4.33, with each
body's twist ``[ω_i; v_i]`` taken at its centre of mass so that its mass matrix is
``diag(I_i, m_i 1)`` (eq. 4.25).
"""

from __future__ import annotations

import numpy as np

from dcsim.robots.kinematics import (
    Array,
    DHArrays,
    Kinematics,
    cross,
    point_jacobians,
    rotation_jacobians,
    skew,
)

_EYE = np.eye(3)


def mass_matrix(dh: DHArrays, kin: Kinematics) -> Array:
    """``M(q)`` (6 + n, 6 + n), eqs 4.5 and 4.10–4.21, SI units.

    The base–base coupling ``B`` is ``(m_tot [r_{s−g}×])ᵀ`` with ``r_{s−g} = r_g − r_b``:
    the transpose of eq. 4.12's matrix, as the kinetic energy's cross term
    ``v_bᵀ (ω_b × m_tot r_{s−g})`` gives it.
    """
    masses, r_is = dh.masses, kin.coms - kin.base_position
    jt = point_jacobians(kin, kin.coms, dh.lower)
    jr = rotation_jacobians(kin, dh.lower)
    total = dh.base_mass + masses.sum()
    r_sg = masses @ r_is / total
    skews = skew(r_is)
    inertia_sum = kin.inertias + masses[:, None, None] * np.einsum("iba,ibc->iac", skews, skews)
    e_block = kin.base_inertia + inertia_sum.sum(axis=0)
    d_block = np.einsum("i,iaj->aj", masses, jt)
    f_block = np.einsum("iab,ibj->aj", kin.inertias, jr) + np.einsum(
        "i,iab,ibj->aj", masses, skews, jt
    )
    h_m = np.einsum("iaj,iab,ibk->jk", jr, kin.inertias, jr) + np.einsum(
        "i,iaj,iak->jk", masses, jt, jt
    )
    upper = np.hstack([total * _EYE, -total * skew(r_sg), d_block])
    middle = np.hstack([total * skew(r_sg), e_block, f_block])
    lower = np.hstack([d_block.T, f_block.T, h_m])
    m = np.vstack([upper, middle, lower])
    return 0.5 * (m + m.T)


def _body_twists(kin: Kinematics, jt: Array, qd: Array) -> tuple[Array, Array]:
    """Angular velocities (n, 3) and centre-of-mass velocities (n, 3) of the links."""
    v_b, w_b, rates = qd[:3], qd[3:6], qd[6:]
    omegas = w_b + np.cumsum(kin.axes * rates[:, None], axis=0)
    velocities = v_b + cross(w_b, kin.coms - kin.base_position) + jt @ rates
    return omegas, velocities


def complement(dh: DHArrays, kin: Kinematics) -> tuple[Array, Array]:
    """``𝒩`` (eqs 4.27–4.33) as per-body blocks (n + 1, 6, 6 + n), ``[ω; v]`` rows at each
    body's centre of mass, and the link translational Jacobians (n, 3, n)."""
    n = dh.a.size
    jt = point_jacobians(kin, kin.coms, dh.lower)
    jr = rotation_jacobians(kin, dh.lower)
    blocks = np.zeros((n + 1, 6, 6 + n))
    blocks[:, 0:3, 3:6] = _EYE
    blocks[:, 3:6, 0:3] = _EYE
    blocks[1:, 0:3, 6:] = jr
    blocks[1:, 3:6, 3:6] = -skew(kin.coms - kin.base_position)
    blocks[1:, 3:6, 6:] = jt
    return blocks, jt


def complement_rate(dh: DHArrays, kin: Kinematics, jt: Array, qd: Array) -> tuple[Array, Array]:
    """``d𝒩/dt`` (n + 1, 6, 6 + n) along ``qd``, and the bodies' angular velocities
    (n + 1, 3), base first."""
    n = dh.a.size
    omegas, velocities = _body_twists(kin, jt, qd)
    axis_rates = cross(omegas, kin.axes)  # k̂_j is fixed in link j (and j − 1)
    joint_velocities = velocities + cross(omegas, kin.joint_points - kin.coms)
    arms = kin.coms[:, None, :] - kin.joint_points[None, :, :]
    arm_rates = velocities[:, None, :] - joint_velocities[None, :, :]
    columns = cross(axis_rates[None], arms) + cross(kin.axes[None], arm_rates)
    rate = np.zeros((n + 1, 6, 6 + n))
    rate[1:, 0:3, 6:] = (axis_rates[None] * dh.lower[:, :, None]).transpose(0, 2, 1)
    rate[1:, 3:6, 3:6] = -skew(velocities - qd[:3])
    rate[1:, 3:6, 6:] = (columns * dh.lower[:, :, None]).transpose(0, 2, 1)
    return rate, np.vstack([qd[3:6], omegas])


def body_inertias(dh: DHArrays, kin: Kinematics) -> tuple[Array, Array]:
    """Rotational inertias (n + 1, 3, 3) and masses (n + 1,) of the bodies, base first."""
    inertias = np.concatenate([kin.base_inertia[None], kin.inertias])
    return inertias, np.concatenate([[dh.base_mass], dh.masses])


def coriolis_matrix(dh: DHArrays, kin: Kinematics, qd: Array) -> Array:
    """``C(q, q̇)`` (6 + n, 6 + n) by eq. 4.23: ``𝒩ᵀ (𝓜 d𝒩/dt + 𝒲 𝓜 𝒩)``.

    ``𝒲 𝓜`` is eq. 4.26's per-body ``diag(ω_i× I_i, 0)``. With it ``Ṁ − 2C`` is
    skew-symmetric and ``C q̇`` is the exact velocity-dependent generalised force.
    """
    blocks, jt = complement(dh, kin)
    rate, omegas = complement_rate(dh, kin, jt, qd)
    inertias, masses = body_inertias(dh, kin)
    spin = np.einsum("bac,bcd->bad", skew(omegas), inertias)
    angular = np.einsum("bka,bkl,bli->ai", blocks[:, :3], inertias, rate[:, :3])
    angular += np.einsum("bka,bkl,bli->ai", blocks[:, :3], spin, blocks[:, :3])
    linear = np.einsum("bka,b,bki->ai", blocks[:, 3:], masses, rate[:, 3:])
    return angular + linear
