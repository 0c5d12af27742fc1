"""``underactuated`` controller: partial base control of a space manipulator (the source
the space manipulator thesis, eqs 6.8–6.25).

Only the attitude control system and the joint motors act; the base's translation is
left free (no thrust: the command's force is always exactly zero). The generalised
coordinates split into actuated and unactuated ones (eq. 6.23), in the order of
``q̇ = [v_base, ω_base, θ̇]``:

    q_a = (base attitude α, joint angles θ)   (3 + n),      q_u = base position r   (3)

and ``M``, ``C`` into the matching blocks (eqs 6.12–6.13, 6.24–6.25). With no force on
the unactuated coordinates, the second row of eq. 6.14 gives their acceleration (6.15),
and the actuated coordinates obey the reduced equation of motion (6.16–6.17)

    M̄ q̈_a + C̄₁ q̇_a + C̄₂ q̇_u = F,
    M̄  = M_aa − M_au M_uu⁻¹ M_ua,
    C̄₁ = C_aa − M_au M_uu⁻¹ C_ua,
    C̄₂ = C_au − M_au M_uu⁻¹ C_uu.

The law (6.18, 6.20, 6.22)

    F = M̄ u + C̄₁ q̇_a + C̄₂ q̇_u,      u = q̈_a,d + K_D ė_a + K_P e_a

makes ``q̈_a = u`` (6.19), so the actuated error obeys ``ë + K_D ė + K_P e = 0`` (6.21)
while the base translates as the conservation of linear momentum dictates. The errors
are those of the ``computed-torque`` controller restricted to ``q_a``: the attitude error
is the world-frame rotation vector ``rotvec(q_d ⊗ q⁻¹)`` in the ``ω`` slots, the joint
error ``θ_d − θ``. The thesis writes ``e = q_a − q_ad`` under eq. 6.20; with the
``+ K_P e`` of that equation only ``e = q_ad − q_a`` (its eq. 6.5) gives stable error
dynamics, and that is the sign used. The reference's base position, velocity and
acceleration are ignored.

``F``'s first three entries are the base torque (N·m, world frame), clipped to
``max_torque`` in magnitude, the rest the joint torques (N·m), each clipped to its
``joint_torque_limits``. Gains are diagonal: the thesis's ``k_P = 10``, ``k_D = 100``
by default (eqs 7.4–7.5), or placed from a bandwidth and damping as in
``computed-torque``. ``k_D = 100`` needs a control period well under ``2 / k_D = 20 ms``
for the sampled loop to stay close to the continuous one.
"""

from __future__ import annotations

import numpy as np
from dcsim_plugins.controllers.computed_torque import (
    ComputedTorqueController,
    ComputedTorqueParams,
    generalised_state,
)

from dcsim.api import (
    Command,
    Reference,
    StateEstimate,
    Surroundings,
    hookimpl,
    quantity,
)

_ACTUATED = slice(3, None)
"""``q_a`` in the velocity order: base angular velocity and joint rates."""
_UNACTUATED = slice(0, 3)
"""``q_u`` in the velocity order: base velocity."""


class UnderactuatedParams(ComputedTorqueParams):
    """Parameters of :class:`UnderactuatedController`."""

    kp: float = quantity(
        10.0,
        unit="1/s^2",
        gt=0,
        description="Proportional gain k_P, every diagonal entry of K_P (thesis eq. 7.4); "
        "ignored when bandwidth is set.",
    )
    kd: float = quantity(
        100.0,
        unit="1/s",
        gt=0,
        description="Derivative gain k_D, every diagonal entry of K_D (thesis eq. 7.5); "
        "ignored when bandwidth is set.",
    )


class UnderactuatedController(ComputedTorqueController):
    """Partial base control: base attitude and joints tracked, base translation free."""

    name = "underactuated"
    summary = "Partial base control: attitude and joints by reduced computed torque, no thrust"
    Params = UnderactuatedParams
    params: UnderactuatedParams

    def command(
        self,
        time: float,
        estimate: StateEstimate,
        reference: Reference,
        surroundings: Surroundings,
    ) -> Command:
        """Base torque and joint torques of eq. 6.22; zero base force."""
        q, qd = generalised_state(estimate)
        u = self.outer_loop(estimate, reference)[_ACTUATED]
        reduced_m, reduced_c1, reduced_c2 = reduced_dynamics(*self.model.dynamics(q, qd))
        f = reduced_m @ u + reduced_c1 @ qd[_ACTUATED] + reduced_c2 @ qd[_UNACTUATED]
        return self.limited(np.zeros(3), f[:3], f[3:])


def reduced_dynamics(
    mass: np.ndarray, coriolis: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``M̄``, ``C̄₁`` and ``C̄₂`` of eq. 6.17 with ``q_a`` = (attitude, joints) and
    ``q_u`` = base position (eq. 6.25).

    Parameters
    ----------
    mass, coriolis : ndarray (6 + n, 6 + n)
        ``M(q)`` and ``C(q, q̇)`` in the order of ``q̇ = [v_base, ω_base, θ̇]``.

    Returns
    -------
    reduced_mass : ndarray (3 + n, 3 + n)
    reduced_c1 : ndarray (3 + n, 3 + n)
    reduced_c2 : ndarray (3 + n, 3)
    """
    a, u = _ACTUATED, _UNACTUATED
    # M_uu⁻¹ [M_ua  C_ua  C_uu]: one solve with the 3 × 3 block of the base's translation.
    solved = np.linalg.solve(mass[u, u], np.hstack([mass[u, a], coriolis[u, a], coriolis[u, u]]))
    n_a = mass.shape[0] - 3
    m_au = mass[a, u]
    reduced_mass = mass[a, a] - m_au @ solved[:, :n_a]
    reduced_c1 = coriolis[a, a] - m_au @ solved[:, n_a : 2 * n_a]
    reduced_c2 = coriolis[a, u] - m_au @ solved[:, 2 * n_a :]
    return reduced_mass, reduced_c1, reduced_c2


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the underactuated controller."""
    return [UnderactuatedController]
