"""The layered dynamic programme against enumeration of every path."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from dcsim.bench.layered_optimum import layered_optimum, optimality_gap


def random_instance(rng: np.random.Generator, m: int, count: int, blocked: float):
    """Edge lengths (some infinite) and node terms of a layered graph with one start
    (node 0 of layer 0) and one goal (node 0 of layer m)."""
    lengths = rng.uniform(0.5, 3.0, (m, count, count))
    lengths[rng.random(lengths.shape) < blocked] = np.inf
    node_cost = rng.uniform(0.0, 2.0, (m + 1, count))
    node_cost[rng.random(node_cost.shape) < blocked / 2] = np.inf
    node_cost[0, 0] = node_cost[m, 0] = 0.0
    node_cost[0, 1:] = node_cost[m, 1:] = np.inf
    return lengths, node_cost


def enumerated(lengths: np.ndarray, node_cost: np.ndarray) -> float:
    """The least objective over every path from node 0 of layer 0 to node 0 of layer m."""
    m, count, _ = lengths.shape
    best = math.inf
    for inner in itertools.product(range(count), repeat=m - 1):
        path = (0, *inner, 0)
        cost = sum(lengths[i, path[i], path[i + 1]] for i in range(m))
        cost += sum(node_cost[i, k] for i, k in enumerate(path))
        best = min(best, cost)
    return best


@pytest.mark.parametrize("seed", range(30))
def test_the_programme_finds_the_enumerated_optimum(seed):
    rng = np.random.default_rng(seed)
    m, count = int(rng.integers(2, 6)), int(rng.integers(1, 5))
    lengths, node_cost = random_instance(rng, m, count, blocked=0.3)
    expected = enumerated(lengths, node_cost)
    found = layered_optimum(lengths, node_cost)
    if math.isinf(expected):
        assert math.isinf(found.cost) and found.path is None
        return
    assert found.cost == pytest.approx(expected)
    path = found.path
    assert path[0] == 0 and path[-1] == 0 and len(path) == m + 1
    again = sum(lengths[i, path[i], path[i + 1]] for i in range(m))
    again += sum(node_cost[i, k] for i, k in enumerate(path))
    assert again == pytest.approx(found.cost)


def test_no_finite_path_is_reported_as_such():
    lengths = np.ones((3, 2, 2))
    lengths[1] = np.inf
    node_cost = np.zeros((4, 2))
    found = layered_optimum(lengths, node_cost)
    assert math.isinf(found.cost) and found.path is None


def test_mismatched_arrays_are_refused():
    with pytest.raises(ValueError, match="one layered graph"):
        layered_optimum(np.ones((3, 2, 2)), np.zeros((3, 2)))


def test_the_gap_is_in_per_cent_of_the_optimum():
    assert optimality_gap(101.0, 100.0) == pytest.approx(1.0)
    assert optimality_gap(0.0, 0.0) == 0.0
    assert math.isinf(optimality_gap(1.0, 0.0))
