"""``dcsim/Transfer-v0``: fly a transfer scenario's free flyer to its goal region.

The transfer mission flies without its path planner, so the goal the observation shows
is the goal region's centre and velocity; the episode terminates when the robot is
inside the region within its tolerances (``goal_reward``) or collides
(``collision_penalty``), and is truncated at ``world.duration``. The cost weights are
the scenario's ``mission.weights`` (w_dv s/m, w_L 1/m, w_T 1/s). Spaces and reward:
:mod:`dcsim.gym.free_flyer`. Without a scenario the packaged ``ffsr_obstacles.yaml``
is flown: a 5 kg free flyer crosses 6 m past four spheres, three of them across the
straight line.
"""

from __future__ import annotations

import numpy as np

from dcsim.gym.free_flyer import FreeFlyerEnv
from dcsim.missions.transfer.settings import TransferMissionSection


class TransferEnv(FreeFlyerEnv):
    """A transfer scenario as an environment (see the module and :class:`FreeFlyerEnv`)."""

    mission_type = "transfer"
    default_scenario = "ffsr_obstacles.yaml"

    def _mission_weights(self) -> np.ndarray:
        weights = self.scenario.mission_as(TransferMissionSection).weights
        return np.array([weights.delta_v, weights.length, weights.time])
