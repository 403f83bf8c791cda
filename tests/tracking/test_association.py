"""The association's shortcut: when no cluster and no track has more than one pair within
its gate, the tracker takes those pairs without solving the assignment; they must be the
pairs the optimal assignment keeps."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment

from zenav.services.tracking import _loops

NO_MATCH = 1e9


def assigned(cost: np.ndarray) -> list[int]:
    """Each row's column in the optimal assignment, pairs beyond the gate dropped."""
    owner = [-1] * cost.shape[0]
    rows, cols = linear_sum_assignment(cost)
    for r, c in zip(rows.tolist(), cols.tolist(), strict=True):
        if cost[r, c] < NO_MATCH:
            owner[r] = c
    return owner


@pytest.mark.parametrize("seed", range(40))
def test_lone_pairs_are_the_optimal_assignments_pairs(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n, k = (int(v) for v in rng.integers(1, 9, 2))
    cost = np.full((n, k), NO_MATCH)
    rows = rng.permutation(n)[: min(n, k)]
    cols = rng.permutation(k)[: min(n, k)]
    for r, c in zip(rows, cols, strict=True):  # a matching, some pairs left out
        if rng.random() < 0.7:
            cost[r, c] = rng.uniform(0.0, 1.5)
    lone = _loops.lone_pairs(cost, NO_MATCH)
    assert lone is not None
    assert lone == assigned(cost)


def test_a_choice_is_left_to_the_assignment() -> None:
    # cluster 0 is within two tracks' gates: the shortcut declines
    assert _loops.lone_pairs(np.array([[0.2, 0.3], [NO_MATCH, NO_MATCH]]), NO_MATCH) is None
    # two clusters within one track's gate
    assert _loops.lone_pairs(np.array([[0.2, NO_MATCH], [0.4, NO_MATCH]]), NO_MATCH) is None
    assert _loops.lone_pairs(np.array([[NO_MATCH, 0.2], [0.4, NO_MATCH]]), NO_MATCH) == [1, 0]


def test_gated_distances_are_the_distances_within_each_gate() -> None:
    points = np.array([[0.0, 0.0], [3.0, 4.0]])
    cost = _loops.gated_distances(points, [(0.0, 0.0, 0.5), (0.0, 4.0, 1.0)], 2.5, NO_MATCH)
    # point 1 is 5 m from track 0 (gate 3 m) and 3 m from track 1 (gate 3.5 m)
    assert cost.tolist() == [[0.0, NO_MATCH], [NO_MATCH, 3.0]]


@pytest.mark.parametrize("seed", range(10))
def test_gated_distances_are_the_numpy_formulation_to_the_bit(seed: int) -> None:
    rng = np.random.default_rng(seed)
    points = rng.normal(0.0, 3.0, (int(rng.integers(1, 12)), 2))
    pred = rng.normal(0.0, 3.0, (int(rng.integers(1, 12)), 2))
    radius = rng.uniform(0.1, 1.0, (pred.shape[0],))
    gate = 0.8
    # the tracker's numpy code before it was compiled
    dx = points[:, None, 0] - pred[None, :, 0]
    dy = points[:, None, 1] - pred[None, :, 1]
    dist = np.sqrt(dx * dx + dy * dy)
    want = np.where(dist <= (radius + gate)[None, :], dist, NO_MATCH)
    tracks = [(x, y, r) for (x, y), r in zip(pred.tolist(), radius.tolist(), strict=True)]
    got = _loops.gated_distances(points, tracks, gate, NO_MATCH)
    assert got.tolist() == want.tolist()
