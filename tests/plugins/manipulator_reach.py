"""The thesis's reach (end effector from [1.4, 0.9, −0.8] m to [1.5, 0.7, −1.0] m) as a
joint-space quintic with the base held, for flying manipulator controllers on the model."""

from __future__ import annotations

import numpy as np

from dcsim.api import Reference
from dcsim.testing.manipulator import thesis_robot

ROBOT = thesis_robot()
MODEL = ROBOT.model
IDENTITY = np.array([0.0, 0.0, 0.0, 1.0])
SEED = np.concatenate([np.zeros(3), IDENTITY, [0.3, 0.8, -0.6, 0.4, 0.5, -0.2]])
START = MODEL.inverse_kinematics([1.4, 0.9, -0.8], SEED).q
GOAL = MODEL.inverse_kinematics([1.5, 0.7, -1.0], START).q
DURATION = 4.0
"""Length of the reach, s."""
PERIOD = 0.01
"""Control period, s."""


def reference(t: float) -> Reference:
    """The quintic from START's joints to GOAL's (rest to rest in DURATION), base held at
    the origin with the identity attitude."""
    s = min(max(t / DURATION, 0.0), 1.0)
    shape = 10 * s**3 - 15 * s**4 + 6 * s**5
    rate = (30 * s**2 - 60 * s**3 + 30 * s**4) / DURATION
    acceleration = (60 * s - 180 * s**2 + 120 * s**3) / DURATION**2
    span = GOAL[7:] - START[7:]
    return Reference(
        time=t,
        position=np.zeros(3),
        attitude=IDENTITY,
        joint_positions=START[7:] + shape * span,
        joint_velocities=rate * span,
        joint_accelerations=acceleration * span,
    )


def reference_states(times: np.ndarray) -> np.ndarray:
    """``q_d`` at each time (k, 13)."""
    return np.array(
        [np.concatenate([np.zeros(3), IDENTITY, reference(t).joint_positions]) for t in times]
    )
