"""The ``lqr`` controller: a linear quadratic regulator on the double integrator.

Per axis the plant is ``ẍ = u`` (acceleration). The weights follow Bryson's rule:
``Q = diag(1/e_max², 1/v_max²)`` and ``R = 1/a_max²`` for the largest acceptable
position error, velocity error and acceleration. python-control's ``lqr`` gives the
gains ``[kp, kd]``; the force is ``m (kp e + kd ė + a_ref)``, scaled down to the force
limit, with the speed kept within the collector's limit.
"""

from __future__ import annotations

import control
import numpy as np

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


class LQRParams(PluginParams):
    """Parameters of :class:`LQRController` (Bryson's rule)."""

    position_error: float = quantity(1.0, unit="m", gt=0, description="Acceptable position error.")
    velocity_error: float = quantity(
        0.1, unit="m/s", gt=0, description="Acceptable velocity error."
    )
    acceleration: float = quantity(0.02, unit="m/s^2", gt=0, description="Acceptable acceleration.")


def lqr_gains(params: LQRParams) -> tuple[float, float]:
    """The regulator's position and velocity gains (1/s² and 1/s)."""
    a = np.array([[0.0, 1.0], [0.0, 0.0]])
    b = np.array([[0.0], [1.0]])
    q = np.diag([params.position_error**-2, params.velocity_error**-2])
    r = np.array([[params.acceleration**-2]])
    gains, _, _ = control.lqr(a, b, q, r)
    kp, kd = np.asarray(gains).ravel()
    return float(kp), float(kd)


class LQRController(Controller):
    """Linear quadratic regulator with force and speed limits."""

    name = "lqr"
    summary = "Linear quadratic regulator, weights by Bryson's rule (python-control)"
    Params = LQRParams
    params: LQRParams

    def reset(self, robot: RobotSpec) -> None:
        """Compute the gains and remember the limits."""
        self.robot = robot
        self.kp, self.kd = lqr_gains(self.params)

    def command(
        self,
        time: float,
        estimate: StateEstimate,
        reference: Reference,
        surroundings: Surroundings,
    ) -> Command:
        """Regulate towards the reference within the force and speed limits."""
        wanted = reference.velocity + (self.kp / self.kd) * (reference.position - estimate.position)
        wanted = clip_norm(wanted, self.robot.max_speed)
        force = self.robot.mass * (self.kd * (wanted - estimate.velocity) + reference.acceleration)
        return Command(force=clip_norm(force, self.robot.max_force))


@hookimpl
def dcsim_plugin_classes() -> list[type]:
    """Tell dcsim about the controller."""
    return [LQRController]
