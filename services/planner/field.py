"""Shortest ways on an 8-connected grid: the distance to the goal around the standing
obstacles seen so far, and the grid search the global path uses (pure, no I/O).

Beyond the paper. Morphin's Delta L term measures how far a candidate's end is from the
target. Measured in a straight line, it favours ends that lie close to the goal behind
a wall, and the robot swings from one side of an obstacle to the other. Measured
around the obstacles, as the length of the shortest way on a grid (8-connected, the
standing obstacles inflated by the robot radius and margin, unseen space taken as
free), every candidate end is judged by the way on from it, and successive choices
lead consistently toward the goal.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy.sparse import coo_matrix, csr_matrix
from scipy.sparse.csgraph import dijkstra

from zenav.services.planner.prediction import gap_to_boxes

Vec = npt.NDArray[np.float64]

_STEPS = ((1, 0, 1.0), (0, 1, 1.0), (1, 1, math.sqrt(2)), (1, -1, math.sqrt(2)))


@dataclass(frozen=True)
class DistanceField:
    origin: Vec  # centre of cell (0, 0), m
    resolution: float  # m
    distance: npt.NDArray[np.float64]  # (nx, ny) m to the goal; inf where blocked/cut off

    def at(self, point: Vec) -> float:
        """Distance (m) from ``point`` to the goal around obstacles; inf if none known."""
        i, j = np.rint((point - self.origin) / self.resolution).astype(int)
        nx, ny = self.distance.shape
        if not (0 <= i < nx and 0 <= j < ny):
            return math.inf
        return float(self.distance[i, j]) + 0.0


def grid_graph(free: npt.NDArray[np.bool_], resolution: float,
               cost: npt.NDArray[np.float64] | None = None) -> csr_matrix:
    """The 8-connected graph of the free cells of a (nx, ny) grid, edge weights in m
    (1 or sqrt 2 cells, times 1 + the mean ``cost`` of the two cells when given);
    node ``i * ny + j`` is cell (i, j)."""
    nx, ny = free.shape
    index = np.arange(nx * ny).reshape(nx, ny)
    rows, cols, weights = [], [], []
    for di, dj, w in _STEPS:
        a = index[max(0, -di): nx - max(0, di), max(0, -dj): ny - max(0, dj)]
        b = index[max(0, di): nx - max(0, -di) or None, max(0, dj): ny - max(0, -dj) or None]
        fa = free[max(0, -di): nx - max(0, di), max(0, -dj): ny - max(0, dj)]
        fb = free[max(0, di): nx - max(0, -di) or None, max(0, dj): ny - max(0, -dj) or None]
        ok = fa & fb
        rows.append(a[ok])
        cols.append(b[ok])
        if cost is None:
            weights.append(np.full(int(ok.sum()), w * resolution))
        else:
            flat = cost.ravel()
            weights.append(w * resolution * (1.0 + (flat[a[ok]] + flat[b[ok]]) / 2.0))
    r = np.concatenate(rows)
    c = np.concatenate(cols)
    return coo_matrix((np.concatenate(weights), (r, c)), shape=(nx * ny, nx * ny)).tocsr()


def grid_distances(
    free: npt.NDArray[np.bool_], source: tuple[int, int], resolution: float,
    cost: npt.NDArray[np.float64] | None = None,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int32]]:
    """Shortest-way distance (m) from cell ``source`` to every cell of the grid over its
    free cells (inf where cut off), and each cell's predecessor toward the source
    (-9999 where none), both (nx, ny)."""
    nx, ny = free.shape
    graph = grid_graph(free, resolution, cost)
    dist, pred = dijkstra(graph, directed=False, indices=source[0] * ny + source[1],
                          return_predecessors=True)
    return (np.asarray(dist, dtype=np.float64).reshape(nx, ny),
            np.asarray(pred, dtype=np.int32).reshape(nx, ny))


def distance_field(
    goal: Vec,
    lows: Vec,
    highs: Vec,
    corner_min: Vec,
    corner_max: Vec,
    resolution: float,
    clearance: float,
) -> DistanceField:
    """Shortest-way distances to ``goal`` over the rectangle [corner_min, corner_max],
    around boxes (lows, highs) inflated by ``clearance``."""
    nx = max(2, math.ceil((corner_max[0] - corner_min[0]) / resolution) + 1)
    ny = max(2, math.ceil((corner_max[1] - corner_min[1]) / resolution) + 1)
    xs = corner_min[0] + resolution * np.arange(nx)
    ys = corner_min[1] + resolution * np.arange(ny)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    centres = np.column_stack([gx.ravel(), gy.ravel()])
    free = gap_to_boxes(centres, lows, highs) >= clearance
    origin = np.array([xs[0], ys[0]])
    goal_cell = np.rint((goal - origin) / resolution).astype(int)
    goal_cell = np.clip(goal_cell, 0, [nx - 1, ny - 1])
    start = int(goal_cell[0] * ny + goal_cell[1])
    if not free[start]:  # the goal cell is inside an inflated obstacle: nearest free one
        candidates = np.flatnonzero(free)
        if len(candidates) == 0:
            return DistanceField(origin, resolution, np.full((nx, ny), math.inf))
        start = int(candidates[np.argmin(np.hypot(*(centres[candidates] - goal).T))])
    dist, _ = grid_distances(free.reshape(nx, ny), (start // ny, start % ny), resolution)
    return DistanceField(origin, resolution, dist)
