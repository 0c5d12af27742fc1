"""The chief's orbit and the exact relative dynamics of the ``two-body`` and ``j2`` worlds.

The world frame of an ``lvlh`` world is the chief's local-vertical local-horizontal
frame at every instant: x along the chief's position, z along its orbital angular
momentum h, y = z × x. Under ``cw`` bodies feel the Clohessy–Wiltshire accelerations
(:mod:`dcsim.world.environment`). Under ``two-body`` and ``j2`` the chief is propagated
in the Earth-centred inertial frame (:mod:`~dcsim.world.orbit.chief`), every free object
too (:mod:`~dcsim.world.orbit.objects`), and the robot's bodies feel the exact relative
acceleration of a point in the rotating frame (:mod:`~dcsim.world.orbit.relative`).

A relative velocity is the velocity seen in the rotating frame:
``v_deputy = v_chief + C (ρ̇ + ω × ρ)``, with ``C`` the LVLH axes as columns in the
inertial frame and ``ω`` the frame's angular velocity in LVLH components.
"""
