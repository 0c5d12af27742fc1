"""The exact optimum of a layered path objective: a yardstick for layered-graph planners.

A planner such as the ant colony of the ant colony paper chooses one node in each layer
of a graph whose layers are cross-sections of the start-goal segment, and scores a path
by

    F = Σᵢ w_i(kᵢ, kᵢ₊₁) + Σᵢ c_i(kᵢ)

a sum of per-edge lengths (infinite for blocked edges) and per-node terms (the paper's
``δ / d_min``). Such a sum is minimised exactly by dynamic programming over the layers
(the Viterbi recursion): the cheapest way to each node of layer i + 1 is its own term
plus the least, over the nodes of layer i, of the cheapest way there plus the edge.
Each layer is one numpy minimum over the predecessors (broadcast over every pair), so
the cost is O(m P²) for m layers of P nodes.

The graph is passed as plain arrays, so the yardstick knows no planner: a planner's own
bench (the ``ant-colony`` plugin's ``dcsim bench ant-colony``) hands it the arrays of
the graph it searched and scores its answer against the optimum of exactly that graph
with :func:`optimality_gap`. Public as ``dcsim.api.layered_optimum``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class LayeredOptimum:
    """The cheapest path through a layered graph.

    Attributes
    ----------
    cost : float
        Its objective F (``inf`` when no path has a finite cost).
    path : ndarray (m + 1,) of int or None
        Its node in each layer; None when there is no finite path.
    """

    cost: float
    path: np.ndarray | None


def layered_optimum(lengths: np.ndarray, node_cost: np.ndarray) -> LayeredOptimum:
    """Minimise ``Σ lengths[i, kᵢ, kᵢ₊₁] + Σ node_cost[i, kᵢ]`` over paths (k₀ … k_m).

    Parameters
    ----------
    lengths : ndarray (m, P, P)
        ``lengths[i, p, q]``: the edge from node p of layer i to node q of layer i + 1
        (``inf``: not allowed), m.
    node_cost : ndarray (m + 1, P)
        The term of each node (``inf``: not allowed; a single start node is expressed by
        ``inf`` on every other node of layer 0, a single goal likewise in layer m).

    Returns
    -------
    LayeredOptimum
        Ties are broken towards the lowest node index.
    """
    lengths = np.asarray(lengths, dtype=float)
    node_cost = np.asarray(node_cost, dtype=float)
    m = lengths.shape[0]
    if node_cost.shape != (m + 1, lengths.shape[1]) or lengths.shape[1] != lengths.shape[2]:
        raise ValueError(
            f"lengths {lengths.shape} and node_cost {node_cost.shape} do not describe one "
            "layered graph: expected (m, P, P) and (m + 1, P)"
        )
    best = node_cost[0].copy()
    choices = np.empty((m, lengths.shape[2]), dtype=np.intp)
    for i in range(m):
        through = best[:, None] + lengths[i]  # (p, q): cheapest way to q via p
        choices[i] = np.argmin(through, axis=0)
        best = through[choices[i], np.arange(through.shape[1])] + node_cost[i + 1]
    end = int(np.argmin(best))
    cost = float(best[end])
    if not math.isfinite(cost):
        return LayeredOptimum(math.inf, None)
    path = np.empty(m + 1, dtype=np.intp)
    path[m] = end
    for i in range(m - 1, -1, -1):
        path[i] = choices[i, path[i + 1]]
    return LayeredOptimum(cost, path)


def optimality_gap(cost: float, optimum: float) -> float:
    """How far ``cost`` is above ``optimum``, in per cent of the optimum (``inf`` above an
    optimum of 0)."""
    if optimum == 0:
        return 0.0 if cost == 0 else math.inf
    return 100.0 * (cost - optimum) / abs(optimum)
