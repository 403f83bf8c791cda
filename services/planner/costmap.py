"""A world-frame occupancy grid built from the scans, and its inflation (pure, no I/O).

Beyond the paper, in the manner of Nav2's obstacle and inflation layers:

- every beam clears the cells it passes through (ray tracing: each beam's cells walked
  one grid line at a time, up to half a cell short of its return or the laser's reach), but
  not a cell another return of the same scan falls in (marking wins, as in Nav2's
  obstacle layer);
- the cell of each return is marked occupied, unless the return falls inside the disc
  of a track typed dynamic (movers are the local layer's business, not the map's); it
  counts as an obstacle once it has stayed occupied for ``confirm`` seconds, so a mover
  beyond perception's window (no track, no type) leaves no wake of marks: its front moves
  on to new cells before they are confirmed, and the beams clear the cells it left;
- a cell keeps what it was last seen as for ``decay`` seconds, then is unknown again;
  except a wall of the memory (below) whose returns came for ``wall_confirm`` seconds
  or more: it stays an obstacle for ``wall_decay`` seconds since it was last seen, and
  recovery's clearing keeps it, unless a beam passes through it first (Nav2's obstacle
  layer keeps its marks until a beam clears them). With the short decay alone, the
  walls of a long corridor or a maze were forgotten behind the robot, and the path went
  back through them. A slow walker far down a corridor, beyond perception's window,
  left marks confirmed as walls that, kept, closed a sealed corridor ahead of the
  robot; their returns had not come for ``wall_confirm``, so they decay and are cleared;
- the planner treats unknown cells as free (optimistic, as Nav2's ``allow_unknown``), but
  not the space beyond the grid: the global path never leaves it (the grid holds start,
  goal, the robot and every return with half the padding to spare; only ``max_size``
  can leave one out);
- occupied cells are inflated by the robot radius plus a margin (each occupied cell's
  disc of cells stamped, or with many of them scipy.ndimage's Euclidean distance
  transform: the same cells), so a path through the free cells keeps the robot's disc
  clear of everything the map holds;
- the wall memory keeps every confirmed obstacle cell until a beam passes through it
  (no decay, no recovery clearing): the map's lethal cells include its long-seen walls
  (above), and ``cut_off`` asks all of it, with no time limit, whether the walls ever
  seen close the goal off from the robot.
  The decaying map alone cannot say so: at 0.1 m/s going round a ring of walls takes
  longer than ``decay``, so the side seen first is unknown (free) again by the time the
  last is seen, and a way "opens" there on every round.

The grid covers start and goal with padding at first and grows (by whole blocks) when
the robot or a return falls outside it, up to ``max_size`` metres a side.

Cells are indexed ``[ix, iy]``; cell (0, 0) spans [origin, origin + resolution) in x and y.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import TypeVar

import numpy as np
import numpy.typing as npt
from scipy.ndimage import distance_transform_edt

from zenav.services.perception.clustering import to_global
from zenav.services.planner._loops import (
    closed_off,
    first_flagged_on,
    lethal_cells,
    line_any,
    look_up,
    look_up_rows,
    return_bounds,
    returns_near,
    squares_clear,
    stamp_discs,
    trace_scan,
)

Vec = npt.NDArray[np.float64]
BoolGrid = npt.NDArray[np.bool_]

UNKNOWN, FREE, OCCUPIED = -1, 0, 100
"""Cell values in :meth:`Costmap.values` (those of ROS nav_msgs/OccupancyGrid)."""


@dataclass(frozen=True)
class ScanData:
    """One scan in the global frame's terms: the pose it was taken from and the beams."""

    pose: tuple[float, float, float]
    ranges: npt.NDArray[np.float64]  # m; range_max = no return
    angle_min: float  # rad, relative to the heading
    angle_increment: float  # rad
    range_max: float  # m
    range_min: float = 0.0

    @functools.cached_property
    def returns(self) -> npt.NDArray[np.float64]:
        """(n, 2) global points of the beams that returned (``range_min`` <= range <
        ``range_max``), by Eq. 1 (``to_global``); made once a scan, however many of the
        planner's checks read it."""
        beams = np.flatnonzero((self.ranges >= self.range_min)
                               & (self.ranges < self.range_max))
        x, y = to_global(self.pose, self.ranges[beams],
                         self.angle_min + self.angle_increment * beams)
        return np.column_stack((x, y))


G = TypeVar("G", bound=np.generic)


def _on_grid_steps(x: float, y: float, dx: float, dy: float, step: float, count: int,
                   origin: tuple[float, float], shape: tuple[int, int], resolution: float
                   ) -> tuple[int, int] | None:
    """The first and last of the points ``(x, y) + k * step * (dx, dy)``, k = 0 ..
    ``count`` - 1, that may lie on a grid of ``shape`` cells from ``origin`` (its box grown
    by a cell each way, so that rounding never leaves one out); None when none does."""
    if step <= 0.0:
        return 0, count - 1
    lo, hi = 0.0, (count - 1) * step  # the way's span, m along it
    for start, d, corner, cells in ((x, dx, origin[0], shape[0]),
                                    (y, dy, origin[1], shape[1])):
        low = corner - resolution
        high = low + (cells + 2) * resolution
        if d == 0.0:
            if not low <= start <= high:
                return None
            continue
        a, b = (low - start) / d, (high - start) / d
        lo, hi = max(lo, min(a, b)), min(hi, max(a, b))
    if lo > hi:
        return None
    first, last = max(0, math.floor(lo / step)), min(count - 1, math.ceil(hi / step))
    return (first, last) if first <= last else None


def _flat(grid: npt.NDArray[G]) -> npt.NDArray[G]:
    """A flat view of a grid (never a copy: the grids are C-contiguous)."""
    flat = grid.reshape(-1)
    assert flat.base is grid or flat.base is grid.base
    return flat


def _disc_offsets(resolution: float, inflation: float) -> tuple[npt.NDArray[np.int_],
                                                               npt.NDArray[np.int_]]:
    """The cell offsets (di, dj) whose centres lie within ``inflation`` of a cell's, as
    the distance transform's test has it: ``sqrt(di^2 + dj^2) * resolution <=
    inflation`` in doubles (the offsets inflation blocks round a lethal cell)."""
    reach = math.ceil(max(inflation, 0.0) / resolution) + 1
    pairs = [(di, dj) for di in range(-reach, reach + 1) for dj in range(-reach, reach + 1)
             if math.sqrt(float(di * di + dj * dj)) * resolution <= inflation]
    di = np.array([p[0] for p in pairs], dtype=np.int_)
    dj = np.array([p[1] for p in pairs], dtype=np.int_)
    return di, dj


class Costmap:
    """Occupancy from the scans, with decay; inflated on demand."""

    def __init__(
        self,
        lo: tuple[float, float],
        hi: tuple[float, float],
        *,
        resolution: float,
        decay: float,
        inflation: float,
        confirm: float = 0.0,
        wall_decay: float | None = None,
        wall_confirm: float = 0.0,
        padding: float,
        max_size: float,
    ) -> None:
        self.resolution = resolution
        self.decay = decay
        self.wall_decay = decay if wall_decay is None else max(wall_decay, decay)
        self.wall_confirm = wall_confirm
        self.confirm = confirm
        self.inflation = inflation
        self.padding = padding
        self.max_size = max_size
        x0 = math.floor((min(lo[0], hi[0]) - padding) / resolution) * resolution
        y0 = math.floor((min(lo[1], hi[1]) - padding) / resolution) * resolution
        nx = math.ceil((max(lo[0], hi[0]) + padding - x0) / resolution)
        ny = math.ceil((max(lo[1], hi[1]) + padding - y0) / resolution)
        self.origin = np.array([x0, y0], dtype=np.float64)
        self.seen = np.full((nx, ny), -math.inf)  # stamp a cell was last observed
        self.occupied = np.zeros((nx, ny), dtype=bool)  # what it was then
        self.hit_since = np.full((nx, ny), math.inf)  # start of its current occupied spell
        self.walls = np.zeros((nx, ny), dtype=bool)  # the wall memory (see cut_off)
        self.now = -math.inf
        self.version = 0  # bumped whenever the grids change
        self._refreshed: tuple[int, float] | None = None  # (version, now) of the cache
        self._inflated: tuple[BoolGrid, BoolGrid] | None = None
        self._gap: npt.NDArray[np.float64] | None = None  # of _inflated's lethal cells
        self._disc = _disc_offsets(resolution, inflation)
        self._clearance_discs: dict[float, tuple[npt.NDArray[np.int_], npt.NDArray[np.int_]]] = {}
        self._returned = np.zeros(0, dtype=np.uint8)  # per flat cell: a mark of this scan
        # The (angle_min, angle_increment, count) of the beams, their angles from the
        # heading, and a range of 1 m for each (for their directions).
        self._beams: tuple[tuple[float, float, int], npt.NDArray[np.float64],
                           npt.NDArray[np.float64]] | None = None

    # -- geometry ----------------------------------------------------------------------

    @property
    def shape(self) -> tuple[int, int]:
        nx, ny = self.seen.shape
        return nx, ny

    def cell_of(self, points: Vec) -> npt.NDArray[np.int64]:
        """(n, 2) integer cell indices of (n, 2) points (may lie outside the grid)."""
        return np.floor((np.asarray(points, dtype=np.float64) - self.origin)
                        / self.resolution).astype(np.int64)

    def centre_of(self, cells: npt.NDArray[np.int64]) -> Vec:
        return self.origin + (np.asarray(cells, dtype=np.float64) + 0.5) * self.resolution

    def inside(self, cells: npt.NDArray[np.int64]) -> npt.NDArray[np.bool_]:
        nx, ny = self.shape
        return np.asarray((cells[:, 0] >= 0) & (cells[:, 0] < nx)
                          & (cells[:, 1] >= 0) & (cells[:, 1] < ny))

    def grow_to(self, points: Vec, margin: float) -> None:
        """Enlarge the grid so ``points`` (n, 2) lie at least ``margin`` m inside it (in
        blocks of ``padding``), never beyond ``max_size`` a side."""
        if len(points) == 0:
            return
        lo = np.min(points, axis=0)
        hi = np.max(points, axis=0)
        self._grow_to_box(float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]), margin)

    def _grow_to_box(self, x_lo: float, y_lo: float, x_hi: float, y_hi: float,
                     margin: float) -> None:
        """``grow_to`` the points of the box [x_lo, x_hi] x [y_lo, y_hi]."""
        r = self.resolution
        nx, ny = self.shape
        ox, oy = float(self.origin[0]), float(self.origin[1])
        if (ox <= x_lo - margin and oy <= y_lo - margin and x_hi + margin <= ox + nx * r
                and y_hi + margin <= oy + ny * r):
            return  # inside already (what the growth below would find, cheaper)
        lo = np.array([x_lo, y_lo]) - margin
        hi = np.array([x_hi, y_hi]) + margin
        top = self.origin + np.array([nx, ny]) * r
        add_lo = np.maximum(np.ceil((self.origin - lo) / self.padding), 0) * self.padding
        add_hi = np.maximum(np.ceil((hi - top) / self.padding), 0) * self.padding
        if not (add_lo.any() or add_hi.any()):
            return
        cells_lo = np.rint(add_lo / r).astype(int)
        cells_hi = np.rint(add_hi / r).astype(int)
        limit = math.ceil(self.max_size / r)
        for axis, size in enumerate((nx, ny)):
            over = size + cells_lo[axis] + cells_hi[axis] - limit
            if over > 0:  # keep the side nearer the points; drop the growth that overflows
                cut_hi = min(cells_hi[axis], over)
                cells_hi[axis] -= cut_hi
                cells_lo[axis] = max(cells_lo[axis] - (over - cut_hi), 0)
        if not (cells_lo.any() or cells_hi.any()):
            return
        pad = ((int(cells_lo[0]), int(cells_hi[0])), (int(cells_lo[1]), int(cells_hi[1])))
        self.seen = np.pad(self.seen, pad, constant_values=-math.inf)
        self.occupied = np.pad(self.occupied, pad, constant_values=False)
        self.hit_since = np.pad(self.hit_since, pad, constant_values=math.inf)
        self.walls = np.pad(self.walls, pad, constant_values=False)
        self.origin = self.origin - cells_lo * r
        self.version += 1
        self._inflated = None

    # -- updates -----------------------------------------------------------------------

    def update(self, scan: ScanData, stamp: float,
               movers: list[tuple[float, float, float]] | None = None) -> None:
        """Ray-trace one scan taken at ``stamp``. ``movers``: (x, y, radius) discs of the
        tracks typed dynamic; returns inside them are not marked."""
        self.now = max(self.now, stamp)
        x, y, heading = scan.pose
        ranges = np.ascontiguousarray(scan.ranges, dtype=np.float64)
        beams = (scan.angle_min, scan.angle_increment, ranges.size)
        if self._beams is None or self._beams[0] != beams:  # the same laser, scan after scan
            self._beams = (beams, np.asarray(scan.angle_min + scan.angle_increment
                                             * np.arange(ranges.size), dtype=np.float64),
                           np.ones(ranges.size))
        _, alpha, unit = self._beams
        # Each beam's unit direction in the global frame (Eq. 1 at rho = 1 m from the
        # robot); a return lies at the robot plus its range times that (Eq. 1 again).
        ux, uy = to_global((0.0, 0.0, heading), unit, alpha)
        box = return_bounds(x, y, ux, uy, ranges, scan.range_min, scan.range_max)
        self._grow_to_box(*box, self.padding / 2)
        nx, ny = self.shape
        if self._returned.size != nx * ny:
            self._returned = np.zeros(nx * ny, dtype=np.uint8)
        discs = np.asarray(movers if movers else [], dtype=np.float64).reshape(-1, 3)
        # Compiled (``_loops.trace_scan``), in three steps:
        # - the marks: the cells of the returns, except those on a mover;
        # - free space: every cell each beam passes through, stopping half a cell short
        #   of its return (a beam with no return clears up to its reach, never beyond the
        #   laser's: a range above it must not make a beam endless), except the marked
        #   cells: along a straight wall, the beams that meet it at a grazing angle pass
        #   through the face cells the others return from, and clearing them would
        #   restart their confirmation on every scan (a wall seen side-on would never be
        #   confirmed);
        # - the marking: occupied now, a wall once occupied for ``confirm`` seconds.
        trace_scan(x, y, ux, uy, ranges, scan.range_min, scan.range_max, discs,
                   float(self.origin[0]), float(self.origin[1]), self.resolution, ny,
                   self._returned, stamp, self.confirm, _flat(self.seen),
                   _flat(self.occupied).view(np.uint8), _flat(self.hit_since),
                   _flat(self.walls).view(np.uint8))
        self.version += 1

    def forget_older_than(self, stamp: float, keep: tuple[Vec, float] | None = None) -> None:
        """Make every cell last seen before ``stamp`` unknown (recovery's clearing),
        except the long-seen walls (``_kept_walls``) and, with ``keep`` (a point and a
        radius, m), the cells whose centre lies within the radius of the point (Nav2's
        clearing except a region round the robot)."""
        old = (self.seen < stamp) & ~self._kept_walls()
        if keep is not None:
            nx, ny = self.shape
            i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
            centre, radius = keep
            x = self.origin[0] + (i + 0.5) * self.resolution
            y = self.origin[1] + (j + 0.5) * self.resolution
            old &= np.hypot(x - centre[0], y - centre[1]) > radius
        if (old & self.occupied).any():
            self._inflated = None
        self.version += 1
        self.seen[old] = -math.inf
        self.occupied[old] = False
        self.hit_since[old] = math.inf

    # -- reading -----------------------------------------------------------------------

    def cut_off(self, start: Vec, goal: Vec, clearance: float) -> bool:
        """Whether the wall memory closes ``goal`` off from ``start``: no way of free
        cells (every cell centre farther than ``clearance`` from the remembered walls)
        joins the free cells within ``clearance`` plus a cell of the start to those near
        the goal. Unknown cells count as free, so this errs toward a way: only walls seen
        close the goal off. Marks on the goal's own cells are not enough: a goal whose
        cells near it are all within ``clearance`` of walls is covered, not closed off.
        A mover passing over the goal leaves such marks until a beam clears them, and a
        slow one walking toward the robot, on the way, keeps the beams off them. The
        map's "goal occupied" answers a covered goal, after a stall."""
        ends = self.cell_of(np.vstack([start, goal]))
        if not self.inside(ends).all():
            return False  # beyond the grid: no knowledge, no verdict
        if not self.walls.any():
            return False
        # The free cells are those farther than ``clearance`` from every wall cell (by
        # the distance transform's test: the cells outside the walls' discs of
        # ``_disc_offsets``), the ways 4-connected (``scipy.ndimage.label``'s): a flood
        # in compiled code (``_loops.closed_off``) from the free cells near the start.
        if clearance not in self._clearance_discs:
            self._clearance_discs[clearance] = _disc_offsets(self.resolution, clearance)
        di, dj = self._clearance_discs[clearance]
        reach = math.ceil(clearance / self.resolution) + 1
        nx, ny = self.shape
        (si, sj), (gi, gj) = ends.tolist()
        return closed_off(_flat(self.walls).view(np.uint8), nx, ny, di, dj, si, sj, gi, gj,
                          reach)

    def _distances(self, cells: BoolGrid) -> npt.NDArray[np.float64]:
        """(nx, ny) distance from each cell's centre to the nearest of ``cells`` (at least
        one), m: scipy's Euclidean distance transform."""
        return np.asarray(distance_transform_edt(~cells), dtype=np.float64) * self.resolution

    def known(self) -> BoolGrid:
        return np.asarray(self.seen >= self.now - self.decay)

    def lethal(self) -> BoolGrid:
        """Cells occupied when last seen, within the decay time, and for at least the
        confirmation time; and the long-seen walls (``_kept_walls``)."""
        return np.asarray(self.occupied & self.known()
                          & (self.hit_since <= self.now - self.confirm)
                          | self._kept_walls())

    def _returns_in(self, lo: Vec, hi: Vec) -> tuple[int, int, int, int]:
        """The columns ``i0..i1 - 1`` and rows ``j0..j1 - 1`` of the grid the box
        ``lo``..``hi`` (m) covers (none when it misses the grid)."""
        first = np.maximum(self.cell_of(lo[None, :])[0], 0)
        last = np.maximum(np.minimum(self.cell_of(hi[None, :])[0] + 1, self.shape), first)
        return int(first[0]), int(last[0]), int(first[1]), int(last[1])

    def has_returns_in(self, lo: Vec, hi: Vec) -> bool:
        """Whether a cell inside the box ``lo``..``hi`` (m) was occupied when last seen,
        within the decay time (a return, confirmed as lethal or not yet)."""
        return self._returns_near(self._returns_in(lo, hi), (0.0, 0.0), (0.0, 0.0),
                                  math.inf)

    def _kept_walls(self) -> BoolGrid:
        """The walls kept past the decay and through recovery's clearing: seen within
        the wall decay time, occupied for at least the wall confirmation time then."""
        return np.asarray(self.walls & (self.seen >= self.now - self.wall_decay)
                          & (self.seen - self.hit_since >= self.wall_confirm))

    def returns_near_segment(self, a: Vec, b: Vec, distance: float,
                             lo: Vec | None = None, hi: Vec | None = None) -> bool:
        """Whether a cell occupied when last seen, within the decay time (a return,
        confirmed as lethal or not yet), has its centre within ``distance`` m of the
        segment from ``a`` to ``b``; with ``lo`` and ``hi`` (m), only the cells inside
        that box count. One compiled pass over the box (``_loops.returns_near``)."""
        if lo is None or hi is None:
            lo, hi = np.minimum(a, b) - distance, np.maximum(a, b) + distance
        return self._returns_near(self._returns_in(lo, hi), (float(a[0]), float(a[1])),
                                  (float(b[0]), float(b[1])), distance)

    def _returns_near(self, part: tuple[int, int, int, int], a: tuple[float, float],
                      b: tuple[float, float], distance: float) -> bool:
        i0, i1, j0, j1 = part
        return returns_near(_flat(self.occupied).view(np.uint8), _flat(self.seen),
                            self.shape[1], i0, i1, j0, j1, self.now - self.decay,
                            float(self.origin[0]), float(self.origin[1]), self.resolution,
                            a[0], a[1], b[0], b[1], distance)

    def lethal_near(self, centre: Vec, radius: float) -> Vec:
        """(n, 2) centres of the lethal cells within ``radius`` m of ``centre``."""
        lo = np.maximum(self.cell_of((centre - radius)[None, :])[0], 0)
        hi = np.minimum(self.cell_of((centre + radius)[None, :])[0] + 1, self.shape)
        if (hi <= lo).any():
            return np.empty((0, 2))
        cells = np.argwhere(self.lethal_grid()[lo[0]:hi[0], lo[1]:hi[1]]) + lo
        points = self.centre_of(cells)
        near: Vec = points[np.hypot(*(points - centre).T) <= radius]
        return near

    def _refresh(self) -> tuple[BoolGrid, BoolGrid]:
        # Lethal cells change only with the grids and the time (decay, confirmation):
        # a cycle asks several times with neither changed.
        if self._inflated is not None and self._refreshed == (self.version, self.now):
            return self._inflated
        self._refreshed = (self.version, self.now)
        # ``lethal()`` in one compiled pass (``_loops.lethal_cells``), which also says
        # whether the set differs from the last: the inflation depends on the set alone
        # (every update bumps the version, though the set mostly stays the same).
        lethal = np.empty_like(self.occupied)
        before = self._inflated[0] if self._inflated is not None else None
        if before is not None and before.shape != lethal.shape:
            before = None
        changed = lethal_cells(
            _flat(self.occupied).view(np.uint8), _flat(self.seen), _flat(self.hit_since),
            _flat(self.walls).view(np.uint8),
            self.now - self.decay, self.now - self.confirm, self.now - self.wall_decay,
            self.wall_confirm,
            _flat(lethal if before is None else before).view(np.uint8),
            _flat(lethal).view(np.uint8))
        if self._inflated is not None and before is not None and not changed:
            return self._inflated
        # The blocked cells are those within the inflation distance of a lethal one;
        # the distances themselves (``gap``) only when asked: most cycles need none.
        # Few lethal cells: each one's disc of blocked cells; many: the distances.
        centres = np.flatnonzero(lethal)
        di, dj = self._disc
        if len(centres) * len(di) <= 4 * lethal.size:
            blocked = np.zeros_like(lethal)
            stamp_discs(centres, *self.shape, di, dj, _flat(blocked).view(np.uint8))
            self._gap = None
        else:
            self._gap = self._distances(lethal)
            blocked = np.asarray(self._gap <= self.inflation)
        self._inflated = (lethal, blocked)
        return lethal, blocked

    def lethal_grid(self) -> BoolGrid:
        """The lethal cells the inflation was made from (cached with it)."""
        return self._refresh()[0]

    def blocked(self) -> BoolGrid:
        """Cells whose centre lies within the inflation distance of an occupied cell:
        the robot's centre must not enter them."""
        return self._refresh()[1]

    def gap(self) -> npt.NDArray[np.float64]:
        """(nx, ny) distance from each cell's centre to the nearest occupied one, m (inf
        when none is known)."""
        lethal = self._refresh()[0]
        if self._gap is None:
            self._gap = (self._distances(lethal) if lethal.any()
                         else np.full(lethal.shape, math.inf))
        return self._gap

    def blocked_at(self, points: Vec, *, outside: bool = False) -> npt.NDArray[np.bool_]:
        """Whether each point (n, 2) lies in a blocked cell; a point beyond the grid is
        ``outside`` (free by default: the local checks near the robot, which the grid
        always holds with room to spare; the global path passes True)."""
        return self._look_up(points, self.blocked(), outside)

    def blocked_rows(self, xs: Vec, ys: Vec) -> npt.NDArray[np.bool_]:
        """For each row of points (``xs[i]``, ``ys[i]``), whether any lies in a blocked
        cell (beyond the grid: free, as for ``blocked_at``), in compiled code
        (``_loops.look_up_rows``), stopping at the first."""
        out = np.empty(xs.shape[0], dtype=bool)
        look_up_rows(np.ascontiguousarray(xs, dtype=np.float64),
                     np.ascontiguousarray(ys, dtype=np.float64), float(self.origin[0]),
                     float(self.origin[1]), self.resolution,
                     _flat(self.blocked()).view(np.uint8), self.shape[1], out.view(np.uint8))
        return out

    def blocked_along(self, start: tuple[float, float], direction: tuple[float, float],
                      length: float, count: int) -> bool:
        """Whether any of ``count`` points evenly spaced along the straight way from
        ``start`` along ``direction`` (unit) for ``length`` m, both ends included (the
        points of ``prediction.path_points``), lies in a blocked cell (beyond the grid:
        free, as for ``blocked_at``); in compiled code (``_loops.line_any``), stopping at
        the first. Only the points on the grid are looked at, so the cost is bounded by
        the grid's size however far the way reaches (a pose a bad message puts 1e15 m
        away must not hold the planner for ever)."""
        grid = self.blocked()
        x, y = start
        dx, dy = direction
        ox, oy = float(self.origin[0]), float(self.origin[1])
        if count > 1:
            step = length / (count - 1)
            on_grid = _on_grid_steps(x, y, dx, dy, step, count, (ox, oy), self.shape,
                                     self.resolution)
            if on_grid is None:
                return False
            first, last = on_grid
            if (first, last) != (0, count - 1):
                x, y = x + dx * step * first, y + dy * step * first
                length, count = step * (last - first), last - first + 1
        return line_any(x, y, dx, dy, length, count, ox, oy, self.resolution,
                        _flat(grid).view(np.uint8), self.shape[1], False)

    def first_blocked_on(self, points: Vec, lengths: Vec, s: Vec) -> int:
        """The index of the first arc length of ``s`` (non-decreasing) whose point on the
        path (``points``, arc ``lengths``; ``np.interp``'s points) lies in a blocked cell
        or beyond the grid, -1 when none does; in compiled code (``_loops.first_flagged_on``,
        stopping at the first)."""
        return first_flagged_on(np.ascontiguousarray(points, dtype=np.float64),
                                np.ascontiguousarray(lengths, dtype=np.float64),
                                np.ascontiguousarray(s, dtype=np.float64),
                                float(self.origin[0]), float(self.origin[1]), self.resolution,
                                _flat(self.blocked()).view(np.uint8), self.shape[1], True)

    def squares_clear(self, point: tuple[float, float], span: float, clearance: float) -> bool:
        """Whether every lethal cell whose square meets the box ``point`` +- ``span`` (m)
        lies at least ``clearance`` m from the point, its distance taken to the cell's
        square; in compiled code (``_loops.squares_clear``), stopping at the first that
        does not."""
        return squares_clear(_flat(self.lethal_grid()).view(np.uint8), self.shape[1],
                             float(self.origin[0]), float(self.origin[1]), self.resolution,
                             point[0], point[1], span, clearance)

    def lethal_at(self, points: Vec) -> npt.NDArray[np.bool_]:
        return self._look_up(points, self._refresh()[0], False)

    def _look_up(self, points: Vec, grid: BoolGrid, outside: bool) -> npt.NDArray[np.bool_]:
        """The flag of the cell of each point (n, 2) in ``grid`` (``cell_of``), or
        ``outside`` beyond the grid, in compiled code (``_loops.look_up``)."""
        xy = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2)
        out = np.empty(len(xy), dtype=bool)
        look_up(xy, float(self.origin[0]), float(self.origin[1]), self.resolution,
                _flat(grid).view(np.uint8), self.shape[1], outside, out.view(np.uint8))
        return out

    def values(self) -> npt.NDArray[np.int8]:
        """(nx, ny) int8: -1 unknown, 0 free, 100 occupied."""
        out = np.full(self.shape, UNKNOWN, dtype=np.int8)
        known = self.known()
        out[known] = FREE
        out[self.lethal()] = OCCUPIED
        return out
