"""Adaptive-threshold nearest-neighbour clustering of one laser scan (paper Section 3.1-3.2).

Pure functions: :func:`cluster_scan` takes the scan in the ROS LaserScan convention and the
robot pose at scan time, and returns a :class:`Clusters` record, one row per obstacle in scan
order (the obstacle chain O_chain(t) of Eq. 4). The equations are functions of this module;
Eqs. 1, 2, 3 and 6 are written once in compiled code (``_equations.pxi``), which these
functions and the compiled passes over the scan, its points and runs (``_loops.pyx``)
both use.

Conventions
-----------
* Beam ``i`` points at ``alpha_i = angle_min + i * angle_increment`` relative to the robot
  heading, counter-clockwise positive (REP 103). For the paper's 180-degree scanner
  ``angle_min = -pi/2``: beam 0 looks to the right and the scan runs right to left, which is
  the paper's 0 -> 180 degree order.
* Eq. 1 in the paper reads ``theta_R - alpha_i`` because the paper counts alpha clockwise from
  the heading; with alpha counter-clockwise the same point is
  ``(x_R + rho cos(theta_R + alpha), y_R + rho sin(theta_R + alpha))``.
* A reading that is not finite, ``< range_min`` or ``>= range_max`` is "no return".
* Scans up to 360 degrees. A full-circle scan has a seam (straight behind, in the usual
  layout) where the last beam meets the first; an obstacle across it would be cut in two.
  ``seam_shift`` and ``rotate_scan`` let perception start such a scan at a break between
  clusters instead (``perceive.py``); within one scan a cluster never wraps.

Decisions on points the paper leaves open
-----------------------------------------
* Edges of S_k (Eq. 6). The paper builds the box from the pairs (min rho, min alpha) and
  (max rho, max alpha), which are generally not points of the cluster, and whose box can miss
  cells the obstacle covers (a surface seen obliquely has its nearest point in the middle) or
  shrink to a line. Here S_k is the bounding box, in grid cells, of *every* point of the
  cluster (Eq. 2 applied to each point): it always holds every cell the cluster touches, does
  not depend on which way the scan runs, and costs two reductions.
* Eq. 3 uses ``rho`` of the current point (the later beam of the pair) and the scan's own
  ``angle_increment``. Beams outside the window are skipped, so the two points compared are
  consecutive *available* points, as the paper's example (rho_2, rho_4) does.
* ``chord_centre`` and ``radius`` go beyond the paper. The Eq. 5 centre lies on the visible
  surface; for a round obstacle it sits about 0.8 radius in front of the true centre and
  swings with the bearing as the robot moves. The midpoint of the two end points is within
  radius^2 / distance of a disc's centre and is exactly the centre of a box seen corner-on,
  so it serves as the footprint centre; the tracker can use either.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final, overload

import numpy as np
import numpy.typing as npt

from zenav.services.perception import _loops
from zenav.services.perception.params import PerceptionParams

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]
Pose = tuple[float, float, float]

# Codes for what lies beyond each end of a cluster (in scan order), see Clusters.edge_start.
EDGE_FREE: Final = 0
"""The neighbouring beam has no return or hits something farther: the cluster ends here."""
EDGE_OCCLUDED: Final = 1
"""The neighbouring beam hits something nearer: the obstacle may go on behind it."""
EDGE_CLIPPED: Final = 2
"""The surface goes on outside the sliding window, or the cluster touches the end of the scan."""


@dataclass(frozen=True, eq=False)
class Clusters:
    """The obstacle chain of one scan: one row per cluster, in scan order.

    All coordinates are global (metres, x right, y up); grid indices follow Eq. 2
    (``floor(x / cell + 1/2)``).

    Attributes:
        centre: (n, 2) Eq. 5 centre Z_k: the point at mean alpha and mean rho, made global
            with Eq. 1.
        mean_rho: (n,) mean range of the cluster's beams, metres (Eq. 5).
        mean_alpha: (n,) mean beam angle relative to the heading, radians (Eq. 5).
        box: (n, 4) grid box ``ix_min, ix_max, iy_min, iy_max`` (inclusive) of S_k (Eq. 6): the
            bounding box, in cells, of every point of the cluster.
        area: (n,) S_k, number of cells in ``box`` (Eq. 6).
        beams: (n, 2) first and last beam index of the cluster (inclusive).
        n_beams: (n,) beams in the cluster (beams outside the window or without a return
            inside the span do not count).
        first_point: (n, 2) global point of the first beam of the cluster.
        last_point: (n, 2) global point of the last beam of the cluster.
        chord_centre: (n, 2) midpoint of ``first_point`` and ``last_point``: a footprint
            centre that moves much less with the viewpoint than ``centre`` (see below).
        radius: (n,) largest distance from ``chord_centre`` to a point of the cluster,
            metres: a footprint radius for the visible part (the hidden back is unknown).
        edge_start: (n,) what lies before the first beam: EDGE_FREE / EDGE_OCCLUDED /
            EDGE_CLIPPED.
        edge_end: (n,) the same after the last beam.
        pose: robot pose (x, y, heading rad) at scan time, used for Eq. 1.
        cell: grid resolution r, metres (Eq. 2).
    """

    centre: FloatArray
    mean_rho: FloatArray
    mean_alpha: FloatArray
    box: IntArray
    area: IntArray
    beams: IntArray
    n_beams: IntArray
    first_point: FloatArray
    last_point: FloatArray
    chord_centre: FloatArray
    radius: FloatArray
    edge_start: IntArray
    edge_end: IntArray
    pose: Pose
    cell: float
    moved: FloatArray | None = None
    """(n,) free-space motion score in [0, 1] (``motion_cue.py``); None when not measured."""
    moved_each: FloatArray | None = None
    """(n, k) the same score against each of the k earlier scans compared with."""
    moved_refs: FloatArray | None = None
    """(k,) stamps of those earlier scans, s (nan: none yet)."""

    def __len__(self) -> int:
        return int(self.area.shape[0])

    @property
    def partial(self) -> npt.NDArray[np.bool_]:
        """(n,) True where either end is occluded or clipped: only part of the obstacle seen."""
        start_hidden = self.edge_start != EDGE_FREE
        end_hidden = self.edge_end != EDGE_FREE
        partial: npt.NDArray[np.bool_] = start_hidden | end_hidden
        return partial

    def with_motion(self, each: FloatArray, refs: FloatArray) -> Clusters:
        """This chain with the motion cue's scores: ``each`` (n, k) against the earlier
        scans stamped ``refs`` (k,), and ``moved`` their largest per cluster (0 without
        any). A copy of the instance's fields, whichever they are, with those three
        replaced: it cannot miss a field, and costs a fraction of ``dataclasses.replace``
        (which passes every field through ``__init__``; the class has no
        ``__post_init__`` to run)."""
        chain = object.__new__(type(self))
        vars(chain).update(vars(self), moved=each.max(axis=1, initial=0.0), moved_each=each,
                           moved_refs=refs)
        return chain

    @classmethod
    def empty(cls, pose: Pose = (0.0, 0.0, 0.0), cell: float = 0.5) -> Clusters:
        """A chain with no obstacles."""
        f1 = np.zeros(0, dtype=np.float64)
        f2 = np.zeros((0, 2), dtype=np.float64)
        i1 = np.zeros(0, dtype=np.int64)
        return cls(
            centre=f2,
            mean_rho=f1,
            mean_alpha=f1,
            box=np.zeros((0, 4), dtype=np.int64),
            area=i1,
            beams=np.zeros((0, 2), dtype=np.int64),
            n_beams=i1,
            first_point=f2,
            last_point=f2,
            chord_centre=f2,
            radius=f1,
            edge_start=i1,
            edge_end=i1,
            pose=pose,
            cell=cell,
        )


def to_global(
    pose: Pose, rho: npt.ArrayLike, alpha: npt.ArrayLike
) -> tuple[FloatArray, FloatArray]:
    """Eq. 1: global (x, y) of the points at range ``rho`` and beam angle ``alpha``.

    ``alpha`` is counter-clockwise from the heading (see the module notes), so the paper's
    ``theta_R - alpha_i`` reads ``theta_R + alpha`` here: ``x_R + rho cos(theta_R +
    alpha)``, ``y_R + rho sin(theta_R + alpha)``. Compiled (``_equations.pxi``, the
    lines the window and the cluster centres use too); ``rho`` and ``alpha`` broadcast.
    """
    x_r, y_r, th_r = pose
    r, a = np.asarray(rho, dtype=np.float64), np.asarray(alpha, dtype=np.float64)
    if r.shape != a.shape:
        r, a = np.broadcast_arrays(r, a)
    gx, gy = np.empty(r.shape), np.empty(r.shape)
    _loops.to_global_into(float(x_r), float(y_r), float(th_r),
                          np.ascontiguousarray(r).reshape(-1),
                          np.ascontiguousarray(a).reshape(-1), gx.reshape(-1), gy.reshape(-1))
    return gx, gy


def grid_index(coord: npt.ArrayLike, cell: float) -> IntArray:
    """Eq. 2: grid index ``floor(coord / r + 1/2)`` (cell k is centred on k * r).
    Compiled (``_equations.pxi``, the lines the cluster boxes use too)."""
    c = np.asarray(coord, dtype=np.float64)
    out = np.empty(c.shape, dtype=np.int64)
    _loops.grid_index_into(np.ascontiguousarray(c).reshape(-1), cell, out.reshape(-1))
    return out


# (A tuple is array-like too, so the two forms overlap for mypy; the tuple's comes first.)
@overload
def box_area(box: tuple[int, int, int, int]) -> int: ...  # type: ignore[overload-overlap]
@overload
def box_area(box: npt.ArrayLike) -> IntArray: ...
def box_area(box: npt.ArrayLike) -> int | IntArray:
    """Eq. 6: cells in an inclusive grid box ``(ix_min, ix_max, iy_min, iy_max)``, or in
    each row of an array of boxes. One box as a tuple of Python ints (as the tracker keeps
    them) gives a Python int. Compiled (``_equations.pxi``, the lines the cluster areas
    use too)."""
    if isinstance(box, tuple):
        return _loops.box_area(*box)
    b = np.asarray(box, dtype=np.int64)
    area = np.empty(b.shape[:-1], dtype=np.int64)
    _loops.box_areas_into(np.ascontiguousarray(b).reshape(-1, 4), area.reshape(-1))
    return area


def join_threshold(
    rho: npt.ArrayLike, angle_increment: float, params: PerceptionParams
) -> FloatArray:
    """Eq. 3: distance above which two consecutive points start a new cluster.

    ``theta = lambda * rho * sin(d_alpha) + gap_floor``; ``d_alpha`` is the scan's own angular
    step (0.5 degrees for the paper's scanner), ``rho`` the range of the current point.
    ``gap_floor`` is 0 in the paper (see PerceptionParams). Compiled (``_equations.pxi``,
    the lines the cuts and the edge codes use too).
    """
    r = np.asarray(rho, dtype=np.float64)
    out = np.empty(r.shape)
    _loops.join_threshold_into(np.ascontiguousarray(r).reshape(-1), params.lambda_,
                               math.sin(abs(angle_increment)), params.gap_floor,
                               out.reshape(-1))
    return out


def cluster_means(
    rho: npt.ArrayLike, alpha: npt.ArrayLike, starts: npt.ArrayLike, counts: npt.ArrayLike
) -> tuple[FloatArray, FloatArray]:
    """Eq. 5: mean rho and mean alpha of each cluster.

    The clusters are runs of ``rho`` / ``alpha`` (1-D, back to back) starting at ``starts``
    with ``counts`` points each.
    """
    first = np.asarray(starts, dtype=np.int64)
    n = np.asarray(counts, dtype=np.float64)
    mean_rho = np.add.reduceat(np.asarray(rho, dtype=np.float64), first) / n
    mean_alpha = np.add.reduceat(np.asarray(alpha, dtype=np.float64), first) / n
    return mean_rho, mean_alpha


@dataclass(frozen=True, eq=False)
class Window:
    """The returns of one scan inside the sliding window, with their global points: what
    clustering starts from, and what the motion cue keeps of the scan (one Eq. 1 pass for
    both).

    Attributes:
        ranges: (n,) the scan's ranges, float64.
        valid: (n,) a return: finite, ``>= range_min`` and ``< range_max``.
        beams: (k,) the beams with a return within ``window_radius``, in scan order.
        rho: (k,) their ranges, metres.
        alpha: (k,) their angles relative to the heading, radians.
        x: (k,) their global points (Eq. 1), metres.
        y: (k,)
        points: (k, 2) the same points as rows (x, y).
    """

    ranges: FloatArray
    valid: npt.NDArray[np.bool_]
    beams: IntArray
    rho: FloatArray
    alpha: FloatArray
    x: FloatArray
    y: FloatArray
    points: FloatArray


def scan_window(
    ranges: npt.ArrayLike,
    angle_min: float,
    angle_increment: float,
    range_min: float,
    range_max: float,
    pose: Pose,
    window_radius: float,
) -> Window:
    """The returns of a scan inside the window (rho <= ``window_radius``), made global with
    Eq. 1 (arguments as :func:`cluster_scan`'s)."""
    r = np.ascontiguousarray(ranges, dtype=np.float64)
    n = r.shape[0]
    valid = np.empty(n, dtype=np.bool_)
    idx = np.empty(n, dtype=np.int64)
    rho, alpha, px, py = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    xy = np.empty((n, 2))
    # The masks, the window's beams, ranges, angles and points (Eq. 1) in one compiled
    # pass (NaN compares False everywhere, so it drops out as "no return" like inf does).
    x, y, heading = pose
    k = _loops.window_points(r, angle_min, angle_increment, range_min, range_max,
                             window_radius, x, y, heading, valid.view(np.uint8), idx, rho,
                             alpha, px, py, xy)
    return Window(r, valid, idx[:k], rho[:k], alpha[:k], px[:k], py[:k], xy[:k])


def full_circle(n_beams: int, angle_increment: float) -> int:
    """The beams of one turn (``round(2 pi / |increment|)``) when the scan's ``n_beams``
    close a full circle (the last may repeat the first's direction, as a 360-degree scan
    from -pi to pi does); 0 for a scan that does not."""
    step = abs(angle_increment)
    if step <= 0.0:
        return 0
    period = round(2.0 * math.pi / step)
    if n_beams < period or abs(period * step - 2.0 * math.pi) > 1e-6:
        return 0
    return period


def seam_shift(clusters: Clusters, window: Window, angle_increment: float,
               params: PerceptionParams) -> int | None:
    """For a full-circle scan whose seam cuts a cluster in two, the beam to start the scan
    at instead: the middle of the widest break between two clusters that follow each
    other (Eq. 3 did not join them), so that no cluster touches the new seam unless the
    break is a single beam wide. None when the scan is not a full circle, the seam already
    lies at a break (the last window point and the first, consecutive across the seam, do
    not join by Eq. 3), or there is no break to move it to (one ring all round)."""
    period = full_circle(window.ranges.shape[0], angle_increment)
    if not period or len(clusters) < 2 or window.beams.size < 2:
        return None
    gap = math.hypot(float(window.x[0] - window.x[-1]), float(window.y[0] - window.y[-1]))
    if gap > float(join_threshold(window.rho[0], angle_increment, params)):
        return None
    beams = clusters.beams
    widest = int(np.argmax(beams[1:, 0] - beams[:-1, 1]))
    shift = int(beams[widest, 1] + beams[widest + 1, 0] + 1) // 2
    return shift if shift < period else None


def rotate_scan(ranges: FloatArray, angle_min: float, angle_increment: float,
                shift: int) -> tuple[FloatArray, float]:
    """One turn of a full-circle scan (``full_circle`` beams; a repeated last direction
    is dropped) started at beam ``shift``: its ranges and the new ``angle_min``. Beam
    angles then run past pi, which Eq. 1 takes as they are."""
    period = full_circle(ranges.shape[0], angle_increment)
    turned = np.roll(np.ascontiguousarray(ranges[:period], dtype=np.float64), -shift)
    return turned, angle_min + shift * angle_increment


def cluster_scan(
    ranges: npt.ArrayLike,
    angle_min: float,
    angle_increment: float,
    range_min: float,
    range_max: float,
    pose: Pose,
    params: PerceptionParams,
) -> Clusters:
    """Cluster one scan into the obstacle chain O_chain(t) (Eqs. 1-6).

    Args:
        ranges: (n,) ranges in metres, beam i at ``angle_min + i * angle_increment``.
        angle_min: angle of beam 0 relative to the heading, radians (CCW positive).
        angle_increment: angle between consecutive beams, radians (the Eq. 3 step).
        range_min: readings below this are no return, metres.
        range_max: readings at or above this are no return, metres.
        pose: robot pose at scan time (x, y, heading rad), global frame.
        params: window, grid and clustering parameters.

    Returns:
        The clusters in scan order. Points with rho > ``window_radius`` are ignored; two
        consecutive points inside the window (skipping beams that are not) join when their
        Euclidean distance is at most the Eq. 3 threshold of the current point.
    """
    window = scan_window(ranges, angle_min, angle_increment, range_min, range_max, pose,
                         params.window_radius)
    return cluster_window(window, angle_increment, pose, params)


def cluster_window(
    window: Window, angle_increment: float, pose: Pose, params: PerceptionParams,
    cuts: IntArray | None = None,
) -> Clusters:
    """:func:`cluster_scan` from the scan's window (:func:`scan_window`). ``cuts``:
    window points (indices into the window's arrays) that start a cluster of their own
    whatever Eq. 3 says (:func:`moving_cuts`); the cluster ends on either side of a cut
    are coded EDGE_OCCLUDED, since the obstacle beyond the cut touches them."""
    cell = params.cell
    r, valid, idx = window.ranges, window.valid, window.beams
    if idx.size == 0:
        return Clusters.empty(pose, cell)

    x_r, y_r, th_r = pose
    rho, alpha, px, py = window.rho, window.alpha, window.x, window.y

    # Eq. 3: a new cluster starts where the distance to the previous point exceeds theta
    # (compared squared, both sides are non-negative; compiled, one pass).
    m = idx.size
    starts, ends, counts = (np.empty(m, dtype=np.int64) for _ in range(3))
    k = _loops.run_bounds(px, py, rho, params.lambda_, math.sin(abs(angle_increment)),
                          params.gap_floor, starts, ends, counts)
    starts, ends, counts = starts[:k], ends[:k], counts[:k]
    cut_start = cut_end = None
    if cuts is not None and cuts.size:
        starts, ends, cut_start, cut_end = _split_runs(starts, ends, cuts)
        counts = ends - starts + 1

    if params.min_beams > 1:
        keep = counts >= params.min_beams
        if not keep.all():
            starts, ends, counts = starts[keep], ends[keep], counts[keep]
            if cut_start is not None and cut_end is not None:
                cut_start, cut_end = cut_start[keep], cut_end[keep]
            if starts.size == 0:
                return Clusters.empty(pose, cell)
            # Gather the kept runs back to back so that reduceat works on them.
            sel = _run_selector(starts, counts)
            rho, alpha, px, py = rho[sel], alpha[sel], px[sel], py[sel]
            idx = idx[sel]
            ends = np.cumsum(counts) - 1
            starts = ends - counts + 1
    k = starts.size

    # Eq. 5: mean alpha and mean rho, then Eq. 1 for the global centre.
    mean_rho, mean_alpha = cluster_means(rho, alpha, starts, counts)
    centre = np.empty((k, 2))
    _loops.to_global_rows(x_r, y_r, th_r, mean_rho, mean_alpha, centre)

    # Eq. 2 on every point, Eq. 6 box over all of them (S_k's edges, see the module notes).
    # The metric bounding box is shrunk by ``edge_inset`` on each side (never past its
    # middle) before Eq. 2: an obstacle edge that lies on a cell boundary, as the edges
    # of boxes laid out on the grid do, then stays in the obstacle's cell instead of
    # spilling into the free one beside it, whichever way range noise moved the point.
    # The boxes (Eq. 2 of the edges: ix_min, ix_max, iy_min, iy_max), their areas (Eq. 6),
    # end points, chord centres and radii in one compiled pass over the runs.
    box = np.empty((k, 4), dtype=np.int64)
    area = np.empty(k, dtype=np.int64)
    first_point = np.empty((k, 2))
    last_point = np.empty((k, 2))
    chord = np.empty((k, 2))
    radius = np.empty(k)
    _loops.run_shapes(px, py, starts, ends, params.edge_inset, cell, box, area, first_point,
                      last_point, chord, radius)

    beams = np.empty((k, 2), dtype=np.int64)
    beams[:, 0] = idx[starts]
    beams[:, 1] = idx[ends]
    codes = _edge_codes(r, valid, beams, angle_increment, params)
    if cut_start is not None and cut_end is not None:
        codes[cut_start, 0] = EDGE_OCCLUDED
        codes[cut_end, 1] = EDGE_OCCLUDED

    return Clusters(
        centre=centre,
        mean_rho=mean_rho,
        mean_alpha=mean_alpha,
        box=box,
        area=area,
        beams=beams,
        n_beams=counts,
        first_point=first_point,
        last_point=last_point,
        chord_centre=chord,
        radius=radius,
        edge_start=codes[:, 0],
        edge_end=codes[:, 1],
        pose=(float(x_r), float(y_r), float(th_r)),
        cell=cell,
    )


def _split_runs(starts: IntArray, ends: IntArray, cuts: IntArray
                ) -> tuple[IntArray, IntArray, npt.NDArray[np.bool_], npt.NDArray[np.bool_]]:
    """The runs ``starts``..``ends`` (window indices, inclusive) cut before each of
    ``cuts`` that falls inside one: the new starts and ends, and which runs start at a
    cut and which end just before one."""
    inside = np.asarray(cuts, dtype=np.int64)
    run = np.searchsorted(starts, inside, side="right") - 1
    inside = inside[(run >= 0) & (inside > starts[np.maximum(run, 0)])
                    & (inside <= ends[np.maximum(run, 0)])]
    new_starts = np.union1d(starts, inside)
    owner = np.searchsorted(starts, new_starts, side="right") - 1
    new_ends = ends[owner].copy()
    new_ends[:-1] = np.minimum(new_ends[:-1], new_starts[1:] - 1)
    cut_start = np.isin(new_starts, inside)
    cut_end = np.isin(new_ends + 1, inside)
    return new_starts, new_ends, cut_start, cut_end


def moving_cuts(starts: IntArray, ends: IntArray, entered: npt.NDArray[np.bool_],
                stayed: npt.NDArray[np.bool_], points: FloatArray, min_moving: int,
                still_span: float) -> IntArray:
    """Where a cluster holds a mover pressed against something that stands: the window
    points (indices) at which to cut it.

    Beyond the paper. A walker that passes a door's jamb or a wall closer than Eq. 3's
    threshold joins the standing obstacle's cluster: the wall's track covers its
    returns, and its own track goes on as a prediction only. The scans before tell the
    two apart: the walker's points lie where an earlier
    scan saw free space (``entered``, the motion cue's test) and the wall's where the
    oldest scan compared with had a surface (``stayed``). Each cluster (window points
    ``starts[i]..ends[i]``) is cut on either side of every run of at least
    ``min_moving`` consecutive points that entered and did not stay, where that side
    holds at least ``min_moving`` points that stayed, spread over ``still_span`` m or
    more: a walker's own trailing points can have stayed, but never over more than its
    width."""
    # One compiled pass over the clusters' points (``_loops.moving_cuts``); a point
    # starts at most one cut, so the points' count bounds the cuts.
    cuts = np.empty(entered.shape[0], dtype=np.int64)
    found = _loops.moving_cuts(np.ascontiguousarray(starts, dtype=np.int64),
                               np.ascontiguousarray(ends, dtype=np.int64),
                               np.ascontiguousarray(entered).view(np.uint8),
                               np.ascontiguousarray(stayed).view(np.uint8),
                               np.ascontiguousarray(points, dtype=np.float64), min_moving,
                               still_span, cuts)
    return cuts[:found]


def _run_selector(starts: IntArray, counts: IntArray) -> IntArray:
    """Indices of the points of the kept runs, run after run."""
    total = int(counts.sum())
    offs = np.concatenate(([0], np.cumsum(counts)[:-1]))
    return np.arange(total) - np.repeat(offs - starts, counts)


def _edge_codes(
    r: FloatArray,
    valid: npt.NDArray[np.bool_],
    beams: IntArray,
    angle_increment: float,
    params: PerceptionParams,
) -> IntArray:
    """(k, 2) codes for what lies beside each end of each cluster (before first, after last).

    The neighbouring beam (first - 1, last + 1) is looked at:

    * outside the scan -> EDGE_CLIPPED (the obstacle may go on outside the field of view);
    * no return -> EDGE_FREE;
    * a return beyond the window that would have joined the cluster (Eq. 3) -> EDGE_CLIPPED;
    * a return nearer than the edge point by more than the join threshold -> EDGE_OCCLUDED;
    * anything else (background behind, or a surface that did not join) -> EDGE_FREE.
    """
    codes = np.empty((beams.shape[0], 2), dtype=np.int64)
    # Eq. 3 of the larger range (would the neighbour have joined?) and of the end's own
    # range (is the neighbour nearer by more than that?); the distance between the two
    # points by the law of cosines (the angle between them is known). One compiled pass.
    _loops.edge_codes(r, valid.view(np.uint8), beams, params.lambda_,
                      math.sin(abs(angle_increment)), params.gap_floor,
                      2.0 * math.cos(angle_increment), params.window_radius, codes)
    return codes
