"""Exact answers on a deterministic cell task, the yardstick of tabular learners such as the
``q-learning`` planner (its own ``dcsim bench q-learning``; public through ``dcsim.api``).

The environment (``next_cell`` and ``reward``, cells × actions; ``ends``: cells whose entry
ends an episode) is a deterministic Markov decision process. Value iteration

    V(s) = max_a [ r(s, a) + γ · (0 if ends[s'] else V(s')) ],      s' = next_cell(s, a),

converges to the optimal discounted return from every cell (a contraction for γ < 1; for
γ = 1 it is iterated until no value changes). The cells from which the target can be
reached at all are those with a chain of actions into the target's cell through cells
that do not end an episode: the ceiling for the planner's "working cells".
"""

from __future__ import annotations

import numpy as np


def optimal_values(
    next_cell: np.ndarray,
    reward: np.ndarray,
    ends: np.ndarray,
    gamma: float,
    tolerance: float = 1e-12,
    max_sweeps: int = 100_000,
) -> np.ndarray:
    """Optimal discounted return ``V*`` of every cell (cells,), by value iteration.

    Raises
    ------
    RuntimeError
        If the values have not settled after ``max_sweeps`` sweeps.
    """
    values = np.zeros(len(next_cell))
    continues = ~ends[next_cell]
    for _ in range(max_sweeps):
        updated = (reward + gamma * np.where(continues, values[next_cell], 0.0)).max(axis=1)
        if np.max(np.abs(updated - values)) <= tolerance:
            return updated
        values = updated
    raise RuntimeError(f"value iteration did not settle in {max_sweeps} sweeps")


def reachable_cells(next_cell: np.ndarray, ends: np.ndarray, target: int) -> np.ndarray:
    """Cells (bool mask) from which some chain of actions enters ``target`` through cells
    that do not end an episode; cells that end an episode themselves are excluded."""
    reach = np.zeros(len(next_cell), dtype=bool)
    reach[target] = True
    while True:
        leads = reach[next_cell] & ((next_cell == target) | ~ends[next_cell])
        updated = reach | (leads.any(axis=1) & ~ends)
        if np.array_equal(updated, reach):
            break
        reach = updated
    reach[target] = False
    return reach


def working_cells(
    q: np.ndarray, next_cell: np.ndarray, ends: np.ndarray, target: int
) -> np.ndarray:
    """Cells (bool mask) whose greedy path (first action of largest ``Q``) enters the
    target's cell without entering a terminal cell or coming back to a cell; cells that
    end an episode are excluded."""
    cells = len(next_cell)
    successor = next_cell[np.arange(cells), np.argmax(q, axis=1)]
    status = np.zeros(cells, dtype=np.int8)  # 0 unknown, 1 works, −1 fails, 2 on this path
    status[target] = 1
    status[ends & (np.arange(cells) != target)] = -1
    for start in range(cells):
        path, cell = [], start
        while status[cell] == 0:
            status[cell] = 2
            path.append(cell)
            cell = int(successor[cell])
        status[path] = -1 if status[cell] == 2 else status[cell]  # a cycle never arrives
    works = status == 1
    works[ends] = False
    return works
