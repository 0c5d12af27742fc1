"""The ants of ``ant-colony``: roulette walks over a layered graph and the pheromone they
lay (eqs 10–13 of the ant colony paper).

Not a plugin itself; :mod:`ant_colony` runs it on the graph of :mod:`layered_graph`.

Ants (:func:`solve_colony`, eqs 10–13)
    All ``ants`` start at S each cycle and advance layer by layer together. From node p
    an ant moves to node q of the next layer with probability
    ``τ_pq^α η_pq^β / Σ_q' τ_pq'^α η_pq'^β`` over the allowed q (eq. 11), η being 0 for
    a blocked segment: one numpy pass per layer for all ants spins every roulette wheel
    at once (cumulative sums of the weights and one uniform draw per ant from the
    plugin's generator). After a cycle every segment's pheromone becomes
    ``ρ τ + Σ_k Q/F_k`` over the ants k that used it (eqs 12–13; ``persistence`` is the
    paper's ρ, ``1 − ρ`` evaporates), starting from ``initial_pheromone`` (C). The colony
    stops when every ant took the same path (converged), when the best path found has
    not improved for ``stall_cycles`` cycles (converged), after ``max_cycles`` cycles, or
    at the time budget. The answer is the best path found in any cycle.
Departures from the paper (each a parameter; the defaults use them)
    ``visibility: objective`` uses ``η = 1/(d_pq + δ/d_min,q)``, the reciprocal of what
    the step adds to F (``length`` is the paper's ``1/d_pq``, :func:`visibility`);
    ``local_search`` moves single points of every ant's path to the best node of their
    layer given their neighbours while F falls (:func:`descend`), before the pheromone
    is laid; ``deposit_by: best`` lets only the cycle's best ant lay pheromone (``all``:
    the paper); ``pheromone_floor`` keeps every segment's pheromone at least that share
    of the most one can hold (``k Q / (F_best (1 − ρ))``, k the ants that lay), so the
    colony keeps exploring (0: the paper). :mod:`ant_colony` says why.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from dcsim_plugins.path_planners.ant_colony.layered_graph import LayeredGraph

if TYPE_CHECKING:
    from dcsim_plugins.path_planners.ant_colony.planner import AntColonyParams

_BELOW_ONE = 1.0 - 2.0**-30  # largest roulette draw: p + draw < p + 1 for any node p


def visibility(graph: LayeredGraph, beta: float, kind: str = "objective") -> np.ndarray:
    """``η^β`` of every segment (0 for a blocked one), (m, P, P).

    Parameters
    ----------
    graph : LayeredGraph
        Its segment lengths and node terms.
    beta : float
        β.
    kind : {"length", "objective"}
        ``length``: the paper's ``η = 1/d_pq``. ``objective``: ``η = 1/(d_pq + δ/d_min,q)``,
        the reciprocal of what the step adds to F.
    """
    steps = graph.lengths
    if kind == "objective":
        steps = steps + graph.node_cost[1:, None, :]
    finite = np.isfinite(steps)
    safe = np.where(finite & (steps > 0), steps, 1.0)
    return np.where(finite, safe**-beta, 0.0)


def transition_weights(pheromone: np.ndarray, eta_beta: np.ndarray, alpha: float) -> np.ndarray:
    """``τ^α η^β`` of every segment, the numerator of eq. 11."""
    if alpha == 1.0:
        return pheromone * eta_beta
    return pheromone**alpha * eta_beta


def transition_probabilities(weights: np.ndarray) -> np.ndarray:
    """Eq. 11: each row of ``weights`` (m, P, P) divided by its sum (rows of unusable
    nodes, which sum to 0, stay 0)."""
    totals = weights.sum(axis=-1, keepdims=True)
    return np.divide(weights, totals, out=np.zeros_like(weights), where=totals > 0)


def walk(weights: np.ndarray, draws: np.ndarray) -> np.ndarray:
    """Paths of a colony through the layers by roulette wheel (Steps 2–3).

    Parameters
    ----------
    weights : ndarray (m, P, P)
        ``τ^α η^β`` of every segment (0 for a segment never to be taken).
    draws : ndarray (m, A)
        Uniform numbers in [0, 1), one per ant and layer.

    Returns
    -------
    ndarray (A, m + 1) of int
        Each ant's node in each layer, starting at node 0 of layer 0.
    """
    m, ants = draws.shape
    count = weights.shape[2]
    wheels = np.cumsum(weights, axis=2)
    totals = wheels[:, :, -1:]
    # Each row's wheel scaled to [0, 1] and shifted by its node index, so that one
    # sorted search per layer spins every ant's wheel: row p spans [p, p + 1].
    wheels = np.divide(wheels, totals, out=np.ones_like(wheels), where=totals > 0)
    wheels += np.arange(count)[:, None]
    wheels = wheels.reshape(m, count * count)
    # A draw just below 1 must stay below p + 1 after the shift (zero-weight segments
    # then are never chosen: the first wheel value above a draw ends a positive weight).
    shifted = np.minimum(draws, _BELOW_ONE)
    paths = np.zeros((ants, m + 1), dtype=np.intp)
    here = paths[:, 0]
    for i in range(m):
        here = np.searchsorted(wheels[i], here + shifted[i], side="right") - here * count
        paths[:, i + 1] = here
    return paths


def lay_pheromone(
    pheromone: np.ndarray,
    paths: np.ndarray,
    costs: np.ndarray,
    persistence: float,
    deposit: float,
) -> np.ndarray:
    """Eqs 12–13: ``ρ τ + Σ_k Q/F_k`` over the ants k that used each segment.

    Parameters
    ----------
    pheromone : ndarray (m, P, P)
        τ before the update.
    paths : ndarray (A, m + 1) of int
        The ants' paths this cycle.
    costs : ndarray (A,)
        Their objectives F.
    persistence, deposit : float
        ρ and Q.

    Returns
    -------
    ndarray (m, P, P)
        τ after the update (a new array).
    """
    m, count, _ = pheromone.shape
    flat = (np.arange(m) * count + paths[:, :-1]) * count + paths[:, 1:]
    share = np.repeat(deposit / costs, m)
    laid = np.bincount(flat.ravel(), weights=share, minlength=pheromone.size)
    return persistence * pheromone + laid.reshape(pheromone.shape)


def descend(graph: LayeredGraph, paths: np.ndarray, sweeps: int = 10) -> np.ndarray:
    """Paths improved by moving one point at a time to the best node of its layer given
    its neighbours, while that lowers F (local search; not in the paper).

    Odd and even cross-sections are moved in turn, so every move of a half-sweep is one
    numpy pass over all ants and layers.

    Parameters
    ----------
    graph : LayeredGraph
        Segment lengths and node terms.
    paths : ndarray (A, m + 1) of int
        Paths to improve.
    sweeps : int
        Largest number of sweeps over the cross-sections.

    Returns
    -------
    ndarray (A, m + 1) of int
        Improved paths (a new array); F of each is at most that of the path it came from.
    """
    m = graph.lengths.shape[0]
    paths = paths.copy()
    for _ in range(sweeps):
        moved = False
        for first in (1, 2):
            layers = np.arange(first, m, 2)
            if not len(layers):
                continue
            costs = (
                graph.lengths[layers[None, :] - 1, paths[:, layers - 1], :]
                + graph.node_cost[layers][None]
                + graph.lengths[layers[None, :], :, paths[:, layers + 1]]
            )
            best = np.argmin(costs, axis=2)
            now = np.take_along_axis(costs, paths[:, layers][..., None], axis=2)[..., 0]
            lowest = np.take_along_axis(costs, best[..., None], axis=2)[..., 0]
            better = lowest < now - 1e-12 * np.abs(now)
            if better.any():
                moved = True
                paths[:, layers] = np.where(better, best, paths[:, layers])
        if not moved:
            break
    return paths


@dataclass(frozen=True)
class ColonyResult:
    """What a colony found, and how it got there.

    Attributes
    ----------
    path : ndarray (m + 1,) of int
        The best path found (node per layer).
    cost : float
        Its objective F.
    history : ndarray (cycles,)
        The best F found up to each cycle.
    cycle_best : ndarray (cycles,)
        The best F of each cycle's ants.
    cycles : int
        Cycles run.
    converged : bool
        Whether the colony stopped because every ant took one path or the best stalled.
    stop : str
        ``"one path"``, ``"stalled"``, ``"max cycles"`` or ``"budget"``.
    pheromone : ndarray (m, P, P)
        τ after the last cycle.
    """

    path: np.ndarray
    cost: float
    history: np.ndarray
    cycle_best: np.ndarray
    cycles: int
    converged: bool
    stop: str
    pheromone: np.ndarray


def solve_colony(
    graph: LayeredGraph,
    params: AntColonyParams,
    rng: np.random.Generator,
    deadline: float = math.inf,
) -> ColonyResult:
    """Run the colony on a graph until it converges, runs out of cycles or of time.

    Parameters
    ----------
    graph : LayeredGraph
        With a path (:attr:`LayeredGraph.has_path`).
    params : AntColonyParams
        α, β, ρ, Q, C, ants, max and stall cycles.
    rng : numpy.random.Generator
        Source of every roulette draw.
    deadline : float
        ``time.monotonic()`` after which no new cycle starts.

    Returns
    -------
    ColonyResult
    """
    if not graph.has_path:
        raise ValueError("the graph has no path from the start to the goal")
    m = graph.lengths.shape[0]
    eta_beta = visibility(graph, params.beta, params.visibility)
    pheromone = np.full(graph.lengths.shape, params.initial_pheromone)
    best_cost, best_path, improved = math.inf, np.zeros(m + 1, dtype=np.intp), 0
    history, cycle_best = [], []
    stop = "max cycles"
    for cycle in range(1, params.max_cycles + 1):
        weights = transition_weights(pheromone, eta_beta, params.alpha)
        paths = walk(weights, rng.random((m, params.ants)))
        if params.local_search:
            paths = descend(graph, paths)
        costs = graph.costs(paths)
        k = int(np.argmin(costs))
        cycle_best.append(float(costs[k]))
        if costs[k] < best_cost:
            best_cost, best_path, improved = float(costs[k]), paths[k].copy(), cycle
        history.append(best_cost)
        layers = slice(k, k + 1) if params.deposit_by == "best" else slice(None)
        pheromone = lay_pheromone(
            pheromone, paths[layers], costs[layers], params.persistence, params.deposit
        )
        if params.pheromone_floor > 0:
            layers_by = 1 if params.deposit_by == "best" else params.ants
            most = layers_by * params.deposit / (best_cost * (1.0 - params.persistence))
            np.maximum(pheromone, params.pheromone_floor * most, out=pheromone)
        if (paths == paths[0]).all():
            stop = "one path"
            break
        if cycle - improved >= params.stall_cycles:
            stop = "stalled"
            break
        if time.monotonic() > deadline:
            stop = "budget" if cycle < params.max_cycles else stop
            break
    return ColonyResult(
        path=best_path,
        cost=best_cost,
        history=np.array(history),
        cycle_best=np.array(cycle_best),
        cycles=len(history),
        converged=stop in ("one path", "stalled"),
        stop=stop,
        pheromone=pheromone,
    )
