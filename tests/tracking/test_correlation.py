"""Eqs. 7-15 and the decision tree against hand-worked numbers, and their invariants; the
compiled Eq. 14 over two chains against the numpy formulation it replaced, to the bit."""

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
    motion,
    non_overlap_rate,
    overlap_cells,
    spatial_correlation,
    union_cells,
)

CELL = 0.5


def sorted_overlap(a: tuple[int, ...], b: tuple[int, ...]) -> int:
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
    cur, prev = (2, 4, 1, 3), (3, 6, 2, 5)
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
    best = best_match([(1.0, 1.0)], [cur], [(1.6, 1.8)], [prev], cell=CELL)
    assert best.index == [0]
    assert best.xi[0] == pytest.approx(4 / 9)
    assert best.delta[0] == pytest.approx(2.0)
    assert best.varsigma_max[0] == pytest.approx(0.442982, abs=1e-6)


def test_identical_areas_give_varsigma_one_and_eta_zero() -> None:
    # The paper's case: same place, same box -> delta = 0, eta = 0, varsigma = 1 (Eq. 7).
    box = (3, 5, -2, 0)
    assert overlap_cells(box, box) == union_cells(9, 9, 9) == 9
    assert non_overlap_rate(9, 9) == 0.0
    best = best_match([(1.7, -0.4)], [box], [(1.7, -0.4)], [box], cell=CELL)
    assert best.delta == [0.0]
    assert best.xi == [1.0]
    assert best.varsigma_max == [1.0]


@pytest.mark.parametrize(
    "prev",
    [
        (0, 1, 0, 1),  # x_max(t-1) < x_min(t)
        (6, 7, 2, 3),  # x_min(t-1) > x_max(t)
        (2, 4, -3, 0),  # y_max(t-1) < y_min(t)
        (2, 4, 4, 9),  # y_min(t-1) > y_max(t)
    ],
)
def test_isolated_areas_give_eta_one(prev: tuple[int, int, int, int]) -> None:
    cur = (2, 4, 1, 3)
    inter = overlap_cells(cur, prev)  # Eq. 8: no overlap
    assert inter == 0
    union = union_cells(9, int(np.prod([prev[1] - prev[0] + 1, prev[3] - prev[2] + 1])), inter)
    assert non_overlap_rate(inter, union) == 1.0
    assert coincidence(inter, 9) == 0.0
    # varsigma falls to y_eta / 2 + y_delta / (delta + 1)
    assert spatial_correlation(3.0, 1.0) == pytest.approx(0.5 / 4 + 0.25)


def test_boxes_sharing_one_column_overlap_by_inclusive_counting() -> None:
    # x 2..4 and 4..7 share column 4: x_b3 - x_b2 + 1 = 1, not 0.
    assert overlap_cells((2, 4, 0, 0), (4, 7, 0, 0)) == 1
    assert overlap_cells((2, 4, 0, 2), (4, 7, 1, 5)) == 2


def test_full_overlap_of_a_box_inside_another() -> None:
    # Eq. 7 from the small box's side: the overlap is all of it.
    assert overlap_cells((3, 4, 3, 4), (0, 9, 0, 9)) == 4
    assert coincidence(4, 4) == 1.0


def test_best_match_covers_every_pair() -> None:
    cur_c = [(0.0, 0.0), (5.0, 5.0)]
    cur_b = [(0, 0, 0, 0), (10, 10, 10, 10)]
    prev_c = [(0.0, 0.0), (5.0, 5.0), (9.0, 9.0)]
    prev_b = [(0, 0, 0, 0), (10, 10, 10, 10), (18, 18, 18, 18)]
    best = best_match(cur_c, cur_b, prev_c, prev_b, cell=CELL)  # Eq. 14
    assert best.index == [0, 1]
    assert best.varsigma_max == [1.0, 1.0]
    assert best.xi == [1.0, 1.0]
    assert best.delta == [0.0, 0.0]
    # the previous chain in the other order: each still finds its own
    best = best_match(cur_c, cur_b, prev_c[::-1], prev_b[::-1], cell=CELL)
    assert best.index == [2, 1]


def test_best_match_with_no_previous_chain_is_new() -> None:
    best = best_match([(1.0, 1.0)], [(2, 2, 2, 2)], [], [], cell=CELL)
    assert best.index == [-1]
    assert best.varsigma_max == [0.0]
    assert math.isinf(best.delta[0])
    assert classify(best.varsigma_max[0], best.delta[0], best.xi[0]) == "new"


def test_best_match_takes_the_first_of_equal_maxima() -> None:
    # two previous obstacles in the same place and box: the first one, as np.argmax
    best = best_match([(0.0, 0.0)], [(0, 1, 0, 1)], [(3.0, 0.0), (0.0, 0.0), (0.0, 0.0)],
                      [(6, 7, 0, 1), (0, 1, 0, 1), (0, 1, 0, 1)], cell=CELL)
    assert best.index == [1] and best.varsigma_max == [1.0]


def test_best_match_takes_the_maximum_over_the_previous_chain() -> None:
    # Eq. 14 by hand: previous obstacles 0.5 m (1 cell, disjoint) and 1.5 m (3 cells,
    # same box) away: 0.5/2 + 0.25 = 0.5 against 0.5/4 + 0.5 = 0.625 -> the second.
    assert spatial_correlation(1.0, 1.0) == 0.5
    assert spatial_correlation(3.0, 0.0) == 0.625
    best = best_match(
        [(0.0, 0.0)],
        [(0, 1, 0, 1)],
        [(0.5, 0.0), (0.0, 1.5)],
        [(5, 5, 5, 5), (0, 1, 0, 1)],
        cell=CELL,
    )
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

Box = tuple[int, int, int, int]
boxes = st.tuples(
    st.integers(-20, 20), st.integers(0, 6), st.integers(-20, 20), st.integers(0, 6)
).map(lambda t: (t[0], t[0] + t[1], t[2], t[2] + t[3]))
points = st.tuples(st.floats(-50, 50), st.floats(-50, 50))


def area(b: Box) -> int:
    return (b[1] - b[0] + 1) * (b[3] - b[2] + 1)


@settings(max_examples=300, deadline=None)
@given(a=boxes, b=boxes, ca=points, cb=points)
def test_xi_eta_and_varsigma_stay_in_their_ranges(a: Box, b: Box, ca: tuple[float, float],
                                                  cb: tuple[float, float]) -> None:
    inter = overlap_cells(a, b)
    union = union_cells(area(a), area(b), inter)
    assert 0 <= inter <= union
    assert 0.0 <= coincidence(inter, area(a)) <= 1.0
    eta = non_overlap_rate(inter, union)
    assert 0.0 <= eta <= 1.0
    v = spatial_correlation(centre_distance(ca, cb, CELL), eta)
    assert 0.0 < v <= 1.0


def numpy_best_match(cc: Any, bc: Any, cp: Any, bp: Any, cell: float, y_delta: float,
                     y_eta: float) -> tuple[list[float], list[int], list[float], list[float]]:
    """Eqs. 6-14 as the tracker computed them before they were compiled: numpy over every
    (current x previous) pair at once, then the first maximum per row."""
    bc = np.asarray(bc, dtype=np.int64).reshape(-1, 4)
    bp = np.asarray(bp, dtype=np.int64).reshape(-1, 4)
    cc = np.asarray(cc, dtype=np.float64).reshape(-1, 2)
    cp = np.asarray(cp, dtype=np.float64).reshape(-1, 2)
    area_c = ((bc[:, 1] - bc[:, 0] + 1) * (bc[:, 3] - bc[:, 2] + 1))[:, None]
    area_p = ((bp[:, 1] - bp[:, 0] + 1) * (bp[:, 3] - bp[:, 2] + 1))[None, :]
    a, b = bc[:, None, :], bp[None, :, :]
    extent = np.minimum(a[..., 1::2], b[..., 1::2]) - np.maximum(a[..., 0::2], b[..., 0::2]) + 1
    np.maximum(extent, 0, out=extent)
    inter = extent[..., 0] * extent[..., 1]
    union = area_c + area_p - inter
    xi = inter.astype(np.float64) / area_c.astype(np.float64)
    eta = 1.0 - inter.astype(np.float64) / union.astype(np.float64)
    d = cc[:, None, :] - cp[None, :, :]
    delta = np.hypot(d[..., 0], d[..., 1]) / cell
    varsigma = y_delta / (delta + 1.0) + y_eta / (eta + 1.0)
    n, m = varsigma.shape
    if m == 0:
        return [0.0] * n, [-1] * n, [math.inf] * n, [0.0] * n
    j = np.argmax(varsigma, axis=1)
    rows = np.arange(n)
    return (varsigma[rows, j].tolist(), j.tolist(), delta[rows, j].tolist(),
            xi[rows, j].tolist())


@settings(max_examples=300, deadline=None)
@given(cur=st.lists(st.tuples(points, boxes), min_size=1, max_size=6),
       prev=st.lists(st.tuples(points, boxes), min_size=0, max_size=6),
       y_delta=st.floats(0.01, 1.0), cell=st.sampled_from([0.1, 0.25, 0.5]),
       repeat=st.booleans())  # fmt: skip
def test_best_match_is_the_numpy_formulation_to_the_bit(
    cur: list[Any], prev: list[Any], y_delta: float, cell: float, repeat: bool
) -> None:
    if repeat and prev:
        prev = [cur[0], *prev, cur[0]]  # equal maxima: the first one wins in both
    args = ([c for c, _ in cur], [b for _, b in cur], [c for c, _ in prev],
            [b for _, b in prev])
    best = best_match(*args, cell=cell, y_delta=y_delta, y_eta=1.0 - y_delta)
    want = numpy_best_match(*args, cell, y_delta, 1.0 - y_delta)
    assert (best.varsigma_max, best.index, best.delta, best.xi) == want


@settings(max_examples=300, deadline=None)
@given(a=boxes, b=boxes)
def test_overlap_matches_the_sorted_bounds_of_eq9(a: Box, b: Box) -> None:
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
