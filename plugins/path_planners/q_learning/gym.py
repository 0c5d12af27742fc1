"""The space manipulator's reach as a Gymnasium environment (optional extra ``rl``).

``dcsim/ManipulatorReachCells-v0`` is the cell task of the ``q-learning`` planner (the
space manipulator thesis, §5.5): the end effector moves one cell of a 3-D grid per step (six
actions: +z, −z, −y, +y, +x, −x; no move past the grid's edge), entering the target's
cell ends the episode with the target reward, entering a cell where the arm breaks a
joint limit, meets a singularity or loses sight of the target ends it with the
terminal reward, and any other move pays the step reward (less where the base moves
more than half as far as the end effector). The grid, the arm's state at each cell and
every reward are those the planner builds for the reach scenario (its parameters set
them), so any Gymnasium agent trains on exactly the planner's task. The environment
lives with the planner; importing this module registers it, and Gymnasium imports the
module itself when the id names it (also in a fresh process or a vector env's worker)::

    import gymnasium

    env = gymnasium.make(
        "dcsim_plugins.path_planners.q_learning.gym:dcsim/ManipulatorReachCells-v0"
    )
    observation, info = env.reset(seed=1)
    observation, reward, terminated, truncated, info = env.step(4)   # +x

The observation is the cell's flat index; ``info`` carries the cell's centre (m) and,
on entering a terminal cell, the constraint it breaks. Episodes start in the scenario's
start cell, or in a random non-terminal cell with ``reset(options={"random_start":
True})``, and are truncated after ``max_steps`` steps.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
from dcsim_plugins.path_planners.q_learning.planner import QLearningPlanner
from gymnasium import spaces

from dcsim.api import load_reach_problem, packaged_scenario_path

ENVIRONMENT_ID = "dcsim/ManipulatorReachCells-v0"
"""The id ``gymnasium.make`` knows the environment by, once this module is imported."""


class ReachCellsEnv(gymnasium.Env):
    """The reach task on the q-learning planner's cells (see the module).

    Parameters
    ----------
    scenario : str or Path or None
        A reach scenario; None: the packaged ``space_manipulator_reach.yaml``.
    start : array_like (3,) or None
        Start the end effector here instead of where the scenario puts it, m.
    max_steps : int
        Steps after which an episode is truncated.
    planner_params : dict or None
        Parameters of the ``q-learning`` planner that shape the cells and rewards
        (``cell_size``, ``margin``, limits and reward values).
    """

    metadata: dict[str, Any] = {"render_modes": []}

    def __init__(
        self,
        scenario: str | Path | None = None,
        start: Any = None,
        max_steps: int = 200,
        planner_params: dict[str, Any] | None = None,
    ) -> None:
        path = (
            packaged_scenario_path("space_manipulator_reach.yaml") if scenario is None else scenario
        )
        problem = load_reach_problem(path, start)
        planner = QLearningPlanner(planner_params or {}, np.random.default_rng(0))
        self.cells = planner.environment(problem)
        self.max_steps = max_steps
        self.observation_space = spaces.Discrete(self.cells.cells)
        self.action_space = spaces.Discrete(self.cells.next_cell.shape[1])
        self._starts = np.flatnonzero(~self.cells.ends)
        self._cell = self.cells.start
        self._steps = 0

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[int, dict[str, Any]]:
        """Start an episode in the start cell (or a random one with ``random_start``)."""
        super().reset(seed=seed)
        random_start = bool((options or {}).get("random_start", False))
        self._cell = (
            int(self.np_random.choice(self._starts)) if random_start else int(self.cells.start)
        )
        self._steps = 0
        return self._cell, self._info()

    def step(self, action: int) -> tuple[int, float, bool, bool, dict[str, Any]]:
        """Move one cell; the reward and the end of the episode are the planner's."""
        if not self.action_space.contains(action):
            raise ValueError(f"action must be an integer in [0, 6), got {action!r}")
        reward = float(self.cells.reward[self._cell, action])
        self._cell = int(self.cells.next_cell[self._cell, action])
        self._steps += 1
        terminated = bool(self.cells.ends[self._cell])
        truncated = not terminated and self._steps >= self.max_steps
        return self._cell, reward, terminated, truncated, self._info()

    def _info(self) -> dict[str, Any]:
        cell = self._cell
        info: dict[str, Any] = {"centre": self.cells.centres(np.array([cell]))[0]}
        if self.cells.terminal[cell]:
            info["constraint"] = self.cells.reasons[cell]
        if cell == self.cells.target:
            info["target"] = True
        return info


if ENVIRONMENT_ID not in gymnasium.registry:
    # gymnasium types entry_point as a callable taking any **kwargs, which no class with
    # named keyword parameters matches; gymnasium.make passes the keywords through.
    gymnasium.register(id=ENVIRONMENT_ID, entry_point=ReachCellsEnv)  # type: ignore[arg-type]
