"""``capture-detumble`` controller: a space manipulator that grasps a body and detumbles it.

While the arm is free it is the ``computed-torque`` controller: the robot's model
``M(q)``, ``C(q, q̇)`` linearise base and joints, and each tracks its reference with
the bandwidth ``bandwidth`` — what an end effector meeting a moving fixture needs.

Once the end effector holds a body (``RobotSpec.held_mass`` > 0: a new spec after the
latch, which also brakes the joints), the model no longer describes the plant: the
body's mass and inertia, often larger than the robot's, hang on the arm, and the stack
turns as one body. The joints get no torque (their brakes hold them); the base, now
steering the whole stack, is held by springs and dampers sized for it:

    torque = K_a e_α + D_a ė_α,      force = K_p e_r + D_v ė_r,

(``e_α`` the rotation vector from the base's attitude to its reference, ``e_r`` the
position error, world frame), clipped to the robot's limits: the rate damping takes
the stack's angular momentum out at the base's largest torque at first, then
exponentially, and the stiffness brings the base back to the attitude it had at the
latch.
"""

from __future__ import annotations

from dcsim_plugins.controllers.computed_torque import (
    ComputedTorqueController,
    ComputedTorqueParams,
    tracking_errors,
)

from dcsim.api import (
    Command,
    Reference,
    RobotSpec,
    StateEstimate,
    Surroundings,
    hookimpl,
    quantity,
)


class CaptureDetumbleParams(ComputedTorqueParams):
    """Parameters of :class:`CaptureDetumbleController`: the computed-torque gains of the
    free arm, and the base's springs and dampers once the stack is held."""

    attitude_stiffness: float = quantity(
        200.0,
        unit="N*m/rad",
        ge=0,
        description="Stiffness of the base's attitude while a body is held.",
    )
    rate_damping: float = quantity(
        20000.0,
        unit="N*m*s/rad",
        gt=0,
        description="Damping of the base's angular rate while a body is held.",
    )
    position_stiffness: float = quantity(
        5.0, unit="N/m", ge=0, description="Stiffness of the base's position while a body is held."
    )
    velocity_damping: float = quantity(
        500.0,
        unit="N*s/m",
        ge=0,
        description="Damping of the base's velocity while a body is held.",
    )


class CaptureDetumbleController(ComputedTorqueController):
    """Computed torque while the arm is free; the stack's rates damped once it holds a body."""

    name = "capture-detumble"
    summary = "Computed torque for the free arm; a held body's stack detumbled by the base"
    Params = CaptureDetumbleParams
    params: CaptureDetumbleParams
    robots = ("manipulator",)

    def reset(self, robot: RobotSpec) -> None:
        """Take the model, the limits and whether the end effector holds a body."""
        super().reset(robot)
        self.holding = robot.held_mass > 0.0

    def command(
        self,
        time: float,
        estimate: StateEstimate,
        reference: Reference,
        surroundings: Surroundings,
    ) -> Command:
        """The computed-torque command while free; the stack's hold once a body is held."""
        if not self.holding:
            return super().command(time, estimate, reference, surroundings)
        error, rate_error, _ = tracking_errors(estimate, reference, self.n_joints)
        p = self.params
        force = p.position_stiffness * error[:3] + p.velocity_damping * rate_error[:3]
        torque = p.attitude_stiffness * error[3:6] + p.rate_damping * rate_error[3:6]
        return self.limited(force, torque, 0.0 * error[6:])


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Register the capture-and-detumble controller."""
    return [CaptureDetumbleController]
