"""Did an obstacle move? A free-space test between this scan and an earlier one.

Beyond the paper. The paper tells moving from standing obstacles by how much their grid
areas overlap from one frame to the next; at 10 Hz a walker moves a tenth of a cell per
frame, so that test only sees fast movers, and a speed estimate from the cluster centre
is fooled by the robot's own motion: as the robot drives past a box, the part of it in
view changes and its centre slides along, at about the robot's speed.

This test does not look at centres. A standing obstacle never occupies space that an
earlier scan saw to be empty, and never leaves empty the space where an earlier scan hit
it. So, for each cluster of the current scan:

- *entered*: the share of its points that lie where an earlier scan's beams passed
  through (its beams toward them reached farther by more than ``margin``);
- *vacated*: the share of the earlier scan's points near it that the current scan's beams
  now pass through.

The score is the larger of the two. The robot's own motion does not matter, since every
point is compared in the global frame by casting it into the other scan's beams. A
surface first seen now was hidden or out of view before, not free, so a new face of a box
scores nothing. Each beam is compared with its two neighbours and the nearest of the three
is used, so grazing surfaces and beam rounding do not read as free space.
"""

from __future__ import annotations

from bisect import bisect_right
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from zenav.services.perception import _loops
from zenav.services.perception.clustering import Window, scan_window, to_global

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]


@dataclass(frozen=True)
class ScanSnapshot:
    """One scan with the pose it was taken from (global frame)."""

    stamp: float
    pose: tuple[float, float, float]
    ranges: FloatArray  # no return = range_max
    angle_min: float
    angle_increment: float
    range_max: float

    def points(self, beams: IntArray) -> FloatArray:
        """(k, 2) global points of ``beams`` (Eq. 1, the one perception clusters with)."""
        alpha = self.angle_min + beams * self.angle_increment
        return np.column_stack(to_global(self.pose, self.ranges[beams], alpha))


def seen_free(scan: ScanSnapshot, points: FloatArray, margin: float) -> npt.NDArray[np.bool_]:
    """Whether ``scan`` saw each global point (k, 2) as empty space: the beams toward it
    (and both neighbours) reached more than ``margin`` beyond it (compiled:
    ``_loops.seen_free``)."""
    x, y, heading = scan.pose
    out = np.empty(points.shape[0], dtype=np.bool_)
    _loops.seen_free(np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2), x, y,
                     heading, np.ascontiguousarray(scan.ranges, dtype=np.float64),
                     scan.angle_min, scan.angle_increment, margin, out.view(np.uint8))
    return out


@dataclass(frozen=True)
class ClusterPoints:
    """The current scan's clustered window points, as every comparison with an earlier
    scan needs them: computed once per scan, whatever the number of baselines."""

    n: int  # clusters
    member: IntArray  # cluster of each point
    points: FloatArray  # (k, 2) global points of the clustered window beams
    counts: IntArray  # (n,) points per cluster
    lo: FloatArray  # (n, 2) each cluster's bounding box, widened by ``reach``
    hi: FloatArray


def cluster_points(current: ScanSnapshot, cluster_beams: IntArray, window_beams: IntArray,
                   reach: float, window_points: FloatArray | None = None
                   ) -> ClusterPoints | None:
    """The clustered points of ``current`` (None when no cluster has a window beam).

    A window beam belongs to the cluster whose beam span holds it; each cluster's box is
    the bounding box of its points widened by ``reach`` (compiled, one pass:
    ``_loops.group_points``)."""
    n = len(cluster_beams)
    if n == 0 or len(window_beams) == 0:
        return None
    beams = np.ascontiguousarray(window_beams, dtype=np.int64)
    if window_points is None:
        window_points = current.points(beams)
    m = beams.shape[0]
    member = np.empty(m, dtype=np.int64)
    points = np.empty((m, 2))
    counts = np.zeros(n, dtype=np.int64)
    lo = np.empty((n, 2))
    hi = np.empty((n, 2))
    kept = _loops.group_points(np.ascontiguousarray(cluster_beams, dtype=np.int64), beams,
                               np.ascontiguousarray(window_points, dtype=np.float64),
                               current.ranges.shape[0], reach, member, points, counts, lo, hi)
    if kept == 0:
        return None
    return ClusterPoints(n, member[:kept], points[:kept], counts, lo, hi)


def scores_against(clustered: ClusterPoints, current: ScanSnapshot, past: ScanSnapshot,
                   past_points: FloatArray, margin: float) -> FloatArray:
    """(n,) score in [0, 1] per cluster of ``clustered`` against the earlier scan
    ``past`` (``past_points``: the global points of its window beams): the larger of
    the share of its points that ``past`` saw as free space (*entered*) and the share of
    the earlier points inside its widened box, two at least, that ``current`` sees
    through (*vacated*). Compiled, one pass over the points (``_loops.free_scores``,
    with the test of :func:`seen_free`)."""
    scores = np.empty(clustered.n)
    px, py, ph = past.pose
    x, y, heading = current.pose
    _loops.free_scores(clustered.points, clustered.member, clustered.counts, px, py, ph,
                       np.ascontiguousarray(past.ranges, dtype=np.float64), past.angle_min,
                       past.angle_increment,
                       np.ascontiguousarray(past_points, dtype=np.float64).reshape(-1, 2),
                       x, y, heading, np.ascontiguousarray(current.ranges, dtype=np.float64),
                       current.angle_min, current.angle_increment, clustered.lo, clustered.hi,
                       margin, scores)
    return scores


class MotionCue:
    """Keeps the recent scans and scores each new scan's clusters against them."""

    def __init__(self, baselines: tuple[float, ...], margin: float, reach: float,
                 window_radius: float) -> None:
        self.baselines = tuple(sorted(baselines))
        self.margin = margin
        self.reach = reach
        self.window_radius = window_radius
        self._scans: list[tuple[ScanSnapshot, IntArray, FloatArray]] = []
        self._stamps: list[float] = []  # theirs, in the same order

    def score(self, scan: ScanSnapshot, range_min: float, cluster_beams: IntArray) -> FloatArray:
        """Scores for this scan's clusters (max over the baselines), then remember it."""
        each, _ = self.score_each(scan, range_min, cluster_beams)
        best: FloatArray = each.max(axis=1, initial=0.0)
        return best

    def score_each(self, scan: ScanSnapshot, range_min: float, cluster_beams: IntArray,
                   window: Window | None = None) -> tuple[FloatArray, FloatArray]:
        """(n, k) scores of this scan's clusters against each baseline's earlier scan, and
        (k,) the stamps of those scans (nan where none is remembered yet); then remember
        this scan. A consumer that knows when an obstacle was first seen can ignore the
        comparisons with scans taken before: an obstacle that appeared out of nothing
        occupies space those scans saw empty without having moved. ``window``: the scan's
        window (:func:`scan_window` with this cue's ``window_radius``) when the caller
        has it already, as perception does from clustering."""
        if window is None:
            window = scan_window(scan.ranges, scan.angle_min, scan.angle_increment, range_min,
                                 scan.range_max, scan.pose, self.window_radius)
        scores, stamps = self.scores(scan, cluster_beams, window)
        # The window's global points, once per scan, kept for the scans after it.
        self._scans.append((scan, window.beams, window.points))
        self._stamps.append(scan.stamp)
        oldest = scan.stamp - self.baselines[-1] - 1.0
        drop = 0
        while len(self._stamps) - drop > 1 and self._stamps[drop + 1] <= oldest:
            drop += 1
        if drop:
            del self._scans[:drop], self._stamps[:drop]
        return scores, stamps

    def scores(self, scan: ScanSnapshot, cluster_beams: IntArray, window: Window
               ) -> tuple[FloatArray, FloatArray]:
        """:meth:`score_each`'s scores and stamps, the scan not remembered: for clusters
        of a scan remembered already (perception's, once it has cut one), the baselines'
        scans are the same, all older than it."""
        scores = np.zeros((len(cluster_beams), len(self.baselines)))
        stamps = np.full(len(self.baselines), np.nan)
        # The clusters' points and boxes once, for every baseline.
        clustered = cluster_points(scan, cluster_beams, window.beams, self.reach,
                                   window.points)
        for j, baseline in enumerate(self.baselines):
            past = self._at_least(scan.stamp - baseline)
            if past is not None:
                stamps[j] = past[0].stamp
                if clustered is not None:
                    scores[:, j] = scores_against(clustered, scan, past[0], past[2],
                                                  self.margin)
        return scores, stamps

    def point_motion(self, stamp: float, points: FloatArray
                     ) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.bool_]] | None:
        """For each global point (k, 2) of the scan stamped ``stamp`` (remembered
        already or not), against the scan of the longest baseline: whether that scan saw it
        as free space (*entered*, the test of :func:`seen_free`), and whether it had a
        surface within ``margin`` of it (*stayed*: something stood there that long
        ago). One compiled pass (``_loops.free_or_hit``). None until a scan that old
        is remembered."""
        oldest = self._at_least(stamp - self.baselines[-1])
        if oldest is None:
            return None
        scan = oldest[0]
        points = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2)
        entered = np.empty(points.shape[0], dtype=np.bool_)
        stayed = np.empty(points.shape[0], dtype=np.bool_)
        _loops.free_or_hit(points, *scan.pose, scan.ranges, scan.angle_min,
                           scan.angle_increment, self.margin, entered.view(np.uint8),
                           stayed.view(np.uint8))
        return entered, stayed

    def _at_least(self, stamp: float) -> tuple[ScanSnapshot, IntArray, FloatArray] | None:
        """The newest remembered scan taken at or before ``stamp`` (scans come in the
        order of their stamps, as perception's stamp gate lets them through)."""
        i = bisect_right(self._stamps, stamp + 1e-9)
        return self._scans[i - 1] if i > 0 else None
