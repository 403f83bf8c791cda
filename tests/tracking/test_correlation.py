"""Eqs. 7-15 and the decision tree against hand-worked numbers, and their invariants."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from zenav.services.geometry import wrap_degrees
from zenav.services.tracking.correlation import (
    alpha_o_from_heading,
    best_match,
    centre_distance,
    classify,
    coincidence,
    correlate,
    motion,
    non_overlap_rate,
    overlap_cells,
    spatial_correlation,
    union_cells,
)

CELL = 0.5


def sorted_overlap(a: list[int], b: list[int]) -> int:
    """Eqs. 8-9 as the paper writes them: test disjointness, sort the bounds, count."""
    if a[1] < b[0] or a[0] > b[1] or a[3] < b[2] or a[2] > b[3]:  # Eq. 8
        return 0
    xb = sorted([a[0], a[1], b[0], b[1]])
    yb = sorted([a[2], a[3], b[2], b[3]])
    return (xb[2] - xb[1] + 1) * (yb[2] - yb[1] + 1)  # Eq. 9


# --- worked example --------------------------------------------------------------------


def test_worked_overlap_example() -> None:
    # S(t): x 2..4, y 1..3 -> 3 x 3 = 9 cells. S(t-1): x 3..6, y 2..5 -> 4 x 4 = 16 cells.
    # x bounds sorted 2 <= 3 <= 4 <= 6: x_b2 = 3, x_b3 = 4 -> 4 - 3 + 1 = 2 columns;
    # y bounds sorted 1 <= 2 <= 3 <= 5: y_b2 = 2, y_b3 = 3 -> 2 rows. Overlap 4 cells.
    cur, prev = [2, 4, 1, 3], [3, 6, 2, 5]
    inter = overlap_cells(cur, prev)
    assert inter == 4
    union = union_cells(9, 16, inter)
    assert union == 21  # Eq. 10: 9 + 16 - 4
    assert coincidence(inter, 9) == pytest.approx(4 / 9)  # Eq. 11
    eta = non_overlap_rate(inter, union)
    assert eta == pytest.approx(17 / 21)  # Eq. 13: 1 - 4/21
    # Centres 1 m apart = 2 cells: varsigma = 0.5/3 + 0.5/(1 + 17/21) = 0.166667 + 0.276316
    delta = centre_distance((1.0, 1.0), (1.6, 1.8), CELL)
    assert delta == pytest.approx(2.0)
    assert spatial_correlation(delta, eta) == pytest.approx(0.442982, abs=1e-6)  # Eq. 12
    corr = correlate([(1.0, 1.0)], [cur], [(1.6, 1.8)], [prev], cell=CELL)
    assert corr.inter[0, 0] == 4
    assert corr.union[0, 0] == 21
    assert corr.xi[0, 0] == pytest.approx(4 / 9)
    assert corr.varsigma[0, 0] == pytest.approx(0.442982, abs=1e-6)


def test_identical_areas_give_varsigma_one_and_eta_zero() -> None:
    # The paper's case: same place, same box -> delta = 0, eta = 0, varsigma = 1 (Eq. 7).
    box = [3, 5, -2, 0]
    corr = correlate([(1.7, -0.4)], [box], [(1.7, -0.4)], [box], cell=CELL)
    assert corr.inter[0, 0] == corr.union[0, 0] == 9
    assert corr.eta[0, 0] == 0.0
    assert corr.delta[0, 0] == 0.0
    assert corr.xi[0, 0] == 1.0
    assert corr.varsigma[0, 0] == 1.0


@pytest.mark.parametrize(
    "prev",
    [
        [0, 1, 0, 1],  # x_max(t-1) < x_min(t)
        [6, 7, 2, 3],  # x_min(t-1) > x_max(t)
        [2, 4, -3, 0],  # y_max(t-1) < y_min(t)
        [2, 4, 4, 9],  # y_min(t-1) > y_max(t)
    ],
)
def test_isolated_areas_give_eta_one(prev: list[int]) -> None:
    cur = [2, 4, 1, 3]
    inter = overlap_cells(cur, prev)  # Eq. 8: no overlap
    assert inter == 0
    union = union_cells(9, int(np.prod([prev[1] - prev[0] + 1, prev[3] - prev[2] + 1])), inter)
    assert non_overlap_rate(inter, union) == 1.0
    assert coincidence(inter, 9) == 0.0
    # varsigma falls to y_eta / 2 + y_delta / (delta + 1)
    assert spatial_correlation(3.0, 1.0) == pytest.approx(0.5 / 4 + 0.25)


def test_boxes_sharing_one_column_overlap_by_inclusive_counting() -> None:
    # x 2..4 and 4..7 share column 4: x_b3 - x_b2 + 1 = 1, not 0.
    assert overlap_cells([2, 4, 0, 0], [4, 7, 0, 0]) == 1
    assert overlap_cells([2, 4, 0, 2], [4, 7, 1, 5]) == 2


def test_full_overlap_of_a_box_inside_another() -> None:
    # Eq. 7 from the small box's side: the overlap is all of it.
    assert overlap_cells([3, 4, 3, 4], [0, 9, 0, 9]) == 4
    assert coincidence(4, 4) == 1.0


def test_correlate_covers_every_pair() -> None:
    cur_c = [(0.0, 0.0), (5.0, 5.0)]
    cur_b = [[0, 0, 0, 0], [10, 10, 10, 10]]
    prev_c = [(0.0, 0.0), (5.0, 5.0), (9.0, 9.0)]
    prev_b = [[0, 0, 0, 0], [10, 10, 10, 10], [18, 18, 18, 18]]
    corr = correlate(cur_c, cur_b, prev_c, prev_b, cell=CELL)
    assert corr.varsigma.shape == (2, 3)
    assert corr.varsigma[0, 0] == corr.varsigma[1, 1] == 1.0
    best = best_match(corr)  # Eq. 14
    assert best.index.tolist() == [0, 1]
    assert best.varsigma_max.tolist() == [1.0, 1.0]
    assert best.xi.tolist() == [1.0, 1.0]
    assert best.delta.tolist() == [0.0, 0.0]


def test_best_match_with_no_previous_chain_is_new() -> None:
    corr = correlate([(1.0, 1.0)], [[2, 2, 2, 2]], np.zeros((0, 2)), np.zeros((0, 4)), cell=CELL)
    best = best_match(corr)
    assert best.index.tolist() == [-1]
    assert best.varsigma_max.tolist() == [0.0]
    assert math.isinf(best.delta[0])
    assert classify(best.varsigma_max[0], best.delta[0], best.xi[0]) == "new"


def test_best_match_takes_the_maximum_over_the_previous_chain() -> None:
    # Eq. 14 by hand: previous obstacles 0.5 m (1 cell, disjoint) and 1.5 m (3 cells,
    # same box) away: 0.5/2 + 0.25 = 0.5 against 0.5/4 + 0.5 = 0.625 -> the second.
    corr = correlate(
        [(0.0, 0.0)],
        [[0, 1, 0, 1]],
        [(0.5, 0.0), (0.0, 1.5)],
        [[5, 5, 5, 5], [0, 1, 0, 1]],
        cell=CELL,
    )
    np.testing.assert_allclose(corr.varsigma[0], [0.5, 0.625])
    best = best_match(corr)
    assert best.index[0] == 1
    assert best.varsigma_max[0] == pytest.approx(0.625)
    assert best.delta[0] == pytest.approx(3.0)
    assert best.xi[0] == 1.0


# --- decision tree -----------------------------------------------------------------------


@pytest.mark.parametrize(
    ("varsigma", "delta", "xi", "kind"),
    [
        (0.29, 9.0, 0.0, "new"),  # varsigma_max < 0.30
        (0.71, 5.0, 0.0, "static"),  # varsigma_max > 0.70
        (0.50, 0.39, 0.0, "static"),  # middle band, delta < 0.4 cells
        (0.50, 0.40, 0.49, "dynamic"),  # middle band, delta >= 0.4, xi < 0.5
        (0.50, 2.00, 0.50, "static"),  # middle band, delta >= 0.4, xi >= 0.5
        (0.30, 1.00, 0.00, "dynamic"),  # 0.30 is inside the band (closed interval)
        (0.70, 1.00, 0.00, "dynamic"),  # and so is 0.70
    ],
)
def test_decision_tree_branches(varsigma: float, delta: float, xi: float, kind: str) -> None:
    assert classify(varsigma, delta, xi) == kind


def test_decision_tree_thresholds_are_parameters() -> None:
    assert classify(0.5, 1.0, 0.6, theta_xi=0.7) == "dynamic"
    assert classify(0.5, 1.0, 0.0, theta_delta=1.5) == "static"
    assert classify(0.5, 1.0, 0.0, theta_varsigma1=0.6) == "new"
    assert classify(0.5, 1.0, 0.0, theta_varsigma2=0.4) == "static"


# --- Eq. 15 ---------------------------------------------------------------------------


def test_eq15_motion_by_hand() -> None:
    # (3, 4) m in 2 s: d_o = 5 m, v_o = 2.5 m/s, alpha_o = atan(3/4) = 36.8699 deg from +y,
    # heading = atan2(4, 3) = 53.1301 deg from +x.
    m = motion((4.0, 6.0), (1.0, 2.0), 2.0)
    assert m.d_o == pytest.approx(5.0)
    assert m.v_o == pytest.approx(2.5)
    assert m.alpha_o_deg == pytest.approx(36.869898, abs=1e-6)
    assert math.degrees(m.heading) == pytest.approx(53.130102, abs=1e-6)
    assert m.vx == pytest.approx(1.5)
    assert m.vy == pytest.approx(2.0)


@pytest.mark.parametrize(
    ("dx", "dy", "alpha"),
    [(0.0, 1.0, 0.0), (1.0, 0.0, 90.0), (0.0, -1.0, 180.0), (-1.0, 0.0, 270.0)],
)
def test_eq15_alpha_o_is_clockwise_from_plus_y(dx: float, dy: float, alpha: float) -> None:
    m = motion((dx, dy), (0.0, 0.0), 0.1)
    assert m.alpha_o_deg == pytest.approx(alpha)
    assert alpha_o_from_heading(m.heading) == pytest.approx(alpha)


def test_eq15_period_must_be_positive() -> None:
    with pytest.raises(ValueError, match="period"):
        motion((1.0, 0.0), (0.0, 0.0), 0.0)


def test_wrap_degrees_stays_below_360() -> None:
    assert wrap_degrees(-1e-17) == 0.0
    assert wrap_degrees(-90.0) == 270.0
    assert wrap_degrees(360.0) == 0.0


# --- properties ------------------------------------------------------------------------

boxes = st.tuples(
    st.integers(-20, 20), st.integers(0, 6), st.integers(-20, 20), st.integers(0, 6)
).map(lambda t: [t[0], t[0] + t[1], t[2], t[2] + t[3]])
points = st.tuples(st.floats(-50, 50), st.floats(-50, 50))


@settings(max_examples=300, deadline=None)
@given(cur=st.lists(st.tuples(points, boxes), min_size=1, max_size=5),
       prev=st.lists(st.tuples(points, boxes), min_size=1, max_size=5))  # fmt: skip
def test_varsigma_in_0_1_and_xi_in_0_1(cur: list[Any], prev: list[Any]) -> None:
    corr = correlate(
        [c for c, _ in cur], [b for _, b in cur], [c for c, _ in prev], [b for _, b in prev],
        cell=CELL,
    )  # fmt: skip
    assert np.all(corr.varsigma > 0.0)
    assert np.all(corr.varsigma <= 1.0)
    assert np.all(corr.xi >= 0.0)
    assert np.all(corr.xi <= 1.0)
    assert np.all((corr.eta >= 0.0) & (corr.eta <= 1.0))
    assert np.all(corr.inter <= corr.union)


@settings(max_examples=300, deadline=None)
@given(a=boxes, b=boxes)
def test_overlap_matches_the_sorted_bounds_of_eq9(a: list[int], b: list[int]) -> None:
    assert overlap_cells(a, b) == sorted_overlap(a, b)
    assert overlap_cells(a, b) == overlap_cells(b, a)


@settings(max_examples=200, deadline=None)
@given(
    delta=st.floats(0, 1e6),
    eta=st.floats(0, 1),
    y_delta=st.floats(0.01, 1),
)
def test_varsigma_range_for_weights_summing_to_one(
    delta: float, eta: float, y_delta: float
) -> None:
    v = float(spatial_correlation(delta, eta, y_delta, 1.0 - y_delta))
    assert 0.0 < v <= 1.0
