"""dcsim's missions as Gymnasium environments (optional extra ``rl``; docs/gym.md).

Importing this module registers the environments, so Gymnasium's module-prefixed form
works in a fresh process and in a vector environment's workers::

    import gymnasium

    env = gymnasium.make("dcsim.gym:dcsim/Transfer-v0")   # the packaged transfer
    observation, info = env.reset(seed=1)
    observation, reward, terminated, truncated, info = env.step(env.action_space.sample())

``dcsim/Transfer-v0`` (:class:`TransferEnv`), ``dcsim/Debris-v0`` (:class:`DebrisEnv`)
and ``dcsim/Reach-v0`` (:class:`ReachEnv`) take a scenario of their mission and
overrides (``gymnasium.make(id, scenario="my.yaml", overrides=["world.duration=60"])``)
and their own options; one step flies one control period.
"""

from __future__ import annotations

from typing import Any

try:
    import gymnasium
except ModuleNotFoundError as missing:  # the optional extra is not installed
    raise ModuleNotFoundError(
        "dcsim.gym needs Gymnasium: pip install 'dcsim[rl]' (or pip install gymnasium)",
        name=missing.name,
    ) from None

from dcsim.gym.debris import DebrisEnv
from dcsim.gym.environment import EpisodeOver, MissionEnv
from dcsim.gym.free_flyer import FreeFlyerEnv
from dcsim.gym.reach import ReachEnv
from dcsim.gym.transfer import TransferEnv

ENVIRONMENTS: dict[str, type[MissionEnv]] = {
    "dcsim/Transfer-v0": TransferEnv,
    "dcsim/Debris-v0": DebrisEnv,
    "dcsim/Reach-v0": ReachEnv,
}
"""Each registered id and its environment class."""

for _id, _env in ENVIRONMENTS.items():
    if _id not in gymnasium.registry:
        _entry: Any = _env  # gymnasium types entry points as callables taking **kwargs
        gymnasium.register(id=_id, entry_point=_entry, disable_env_checker=False)

__all__ = [
    "ENVIRONMENTS",
    "DebrisEnv",
    "EpisodeOver",
    "FreeFlyerEnv",
    "MissionEnv",
    "ReachEnv",
    "TransferEnv",
]
