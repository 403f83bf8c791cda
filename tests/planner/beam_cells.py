"""The cells a scan's beams pass through, worked out as geometry (for the map's tests).

Each beam clears the segment from the robot to its reach: half a cell short of its
return, or the laser's range without one (``Costmap.update``). A cell's square is
``origin + [i, i + 1) x [j, j + 1)`` cells. Which squares a segment meets is found
here by clipping it to each square (the slab test), not by walking the grid as the
compiled update does, and twice: against the squares shrunk by ``eps``, the cells the
segment surely crosses, and grown by ``eps``, the cells it may only touch at an edge
or a corner. The map must clear every cell of the first set and none beyond the second.
"""

from __future__ import annotations

import math

import numpy as np

from zenav.services.perception.clustering import to_global
from zenav.services.planner.costmap import Costmap, ScanData

Cells = set[tuple[int, int]]

_NEIGHBOURS = np.array([(di, dj) for di in (-1, 0, 1) for dj in (-1, 0, 1)])


def beam_reach(costmap: Costmap, scan: ScanData) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each beam's unit direction (x and y, Eq. 1) and its reach, m (nan: no segment)."""
    ranges = np.asarray(scan.ranges, dtype=np.float64)
    alpha = scan.angle_min + scan.angle_increment * np.arange(ranges.size)
    ux, uy = to_global((0.0, 0.0, scan.pose[2]), np.ones_like(ranges), alpha)
    hit = (ranges < scan.range_max) & (ranges >= scan.range_min)
    with np.errstate(invalid="ignore"):
        reach = np.minimum(np.where(hit, ranges - costmap.resolution / 2, ranges),
                           scan.range_max)
        reach[~(reach >= 0.0)] = np.nan
    return np.asarray(ux), np.asarray(uy), reach


def _meets(p0: np.ndarray, p1: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Row by row, whether the segment p0 -> p1 meets the closed box [lo, hi] (slabs)."""
    d = p1 - p0
    t_min = np.zeros(len(p0))
    t_max = np.ones(len(p0))
    for axis in (0, 1):
        along = d[:, axis] != 0.0
        with np.errstate(divide="ignore", invalid="ignore"):
            ta = (lo[:, axis] - p0[:, axis]) / d[:, axis]
            tb = (hi[:, axis] - p0[:, axis]) / d[:, axis]
        t_min = np.where(along, np.maximum(t_min, np.minimum(ta, tb)), t_min)
        t_max = np.where(along, np.minimum(t_max, np.maximum(ta, tb)), t_max)
        inside = (p0[:, axis] >= lo[:, axis]) & (p0[:, axis] <= hi[:, axis])
        t_max = np.where(along | inside, t_max, -1.0)
    return t_min <= t_max


def beam_cells(costmap: Costmap, scan: ScanData, eps: float = 1e-9) -> tuple[Cells, Cells]:
    """(surely crossed, at most touched): the grid's cells the beams' segments meet,
    inside the squares shrunk by ``eps`` and grown by it."""
    ux, uy, reach = beam_reach(costmap, scan)
    x, y = scan.pose[0], scan.pose[1]
    r = costmap.resolution
    beams = np.flatnonzero(~np.isnan(reach))
    if not beams.size:
        return set(), set()
    # Candidates: the cells of points every half cell along each segment (and its
    # end), with their eight neighbours: every point of a segment is within a quarter
    # cell of one of those points, so in its cell or a neighbour of it.
    count = math.ceil(float(np.max(reach[beams])) / (r / 2)) + 2
    s = np.minimum(np.arange(count) * (r / 2), reach[beams][:, None])
    px = x + s * ux[beams][:, None]
    py = y + s * uy[beams][:, None]
    cells = costmap.cell_of(np.column_stack([px.ravel(), py.ravel()]))
    # (beam, i, j) as one whole number, for a fast unique: cells stay within a
    # million of the grid's origin (the scans of the tests reach 9 m)
    size = 1 << 21
    keys = np.unique((np.repeat(beams, count) * size + cells[:, 0] + size // 2) * size
                     + cells[:, 1] + size // 2)
    keys = np.unique((keys[:, None] + _NEIGHBOURS[None, :, 0] * size
                      + _NEIGHBOURS[None, :, 1]).ravel())
    pairs = np.column_stack([keys // size // size, keys // size % size - size // 2,
                             keys % size - size // 2])
    pairs = pairs[costmap.inside(pairs[:, 1:])]
    b = pairs[:, 0]
    p0 = np.column_stack([np.full(len(b), x), np.full(len(b), y)])
    p1 = np.column_stack([x + reach[b] * ux[b], y + reach[b] * uy[b]])
    lo = costmap.origin[None, :] + pairs[:, 1:] * r
    hi = lo + r
    out: list[Cells] = []
    for grow in (-eps, eps):
        met = pairs[_meets(p0, p1, lo - grow, hi + grow), 1:]
        out.append({(int(i), int(j)) for i, j in met})
    return out[0], out[1]
