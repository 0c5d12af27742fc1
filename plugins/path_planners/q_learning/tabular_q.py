"""Tabular Q-learning on a cell environment (the space manipulator thesis, §5.4–5.5).

Each episode starts in a cell drawn uniformly from the non-terminal cells other than the
target's (the agent must find its way from anywhere) and runs until it enters the
target's cell, a terminal cell, or ``max_steps`` actions have been taken. At each step
the thesis's ε-greedy rule (Algorithm 5.2) takes the greedy action — the first action of
largest ``Q(s, ·)`` — when a uniform draw is below ε, a uniformly random action
otherwise; ε rises linearly from ``ε_start`` in the first episode to ``ε_end`` in the last
(eq. 5.2). The temporal-difference update (eq. 5.1, Algorithm 5.3) is

    Q(s, a) ← Q(s, a) + α [r + γ max_a' Q(s', a') − Q(s, a)],

with ``max_a' Q(s', ·)`` taken as 0 when ``s'`` ends the episode. The table starts at 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from dcsim_plugins.path_planners.deadline import check


@dataclass(frozen=True)
class Schedule:
    """Training constants.

    Attributes
    ----------
    episodes : int
        Episodes ``N_ep``.
    max_steps : int
        Most actions per episode.
    alpha, gamma : float
        Learning rate and discount factor.
    epsilon_start, epsilon_end : float
        ε in the first and the last episode (the probability of the greedy action).
    """

    episodes: int = 2000
    max_steps: int = 200
    alpha: float = 0.9
    gamma: float = 0.9
    epsilon_start: float = 0.1
    epsilon_end: float = 0.9

    def epsilon(self, episode: int) -> float:
        """ε of ``episode`` (0-based), linear from ``epsilon_start`` to ``epsilon_end``."""
        if self.episodes == 1:
            return self.epsilon_end
        fraction = episode / (self.episodes - 1)
        return self.epsilon_start + (self.epsilon_end - self.epsilon_start) * fraction


@dataclass(frozen=True)
class Training:
    """A trained table and how training went.

    Attributes
    ----------
    q : ndarray (cells, actions)
        The Q-table.
    returns : ndarray (episodes,)
        The sum of the rewards of each episode (the thesis's cumulated reward).
    steps : ndarray (episodes,) of int
        Actions taken in each episode.
    """

    q: np.ndarray
    returns: np.ndarray
    steps: np.ndarray


def choose_action(q_row: np.ndarray, epsilon: float, draw: float, random_action: int) -> int:
    """Algorithm 5.2: the greedy action (the first of largest ``Q``) when the uniform
    ``draw`` is below ``epsilon``, ``random_action`` otherwise."""
    return int(np.argmax(q_row)) if draw < epsilon else int(random_action)


def td_update(
    q: np.ndarray, cell: int, action: int, reward: float, after: int, ends: bool,
    alpha: float, gamma: float,
) -> None:  # fmt: skip
    """One temporal-difference update of ``q`` in place (eq. 5.1)."""
    future = 0.0 if ends else float(q[after].max())
    q[cell, action] += alpha * (reward + gamma * future - q[cell, action])


def train(
    next_cell: np.ndarray,
    reward: np.ndarray,
    ends: np.ndarray,
    starts: np.ndarray,
    schedule: Schedule,
    rng: np.random.Generator,
    deadline: float = float("inf"),
) -> Training:
    """Train a Q-table on a deterministic environment.

    Parameters
    ----------
    next_cell : ndarray (cells, actions) of int
        The cell each action leads to.
    reward : ndarray (cells, actions)
        The reward of each action.
    ends : ndarray (cells,) of bool
        Cells whose entry ends an episode.
    starts : ndarray of int
        Cells an episode may start from (drawn uniformly).
    schedule : Schedule
        Episodes, steps, α, γ and the ε ramp.
    rng : numpy.random.Generator
        Draws the starts, the ε tests and the random actions.
    deadline : float
        ``time.monotonic()`` by which training must end (checked every 50 episodes).

    Raises
    ------
    OutOfTime
        If the deadline passes first.
    """
    cells, actions = next_cell.shape
    q = np.zeros((cells, actions))
    returns = np.zeros(schedule.episodes)
    steps = np.zeros(schedule.episodes, dtype=int)
    successors, rewards, stops = next_cell.tolist(), reward.tolist(), ends.tolist()
    for episode in range(schedule.episodes):
        if episode % 50 == 0:
            check(deadline, f"{episode} of {schedule.episodes} episodes")
        epsilon = schedule.epsilon(episode)
        draws = rng.random(schedule.max_steps)
        random_actions = rng.integers(0, actions, schedule.max_steps)
        cell = int(starts[rng.integers(len(starts))])
        total = 0.0
        for step in range(schedule.max_steps):
            action = choose_action(q[cell], epsilon, draws[step], random_actions[step])
            after, gained = successors[cell][action], rewards[cell][action]
            done = stops[after]
            td_update(q, cell, action, gained, after, done, schedule.alpha, schedule.gamma)
            total += gained
            cell = after
            if done:
                break
        returns[episode], steps[episode] = total, step + 1
    return Training(q, returns, steps)


@dataclass(frozen=True)
class Rollout:
    """The greedy path from a cell.

    Attributes
    ----------
    cells : list of int
        Cells visited, the first included.
    outcome : str
        ``"target"``, ``"terminal"`` (it entered a terminal cell), ``"loop"`` (it came back
        to a cell) or ``"stuck"`` (no progress within the step limit).
    discounted_return : float
        ``Σ γ^k r_k`` along the path.
    """

    cells: list[int]
    outcome: str
    discounted_return: float


def greedy_rollout(
    q: np.ndarray,
    next_cell: np.ndarray,
    reward: np.ndarray,
    ends: np.ndarray,
    target: int,
    start: int,
    gamma: float,
) -> Rollout:
    """Follow the greedy action (first of largest Q) from ``start`` until the target, a
    terminal cell, or a revisit."""
    cells, total, discount = [start], 0.0, 1.0
    seen = {start}
    cell = start
    for _ in range(len(next_cell)):
        action = int(np.argmax(q[cell]))
        after = int(next_cell[cell, action])
        total += discount * float(reward[cell, action])
        discount *= gamma
        cells.append(after)
        if after == target:
            return Rollout(cells, "target", total)
        if ends[after]:
            return Rollout(cells, "terminal", total)
        if after in seen:
            return Rollout(cells, "loop", total)
        seen.add(after)
        cell = after
    return Rollout(cells, "stuck", total)
