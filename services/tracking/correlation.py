"""The paper's obstacle-recognition equations (Eqs. 7-15) and decision tree, as pure functions.

Grid boxes are inclusive ``(ix_min, ix_max, iy_min, iy_max)`` tuples, the rows produced by
:func:`zenav.services.perception.clustering.cluster_scan`. Eqs. 7-14 are compiled
(``_loops.pyx``), one function per equation for one pair; :func:`best_match` runs them over
every (current x previous) pair of two chains.

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
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

from zenav.services.geometry import wrap_degrees
from zenav.services.perception.clustering import box_area
from zenav.services.tracking import _loops

Box = tuple[int, int, int, int]
Kind = Literal["new", "static", "dynamic"]


# Eqs. 7-14 are compiled (``_loops.pyx``): one function per equation, and
# ``best_match``, which runs them over every (current, previous) pair of two chains. The
# tracker calls ``best_match``; the equation tests pin each of these functions.
overlap_cells = _loops.overlap_cells  # Eqs. 7-9
union_cells = _loops.union_cells  # Eq. 10
coincidence = _loops.coincidence  # Eq. 11
non_overlap_rate = _loops.non_overlap_rate  # Eq. 13, eta
centre_distance = _loops.centre_distance  # Eq. 13, delta (cells)
spatial_correlation = _loops.spatial_correlation  # Eq. 12


@dataclass(frozen=True, eq=False, slots=True)
class BestMatch:
    """Eq. 14 per current obstacle, with the xi and delta of the maximising pair.

    ``index`` is the previous obstacle attaining varsigma_max, -1 when the previous chain is
    empty (then varsigma_max = 0, delta = inf, xi = 0).
    """

    varsigma_max: list[float]
    index: list[int]
    delta: list[float]
    xi: list[float]


def best_match(
    centre_cur: Sequence[tuple[float, float]],
    box_cur: Sequence[Box],
    centre_prev: Sequence[tuple[float, float]],
    box_prev: Sequence[Box],
    *,
    cell: float,
    y_delta: float = 0.5,
    y_eta: float = 0.5,
) -> BestMatch:
    """Eq. 14: varsigma_max of each current obstacle over the previous chain (the first
    maximum on ties), from Eqs. 6 and 9-13 for every (current, previous) pair.

    Args:
        centre_cur: n Eq. 5 centres at t, metres.
        box_cur: n grid boxes at t.
        centre_prev: m Eq. 5 centres at t-1.
        box_prev: m grid boxes at t-1.
        cell: grid resolution r, metres (delta is in cells).
        y_delta: weight of the distance term of Eq. 12.
        y_eta: weight of the overlap term of Eq. 12.
    """
    v, j, delta, xi = _loops.best_match(
        list(centre_cur), list(box_cur), [box_area(b) for b in box_cur],  # Eq. 6
        list(centre_prev), list(box_prev), [box_area(b) for b in box_prev],
        cell, y_delta, y_eta,
    )  # fmt: skip
    return BestMatch(varsigma_max=v, index=j, delta=delta, xi=xi)


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
