"""The base of dcsim's Gymnasium environments: a scenario's run, stepped by an agent.

An episode is one run of the scenario (:class:`~dcsim.run.loop.Runner`) recorded in
memory without keeping its rows: :meth:`MissionEnv.reset` opens it, each
:meth:`MissionEnv.step` flies one control period (``world.control_period``) with the
agent's action as the command (:meth:`~dcsim.run.loop.Runner.advance`), in place of
the controller's; the controller is asked only for the fields an action leaves to it
(the torque that holds the attitude, say), so an agent that gives the whole command
pays nothing for it. The mission flies without its path
planner (``path_planner: null``): the agent is the planner, and the mission's
reference — the goal region, the stand-off point of the target it chose, the drop
point — is what the observation calls the goal.

Every episode has its own seed: the one given to ``reset(seed=...)``, else one drawn
from the environment's generator (seeded by the first ``reset``), so a seed reproduces
an episode exactly. Rewards are computed from the true state (the observation is the
estimate); the terms are documented in docs/gym.md and by each environment.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from os import PathLike
from typing import Any, ClassVar

import gymnasium
import numpy as np
from gymnasium import spaces

from dcsim.errors import Problem, ScenarioError
from dcsim.messages import Command
from dcsim.registry.discovery import PluginRegistry
from dcsim.run.loop import Runner
from dcsim.run.setup import Overrides, RunSetup, ScenarioInput, override_texts, setup_run
from dcsim.scenario import Scenario
from dcsim.scenario.loader import packaged_scenario_path

SEED_RANGE = 2**31
"""Episode seeds drawn by the environment are below this (``world.seed`` values)."""


class EpisodeOver(RuntimeError):
    """``step`` was called on an episode that has ended: call ``reset`` first."""


class MissionEnv(gymnasium.Env[np.ndarray, np.ndarray]):
    """A scenario of one mission type as a Gymnasium environment (see the module).

    Parameters
    ----------
    scenario : str, Path, mapping or Scenario, optional
        A scenario of the environment's mission type; the packaged
        :attr:`default_scenario` if None.
    overrides : sequence of str or mapping
        ``key.path=value`` overrides, as ``dcsim run --set`` takes them.
    goal_reward : float
        Reward on meeting the mission's goal (the episode terminates).
    collision_penalty : float
        Reward taken away on a collision (the episode terminates).
    progress_weight : float
        Weight of the shaping term: this times the distance (m) closed towards the
        goal over the step, measured to the goal given at the step's start.
    registry : PluginRegistry, optional
        The plugins to choose from; the installed ones if None.

    Attributes
    ----------
    scenario : Scenario
        The resolved scenario every episode flies (its path planner removed).
    observation_names : tuple of str
        The name, with its unit suffix, of each entry of the observation.
    action_names : tuple of str
        The name of each entry of the action, with the limit it is scaled to.
    runner : Runner or None
        The current episode's run.
    start_state : RobotState
        The robot's true state at the current episode's start.
    """

    metadata = {"render_modes": []}  # noqa: RUF012  (Gymnasium's class attribute)
    mission_type: ClassVar[str]
    default_scenario: ClassVar[str]

    def __init__(
        self,
        scenario: ScenarioInput = None,
        overrides: Overrides = (),
        *,
        goal_reward: float = 10.0,
        collision_penalty: float = 10.0,
        progress_weight: float = 1.0,
        registry: PluginRegistry | None = None,
    ) -> None:
        source = packaged_scenario_path(self.default_scenario) if scenario is None else scenario
        texts = [*override_texts(overrides), "path_planner=null"]
        setup = setup_run(source, texts, registry=registry)
        if setup.scenario.mission.type != self.mission_type:
            message = (
                f"is {setup.scenario.mission.type}, but {type(self).__name__} flies "
                f"{self.mission_type} missions"
            )
            name = str(source) if isinstance(source, str | PathLike) else "the scenario"
            raise ScenarioError(name, [Problem("mission.type", message)])
        self.scenario: Scenario = setup.scenario
        self.registry = setup.registry
        self.goal_reward = float(goal_reward)
        self.collision_penalty = float(collision_penalty)
        self.progress_weight = float(progress_weight)
        self.runner: Runner | None = None
        self._collisions = 0
        self._over = False
        self.observation_names = tuple(self._observation_names())
        self.action_names = tuple(self._action_names())
        self.observation_space = spaces.Box(
            -np.inf, np.inf, shape=(len(self.observation_names),), dtype=np.float32
        )
        self.action_space = spaces.Box(-1.0, 1.0, shape=(len(self.action_names),), dtype=np.float32)

    # ------------------------------------------------------------------ Gymnasium
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Start an episode: a new run of the scenario with the episode's seed.

        Parameters
        ----------
        seed : int, optional
            The episode's ``world.seed`` (it also seeds the environment's generator,
            which draws the seeds of the episodes that follow).
        options : dict, optional
            Unused.

        Returns
        -------
        observation : ndarray (float32)
            See :attr:`observation_names`.
        info : dict
            As :meth:`step` gives it.
        """
        super().reset(seed=seed)
        episode_seed = seed if seed is not None else int(self.np_random.integers(SEED_RANGE))
        self.close()
        scenario = self._episode_scenario(episode_seed)
        setup = RunSetup.from_scenario(scenario, self.registry)
        self.runner = Runner(setup, keep_rows=False, controller_on_demand=True)
        self.runner.open()
        self._check_failure()
        assert self.runner.world is not None  # an open run has its world
        self.start_state = self.runner.world.robot_state()
        self._collisions = 0
        self._over = False
        self._start_episode()
        return self._observation(), self._info()

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Fly one control period with ``action`` as the command.

        Parameters
        ----------
        action : array_like
            Each entry in [-1, 1] (values beyond are clipped), scaled to the limit
            :attr:`action_names` gives.

        Returns
        -------
        observation, reward, terminated, truncated, info
            ``terminated`` when the mission's goal is met or the robot collides;
            ``truncated`` when the run ends otherwise (``world.duration`` reached, the
            mission gave up). ``info`` has ``time_s``, ``mode``, ``goal_met``,
            ``collisions`` and, once the episode is over, ``status`` and ``reason``.

        Raises
        ------
        EpisodeOver
            If the episode has ended (or none was started).
        """
        runner = self.runner
        if runner is None or runner.ended or self._over:
            raise EpisodeOver("the episode is over: call reset() to start another")
        clipped = np.clip(np.asarray(action, dtype=float), -1.0, 1.0)
        before = self._progress_state()
        runner.advance(command=self._command(clipped))
        self._check_failure()
        world = runner.world
        assert world is not None  # an open run has its world
        collided = len(world.collisions) > self._collisions
        self._collisions = len(world.collisions)
        goal_met = bool(runner.mission is not None and runner.mission.goal_met())
        reward = self._reward(before, clipped) - self.collision_penalty * collided
        reward += self._event_reward(before)
        terminated = goal_met or collided
        truncated = runner.ended and not terminated
        self._over = terminated or truncated  # a collision the run goes on after ends it too
        return self._observation(), float(reward), terminated, truncated, self._info()

    def close(self) -> None:
        """End the current episode's run, if one is open."""
        if self.runner is not None and not self.runner.summary:
            self.runner.close()
        self.runner = None

    # ------------------------------------------------------------------ per mission
    def _start_episode(self) -> None:
        """Take what the episode's steps reuse, once its run is open (nothing here)."""

    def _observation_names(self) -> Sequence[str]:
        """The observation's entries, named with their unit suffix."""
        raise NotImplementedError

    def _action_names(self) -> Sequence[str]:
        """The action's entries, each named with the limit it is scaled to."""
        raise NotImplementedError

    def _command(self, action: np.ndarray) -> Command | Mapping[str, np.ndarray]:
        """The command an action in [-1, 1] gives (SI units): a whole :class:`Command`,
        or the fields it sets, the scenario's controller giving the others."""
        raise NotImplementedError

    def _observation(self) -> np.ndarray:
        """The observation now (float32, laid out as :attr:`observation_names`)."""
        raise NotImplementedError

    def _progress_state(self) -> dict[str, Any]:
        """What the reward compares across a step, taken before it: the goal given,
        the distance to it, and the running totals the cost weights apply to."""
        raise NotImplementedError

    def _reward(self, before: Mapping[str, Any], action: np.ndarray) -> float:
        """The reward of the step just flown, collision penalty aside."""
        raise NotImplementedError

    def _event_reward(self, before: Mapping[str, Any]) -> float:
        """Reward for what the mission achieved over the step: the goal reward when the
        goal is met."""
        runner = self.runner
        assert runner is not None and runner.mission is not None
        return self.goal_reward if runner.mission.goal_met() else 0.0

    # ------------------------------------------------------------------ helpers
    def _episode_scenario(self, seed: int) -> Scenario:
        """The scenario an episode of seed ``seed`` flies."""
        world = self.scenario.world.model_copy(update={"seed": seed})
        return self.scenario.model_copy(update={"world": world})

    def _time_left(self) -> float:
        """The share of ``world.duration`` still to fly, 1 at the start and 0 at the end."""
        runner = self.runner
        assert runner is not None and runner.world is not None
        duration = self.scenario.world.duration
        return max(0.0, 1.0 - runner.world.time / duration)

    def _check_failure(self) -> None:
        """Raise the failure that ended the run, if a plugin failed."""
        runner = self.runner
        if runner is not None and runner.status == "failed":
            raise RuntimeError(f"the episode's run failed: {runner.reason}")

    def _info(self) -> dict[str, Any]:
        runner = self.runner
        assert runner is not None and runner.world is not None and runner.mission is not None
        info: dict[str, Any] = {
            "time_s": runner.world.time,
            "mode": runner.mode,
            "goal_met": bool(runner.mission.goal_met()),
            "collisions": len(runner.world.collisions),
        }
        if runner.ended:
            info.update(status=runner.status, reason=runner.reason)
        return info
