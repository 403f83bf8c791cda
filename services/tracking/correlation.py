"""The paper's obstacle-recognition equations (Eqs. 7-15) and decision tree, as pure functions.

Grid boxes are inclusive ``(ix_min, ix_max, iy_min, iy_max)`` rows as produced by
:func:`zenav.services.perception.clustering.cluster_scan`; the functions broadcast over
leading dimensions, so ``box_cur[:, None, :]`` against ``box_prev[None, :, :]`` gives every
(current x previous) pair at once.

Decisions on points the paper leaves open
-----------------------------------------
* Units of delta (Eq. 13): grid CELLS, i.e. metres / r. The paper bounds delta by the window
  radius r_w, which it gives as 8 grids, and the areas it is combined with in Eq. 12 are
  counted in cells too; in cells theta_delta = 0.4 means "less than half a cell apart"
  (0.2 m), a natural reading of "the same place" on a 0.5 m grid, while in metres the
  1/(delta + 1) term would hardly change over the size of one cell.
* Which previous obstacle xi and delta refer to in the tree: the one that attains
  varsigma_max (Eq. 14), the best candidate for being the same obstacle.
* An empty previous chain gives varsigma_max = 0, so every obstacle is new.
* Heading alpha_o (Eq. 15): the paper writes arctan((x_t - x_{t-T}) / (y_t - y_{t-T})), with
  dx over dy, so its zero is the +y axis and +90 degrees is +x: a bearing measured clockwise
  from +y. It is kept that way (``alpha_o_deg``), with atan2 to get the full circle that a
  plain arctan folds onto 180 degrees, wrapped to [0, 360) like the paper's table (180.09).
  The rest of the stack uses ``heading`` = atan2(dy, dx), REP 103 (from +x, CCW);
  alpha_o_deg = (90 - degrees(heading)) mod 360.
* T in Eq. 15 is the difference of the two frames' stamps, not a constant scan period.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
import numpy.typing as npt

from zenav.services.geometry import wrap_degrees
from zenav.services.perception.clustering import box_area

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]
Kind = Literal["new", "static", "dynamic"]


def overlap_cells(box_a: npt.ArrayLike, box_b: npt.ArrayLike) -> IntArray:
    """Eqs. 7-9: number of grid cells shared by two inclusive boxes (0 when disjoint).

    Eq. 8: disjoint when one box's max is below the other's min on x or on y. Eq. 9: sorting
    the four x bounds x_b1 <= x_b2 <= x_b3 <= x_b4 of overlapping boxes, x_b2 is the larger of
    the two mins and x_b3 the smaller of the two maxes, so the overlap holds
    (x_b3 - x_b2 + 1) * (y_b3 - y_b2 + 1) cells (inclusive counting). A negative extent
    means disjoint and is clipped to 0, which covers Eq. 8. Eq. 7 (full overlap) is the case
    where both boxes are equal and the overlap is the whole area.
    """
    a = np.asarray(box_a, dtype=np.int64)
    b = np.asarray(box_b, dtype=np.int64)
    # Eq. 9, x_b3 - x_b2 + 1 and y_b3 - y_b2 + 1, both at once: the maxes are columns
    # 1 and 3 of a box, the mins 0 and 2
    extent = np.minimum(a[..., 1::2], b[..., 1::2]) - np.maximum(a[..., 0::2], b[..., 0::2]) + 1
    # Eq. 8: no overlap when either extent is empty
    np.maximum(extent, 0, out=extent)
    inter: IntArray = extent[..., 0] * extent[..., 1]
    return inter


def union_cells(area_a: npt.ArrayLike, area_b: npt.ArrayLike, inter: npt.ArrayLike) -> IntArray:
    """Eq. 10: cells covered by either box, S(t) + S(t-1) - S(t) n S(t-1)."""
    return (
        np.asarray(area_a, dtype=np.int64)
        + np.asarray(area_b, dtype=np.int64)
        - np.asarray(inter, dtype=np.int64)
    )


def coincidence(inter: npt.ArrayLike, area_cur: npt.ArrayLike) -> FloatArray:
    """Eq. 11: xi = (S(t) n S(t-1)) / S(t), in [0, 1]."""
    return np.asarray(inter, dtype=np.float64) / np.asarray(area_cur, dtype=np.float64)


def non_overlap_rate(inter: npt.ArrayLike, union: npt.ArrayLike) -> FloatArray:
    """Eq. 13: eta = 1 - (S1 n S2) / (S1 u S2): 0 for identical boxes, 1 for disjoint ones."""
    return 1.0 - np.asarray(inter, dtype=np.float64) / np.asarray(union, dtype=np.float64)


def centre_distance(centre_a: npt.ArrayLike, centre_b: npt.ArrayLike, cell: float) -> FloatArray:
    """Eq. 13: delta = ||Z_k1(t) - Z_k2(t-1)||, in grid cells (metres / cell)."""
    d = np.asarray(centre_a, dtype=np.float64) - np.asarray(centre_b, dtype=np.float64)
    return np.hypot(d[..., 0], d[..., 1]) / cell


def spatial_correlation(
    delta: npt.ArrayLike, eta: npt.ArrayLike, y_delta: float = 0.5, y_eta: float = 0.5
) -> FloatArray:
    """Eq. 12: varsigma = y_delta / (delta + 1) + y_eta / (eta + 1).

    With y_delta = y_eta = 0.5, delta >= 0 and eta in [0, 1], varsigma lies in (0.25, 1]:
    1 for the same place and box, 0.25 in the limit of far and disjoint.
    """
    return y_delta / (np.asarray(delta, dtype=np.float64) + 1.0) + y_eta / (
        np.asarray(eta, dtype=np.float64) + 1.0
    )


@dataclass(frozen=True, eq=False)
class Correlation:
    """Eqs. 9-13 for every (current k1, previous k2) pair; each array is (n_cur, n_prev)."""

    inter: IntArray
    union: IntArray
    xi: FloatArray
    eta: FloatArray
    delta: FloatArray
    varsigma: FloatArray


def correlate(
    centre_cur: npt.ArrayLike,
    box_cur: npt.ArrayLike,
    centre_prev: npt.ArrayLike,
    box_prev: npt.ArrayLike,
    *,
    cell: float,
    y_delta: float = 0.5,
    y_eta: float = 0.5,
) -> Correlation:
    """All pairwise overlaps, coincidences and spatial correlations between two chains.

    Args:
        centre_cur: (n, 2) Eq. 5 centres at t, metres.
        box_cur: (n, 4) grid boxes at t.
        centre_prev: (m, 2) Eq. 5 centres at t-1.
        box_prev: (m, 4) grid boxes at t-1.
        cell: grid resolution r, metres (delta is in cells).
        y_delta: weight of the distance term of Eq. 12.
        y_eta: weight of the overlap term of Eq. 12.
    """
    bc = np.asarray(box_cur, dtype=np.int64).reshape(-1, 4)
    bp = np.asarray(box_prev, dtype=np.int64).reshape(-1, 4)
    cc = np.asarray(centre_cur, dtype=np.float64).reshape(-1, 2)
    cp = np.asarray(centre_prev, dtype=np.float64).reshape(-1, 2)
    area_c = box_area(bc)[:, None]  # Eq. 6
    area_p = box_area(bp)[None, :]
    inter = overlap_cells(bc[:, None, :], bp[None, :, :])  # Eqs. 7-9
    union = union_cells(area_c, area_p, inter)  # Eq. 10
    xi = coincidence(inter, area_c)  # Eq. 11
    eta = non_overlap_rate(inter, union)  # Eq. 13
    delta = centre_distance(cc[:, None, :], cp[None, :, :], cell)  # Eq. 13, cells
    varsigma = spatial_correlation(delta, eta, y_delta, y_eta)  # Eq. 12
    return Correlation(inter=inter, union=union, xi=xi, eta=eta, delta=delta, varsigma=varsigma)


@dataclass(frozen=True, eq=False)
class BestMatch:
    """Eq. 14 per current obstacle, with the xi and delta of the maximising pair.

    ``index`` is the previous obstacle attaining varsigma_max, -1 when the previous chain is
    empty (then varsigma_max = 0, delta = inf, xi = 0).
    """

    varsigma_max: FloatArray
    index: IntArray
    delta: FloatArray
    xi: FloatArray


def best_match(corr: Correlation) -> BestMatch:
    """Eq. 14: varsigma_max over the previous chain (first maximum on ties)."""
    n, m = corr.varsigma.shape
    if m == 0:
        return BestMatch(
            varsigma_max=np.zeros(n),
            index=np.full(n, -1, dtype=np.int64),
            delta=np.full(n, np.inf),
            xi=np.zeros(n),
        )
    j = np.argmax(corr.varsigma, axis=1)
    rows = np.arange(n)
    return BestMatch(
        varsigma_max=corr.varsigma[rows, j],
        index=j.astype(np.int64),
        delta=corr.delta[rows, j],
        xi=corr.xi[rows, j],
    )


def classify(
    varsigma_max: float,
    delta: float,
    xi: float,
    *,
    theta_varsigma1: float = 0.30,
    theta_varsigma2: float = 0.70,
    theta_delta: float = 0.4,
    theta_xi: float = 0.5,
) -> Kind:
    """The paper's decision tree (Sec. 3.3): new, static or dynamic.

    varsigma_max < theta_varsigma1 -> new; > theta_varsigma2 -> static; in between (both ends
    included): delta < theta_delta (cells) -> static, else xi < theta_xi -> dynamic, else
    static.
    """
    if varsigma_max < theta_varsigma1:
        return "new"
    if varsigma_max > theta_varsigma2:
        return "static"
    if delta < theta_delta:
        return "static"
    if xi < theta_xi:
        return "dynamic"
    return "static"


@dataclass(frozen=True)
class Motion:
    """Eq. 15 between two positions of one obstacle.

    Attributes:
        v_o: speed, m/s.
        alpha_o_deg: the paper's direction angle, degrees in [0, 360), clockwise from +y.
        d_o: distance moved, metres.
        heading: direction of motion, radians from +x counter-clockwise (REP 103).
        vx: velocity along x, m/s.
        vy: velocity along y, m/s.
    """

    v_o: float
    alpha_o_deg: float
    d_o: float
    heading: float
    vx: float
    vy: float


def alpha_o_from_heading(heading: float) -> float:
    """The paper's alpha_o (degrees clockwise from +y, [0, 360)) of a REP 103 heading."""
    return wrap_degrees(90.0 - math.degrees(heading))


def motion(now: tuple[float, float], before: tuple[float, float], period: float) -> Motion:
    """Eq. 15: speed v_o = d_o / T, direction alpha_o and distance d_o from t-T to t.

    Args:
        now: (x_k(t), y_k(t)), metres.
        before: (x_k(t-T), y_k(t-T)), metres.
        period: T, seconds (> 0): the difference of the two frames' stamps.
    """
    if not period > 0.0:
        raise ValueError(f"period must be positive, got {period}")
    dx = now[0] - before[0]
    dy = now[1] - before[1]
    d_o = math.hypot(dx, dy)  # Eq. 15, d_o
    heading = math.atan2(dy, dx)
    # Eq. 15, alpha_o = arctan(dx / dy): from +y towards +x, full circle (the heading's).
    alpha_o = alpha_o_from_heading(heading)
    return Motion(
        v_o=d_o / period,  # Eq. 15, v_o
        alpha_o_deg=alpha_o,
        d_o=d_o,
        heading=heading,
        vx=dx / period,
        vy=dy / period,
    )
