"""The global path: the shortest way to the goal on the inflated occupancy grid, made
any-angle by line-of-sight shortcuts (pure, no I/O).

A grid search (Dijkstra on the 8-connected free cells, ``field.grid_distances``) from
the goal gives every cell's distance to go and the way there; the robot's cell is
followed down that way, and then, in the manner of Theta*, each vertex is joined to the
farthest later one it sees in a straight line through free cells, so the path bends only
where an obstacle makes it. Unknown cells count as free; the space beyond the grid does
not (there is no map of it: the path stays on the grid). With nothing known the path is
the straight line from the robot to the goal, exactly the paper's global path.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from zenav.services.planner._loops import (
    line_any,
    max_along,
    point_on,
    project_on,
    straight_on,
)
from zenav.services.planner.costmap import Costmap
from zenav.services.planner.field import grid_distances

Vec = npt.NDArray[np.float64]
BoolGrid = npt.NDArray[np.bool_]


@dataclass(frozen=True)
class GlobalPlan:
    points: Vec  # (n, 2) vertices from the robot to the goal; empty when no way exists
    length: float  # m along the vertices (inf when no way)
    reason: str  # why this plan was made

    @property
    def found(self) -> bool:
        return len(self.points) >= 2


def _nearest_free(free: BoolGrid, cell: tuple[int, int], radius: int,
                  lethal: BoolGrid | None = None) -> tuple[int, int] | None:
    """The free cell nearest ``cell`` within ``radius`` cells, or None. With ``lethal``
    (the occupied cells), only a free cell that ``cell`` sees in a straight line through
    no occupied cell counts: next to a thin wall the nearest free cell may lie on its
    far side, and the path joins it straight."""
    nx, ny = free.shape
    i0, j0 = cell
    lo_i, hi_i = max(0, i0 - radius), min(nx, i0 + radius + 1)
    lo_j, hi_j = max(0, j0 - radius), min(ny, j0 + radius + 1)
    window = free[lo_i:hi_i, lo_j:hi_j]
    if not window.any():
        return None
    ii, jj = np.nonzero(window)
    ii, jj = ii + lo_i, jj + lo_j
    d = (ii - i0) ** 2 + (jj - j0) ** 2
    for k in np.argsort(d, kind="stable"):
        there = (int(ii[k]), int(jj[k]))
        if lethal is None or not _crosses(lethal, cell, there):
            return there
    return None


def _crosses(grid: BoolGrid, a: tuple[int, int], b: tuple[int, int]) -> bool:
    """Whether the straight line between the centres of cells ``a`` and ``b`` passes
    through a True cell of ``grid`` (sampled every quarter cell), ``a`` itself aside."""
    steps = max(1, 4 * max(abs(b[0] - a[0]), abs(b[1] - a[1])))
    t = np.linspace(0.0, 1.0, steps + 1)[1:]
    i = np.floor(a[0] + 0.5 + t * (b[0] - a[0])).astype(np.int64)
    j = np.floor(a[1] + 0.5 + t * (b[1] - a[1])).astype(np.int64)
    return bool(grid[i, j].any())


def visible(free: BoolGrid, costmap: Costmap, a: Vec, b: Vec) -> bool:
    """Whether the straight segment a-b passes through free cells only (sampled every
    quarter cell; a point beyond the grid is not free: there is no map of it). In
    compiled code (``_loops.line_any`` over the points ``a + t (b - a)``, ``t`` the points
    of ``np.linspace(0, 1, count)``), stopping at the first point that is not free."""
    length = float(np.hypot(*(b - a)))
    count = max(2, math.ceil(length / (costmap.resolution / 4)) + 1)
    (ax, ay), (dx, dy) = a.tolist(), (b - a).tolist()
    walls = np.ascontiguousarray(~free).reshape(-1).view(np.uint8)
    return not line_any(ax, ay, dx, dy, 1.0, count, float(costmap.origin[0]),
                        float(costmap.origin[1]), costmap.resolution, walls, free.shape[1],
                        True)


def _cost_along(cost: npt.NDArray[np.float64], costmap: Costmap, points: Vec) -> float:
    """The highest comfort cost over a polyline's cells (sampled every quarter cell, leg
    by leg, in compiled code: ``_loops.max_along``; cells beyond the grid skipped)."""
    flat = np.ascontiguousarray(cost).reshape(-1)
    ox, oy = float(costmap.origin[0]), float(costmap.origin[1])
    worst = 0.0
    for a, b in itertools.pairwise(points):
        count = max(2, math.ceil(float(np.hypot(*(b - a))) / (costmap.resolution / 4)) + 1)
        (ax, ay), (dx, dy) = a.tolist(), (b - a).tolist()
        worst = max(worst, max_along(ax, ay, dx, dy, count, ox, oy, costmap.resolution, flat,
                                     cost.shape[1]))
    return worst


def shortcut(free: BoolGrid, costmap: Costmap, points: Vec,
             cost: npt.NDArray[np.float64] | None = None) -> Vec:
    """Line-of-sight shortcutting: from each kept vertex, the farthest later vertex it
    sees in a straight line is the next one kept. With ``cost`` (the comfort cost of
    each cell), a shortcut may not come nearer the obstacles than the grid path it
    replaces did: it cuts corners of the way, not into the room kept round obstacles."""
    if len(points) <= 2:
        return points
    # Each leg's cost once: the cost along the vertices i..j is the highest of their
    # legs' (``_cost_along`` over them, leg by leg, from 0), asked for again and again.
    legs = ([] if cost is None else
            [_cost_along(cost, costmap, points[k:k + 2]) for k in range(len(points) - 1)])

    def ok(i: int, j: int) -> bool:
        if not visible(free, costmap, points[i], points[j]):
            return False
        if cost is None:
            return True
        return _cost_along(cost, costmap, points[[i, j]]) <= max(0.0, *legs[i:j]) + 1e-9

    kept = [0]
    i = 0
    last = len(points) - 1
    while i < last:
        j = last
        while j > i + 1 and not ok(i, j):
            # Binary-search-like back-off keeps long open stretches cheap.
            j = i + 1 + (j - i - 1) // 2 if j - i > 8 else j - 1
        # Then move forward as far as still allowed (the back-off may have overshot).
        while j < last and ok(i, j + 1):
            j += 1
        kept.append(j)
        i = j
    return points[kept]


COMFORT = 0.5
"""m beyond the inflation over which a cell costs more the nearer it is to an obstacle
(like the decaying cost of Nav2's inflation layer): the path keeps to the middle of a
passage where it can, instead of grazing the inflation's edge."""
COMFORT_WEIGHT = 2.0
"""Extra cost per metre in a cell right at the inflation's edge (falling to 0 at
``COMFORT`` beyond it)."""


def plan_path(costmap: Costmap, start: Vec, goal: Vec, reason: str = "") -> GlobalPlan:
    """The any-angle shortest way from ``start`` to ``goal`` round the blocked cells.

    A start or goal inside a blocked (inflated) cell but not on an occupied one is joined
    to the nearest free cell within the inflation distance (twice that for the start)
    that it sees past every occupied cell: the robot may stand closer to an obstacle
    than the margin, and a goal may lie near a wall. A goal on an
    occupied cell, or one cut off, has no way (``found`` is False)."""
    costmap.grow_to(np.vstack([start, goal]), costmap.padding / 2)
    ends = costmap.cell_of(np.vstack([start, goal]))
    if not costmap.inside(ends).all():  # the grid at its largest cannot hold them
        return GlobalPlan(np.empty((0, 2)), math.inf, "start or goal beyond the map")
    free = ~costmap.blocked()
    ny = free.shape[1]
    si, sj = (int(v) for v in ends[0])
    gi, gj = (int(v) for v in ends[1])
    s_cell, g_cell = (si, sj), (gi, gj)
    if costmap.lethal_at(goal[None, :])[0]:
        return GlobalPlan(np.empty((0, 2)), math.inf, "goal occupied")
    reach = max(1, math.ceil(costmap.inflation / costmap.resolution) + 1)
    lethal = costmap.lethal_grid()
    g_free = g_cell if free[g_cell] else _nearest_free(free, g_cell, reach, lethal)
    s_free = s_cell if free[s_cell] else _nearest_free(free, s_cell, 2 * reach, lethal)
    if g_free is None or s_free is None:
        return GlobalPlan(np.empty((0, 2)), math.inf, "no free cell at start or goal")
    if free.all() or (visible(free, costmap, start, goal) and s_free == s_cell
                      and g_free == g_cell):
        length = float(np.hypot(*(goal - start)))
        return GlobalPlan(np.vstack([start, goal]), length, reason)
    room = costmap.gap() - costmap.inflation
    cost = COMFORT_WEIGHT * np.clip((COMFORT - room) / COMFORT, 0.0, 1.0)
    dist, pred = grid_distances(free, g_free, costmap.resolution, cost)
    if not math.isfinite(dist[s_free]):
        return GlobalPlan(np.empty((0, 2)), math.inf, "no way to the goal")
    cells = [s_free]
    node = s_free[0] * ny + s_free[1]
    target = g_free[0] * ny + g_free[1]
    while node != target:
        node = int(pred[node // ny, node % ny])
        if node < 0:  # cannot happen for a finite distance; never loop on bad input
            return GlobalPlan(np.empty((0, 2)), math.inf, "no way to the goal")
        cells.append((node // ny, node % ny))
    centres = costmap.centre_of(np.array(cells, dtype=np.int64))
    points = np.vstack([start, centres[1:-1] if len(centres) > 2 else np.empty((0, 2)), goal])
    points = shortcut(free, costmap, points, cost)
    length = float(np.hypot(*np.diff(points, axis=0).T).sum())
    return GlobalPlan(points, length, reason)


SETTLE_BEARINGS = 36
"""Points looked at on each ring round the goal by ``settle_point`` (every 10 degrees)."""


def goal_clear(costmap: Costmap, goal: Vec, clearance: float) -> bool:
    """Whether every occupied cell's square lies at least ``clearance`` from ``goal`` (any
    point): ``settle_point``'s answer is then the goal itself, whatever its reach. Only
    the cells whose squares meet the box ``goal`` +- (``clearance`` + a cell) can be
    nearer, and only those are looked at (``Costmap.squares_clear``)."""
    return costmap.squares_clear((float(goal[0]), float(goal[1])),
                                 clearance + costmap.resolution, clearance)


def settle_point(costmap: Costmap, goal: Vec, toward: Vec, clearance: float,
                 reach: float) -> Vec:
    """Where to stop for a goal the robot cannot stand on comfortably: the goal itself
    when every occupied cell of the map lies farther than ``clearance`` from it (a disc
    of the robot's radius plus a margin there touches nothing: ``goal_clear``); else, on
    the nearest of the rings round the goal (half a cell apart, out to ``reach``) that has
    such a point, the one nearest ``toward`` (the robot); the goal when no ring within
    ``reach`` has one. A goal beside a wall is reached from the free side, within the
    run's tolerance, instead of being driven at until the local layer turns away from
    the wall.

    Distances are to the occupied cells' squares (the map holds a return somewhere in
    its cell, so the square is the nearest the obstacle can be); the space beyond the
    grid holds nothing known."""
    goal = np.asarray(goal, dtype=np.float64)
    if goal_clear(costmap, goal, clearance):
        return goal
    angles = np.linspace(0.0, 2.0 * math.pi, SETTLE_BEARINGS, endpoint=False)
    ring = np.column_stack([np.cos(angles), np.sin(angles)])
    step = costmap.resolution / 2
    for k in range(1, int(reach / step + 1e-9) + 1):
        points = goal + (k * step) * ring
        ok = np.array([goal_clear(costmap, point, clearance) for point in points])
        if ok.any():
            found = points[ok]
            return np.asarray(found[int(np.argmin(np.hypot(*(found - toward).T)))])
    return goal


# -- following a path -------------------------------------------------------------------


def arc_lengths(points: Vec) -> Vec:
    """Cumulative length at each vertex, from 0."""
    d = points[1:] - points[:-1]
    out = np.zeros(len(d) + 1)
    np.cumsum(np.hypot(d[:, 0], d[:, 1]), out=out[1:])
    return out


def project(points: Vec, p: Vec, lengths: Vec | None = None) -> tuple[float, float]:
    """(s, d): arc length of the point of the path nearest ``p``, and the distance; in
    compiled code (``_loops.project_on``), segment by segment. ``lengths``: the path's
    ``arc_lengths``, when the caller keeps them."""
    s = arc_lengths(points) if lengths is None else lengths
    return project_on(np.ascontiguousarray(points, dtype=np.float64), s, float(p[0]),
                      float(p[1]))


def straight_ahead(points: Vec, p: Vec, direction: Vec, lengths: Vec) -> float:
    """How far the path runs on from ``p`` in ``direction`` (unit) before it bends: the
    distance to the last vertex ahead of ``p``'s projection whose leg from ``p`` keeps
    within about 2.6 degrees of the direction (cosine 0.999), 0 when the first one does
    not; in compiled code (``_loops.straight_on``). ``lengths``: the path's
    ``arc_lengths``."""
    s0 = project(points, p, lengths)[0]
    return straight_on(np.ascontiguousarray(points, dtype=np.float64), lengths, s0,
                       float(p[0]), float(p[1]), float(direction[0]), float(direction[1]))


def point_at(points: Vec, s: float, lengths: Vec | None = None) -> Vec:
    """The point of the path at arc length ``s`` (clamped to its ends); ``lengths`` as
    for :func:`project`; in compiled code (``_loops.point_on``)."""
    if lengths is None:
        lengths = arc_lengths(points)
    return np.array(point_on(np.ascontiguousarray(points, dtype=np.float64), lengths,
                             float(s)), dtype=np.float64)


def first_blocked(costmap: Costmap, points: Vec, from_s: float, step: float,
                  lengths: Vec | None = None) -> float | None:
    """Arc length of the first point of the path, at or beyond ``from_s``, that lies in
    a blocked cell or beyond the grid; None if the rest of the path is free. ``lengths``
    as for :func:`project`."""
    if lengths is None:
        lengths = arc_lengths(points)
    total = float(lengths[-1])
    if from_s >= total:
        return None
    s = np.arange(from_s, total + step / 2, step)
    first = costmap.first_blocked_on(points, lengths, s)
    return float(s[first]) if first >= 0 else None
