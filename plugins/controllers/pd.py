"""``pd`` controller: proportional-derivative tracking with force and speed limits.

The gains come from pole placement on the double integrator ẍ = u (per axis, per unit
mass) by Ackermann's formula (:func:`design_gains`): the closed-loop poles are those of a
second-order system of natural frequency ``bandwidth`` and damping ratio ``damping``,
giving ``kp = ω²`` and ``kd = 2ζω`` (to the last bits). The law is written in its speed-limited form

    v_cmd = v_ref + (kp / kd) (p_ref − p),   |v_cmd| ≤ max_speed
    F = m (kd (v_cmd − v) + a_ref),          |F| ≤ max_force

which equals ``F = m (kp e + kd ė + a_ref)`` while no limit is active.

When the reference gives an attitude, the shared attitude loop
(:mod:`dcsim_plugins.controllers.attitude`) turns the base towards it with its own
pole-placed gains; a reference without attitude leaves the attitude free.
"""

from __future__ import annotations

from dcsim_plugins.controllers.attitude import (
    AttitudeLoop,
    attitude_bandwidth,
    attitude_damping,
    design_gains,
)

from dcsim.api import (
    Command,
    Controller,
    PluginParams,
    Reference,
    RobotSpec,
    StateEstimate,
    Surroundings,
    clip_norm,
    hookimpl,
    quantity,
)


class PDParams(PluginParams):
    """Parameters of :class:`PDController`."""

    bandwidth: float = quantity(
        0.2, unit="rad/s", gt=0, description="Natural frequency ω of the closed position loop."
    )
    damping: float = quantity(0.9, gt=0, le=5, description="Damping ratio ζ of the closed loop.")
    attitude_bandwidth: float = attitude_bandwidth()
    attitude_damping: float = attitude_damping()


class PDController(Controller):
    """Speed- and force-limited PD tracking with pole-placed gains."""

    name = "pd"
    summary = "PD tracking with pole-placed gains, force and speed limits (baseline)"
    Params = PDParams
    params: PDParams

    def reset(self, robot: RobotSpec) -> None:
        """Design the gains and remember the robot's limits."""
        self.robot = robot
        self.kp, self.kd = design_gains(self.params.bandwidth, self.params.damping)
        self.attitude_loop = AttitudeLoop(
            self.params.attitude_bandwidth, self.params.attitude_damping
        )

    def command(
        self,
        time: float,
        estimate: StateEstimate,
        reference: Reference,
        surroundings: Surroundings,
    ) -> Command:
        """Force towards the reference; torque towards its attitude, if it gives one."""
        error = reference.position - estimate.position
        limit = min(self.robot.max_speed, reference.max_speed)
        v_cmd = clip_norm(reference.velocity + (self.kp / self.kd) * error, limit)
        acceleration = self.kd * (v_cmd - estimate.velocity) + reference.acceleration
        force = clip_norm(self.robot.mass * acceleration, self.robot.max_force)
        if reference.attitude is None:
            return Command(force=force)
        return Command(
            force=force, torque=self.attitude_loop.torque(self.robot, estimate, reference)
        )


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the PD controller."""
    return [PDController]
