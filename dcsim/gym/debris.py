"""``dcsim/Debris-v0``: fly the debris collector while the mission decides the targets.

The debris mission keeps its task planner, its grabs and its releases and flies
without its path planner: the goal the observation shows is the stand-off point of the
target the mission is after, or the drop point while it delivers (or where it holds
while it localises or plans). The observation adds the cargo on board and the targets
delivered, each as a share of the capacity and of all targets. Beside the reward terms
of :mod:`dcsim.gym.free_flyer` (cost weights ``(1 s/m, 0, 0)`` unless given: the
debris thesis minimises propellant), each grab earns ``grab_reward`` and each target
delivered ``delivery_reward``; the episode terminates when every target is delivered
(``goal_reward``) or on a collision, and is truncated at ``world.duration``. Without a
scenario the packaged ``default.yaml`` is flown.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from dcsim.gym.free_flyer import FreeFlyerEnv
from dcsim.run.setup import Overrides, ScenarioInput
from dcsim.world.objects import ObjectStatus


class DebrisEnv(FreeFlyerEnv):
    """A debris scenario as an environment (see the module and :class:`FreeFlyerEnv`).

    Parameters
    ----------
    grab_reward : float
        Reward for each target grabbed.
    delivery_reward : float
        Reward for each target delivered.
    **options
        As for :class:`FreeFlyerEnv`.
    """

    mission_type = "debris"
    default_scenario = "default.yaml"

    def __init__(
        self,
        scenario: ScenarioInput = None,
        overrides: Overrides = (),
        *,
        grab_reward: float = 1.0,
        delivery_reward: float = 1.0,
        **options: Any,
    ) -> None:
        self.grab_reward = float(grab_reward)
        self.delivery_reward = float(delivery_reward)
        super().__init__(scenario, overrides, **options)

    def _mission_weights(self) -> np.ndarray:
        return np.array([1.0, 0.0, 0.0])

    def _mission_names(self) -> Sequence[str]:
        return ("carried_share", "delivered_share")

    def _mission_observation(self) -> np.ndarray:
        counts = self._mission_counts()
        capacity = self.scenario.robot.capacity
        targets = max(counts["targets"], 1)
        return np.array([counts["carried"] / capacity, counts["delivered"] / targets])

    def _mission_counts(self) -> dict[str, Any]:
        runner = self.runner
        assert runner is not None and runner.world is not None
        field = runner.world.field
        carried, delivered = field.count(ObjectStatus.CARRIED), field.count(ObjectStatus.REMOVED)
        return {
            "carried": carried,
            "delivered": delivered,
            "captured": carried + delivered,
            "targets": int(field.is_target.sum()),
        }

    def _event_reward(self, before: Mapping[str, Any]) -> float:
        after = self._mission_counts()
        grabbed = after["captured"] - before["captured"]
        delivered = after["delivered"] - before["delivered"]
        event = self.grab_reward * grabbed + self.delivery_reward * delivered
        return event + super()._event_reward(before)
