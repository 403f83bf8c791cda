# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False
"""Perception's compiled inner loops (Cython, built at install): the clustering's
passes over the scan, its points and runs (the window, the Eq. 3 cuts, each run's box,
end points and radius, the edge codes) and the motion cue's (the free-space test, point
by point, the grouping of a scan's points by cluster and the scores against an earlier
scan), with the floating-point operations of the numpy code they replaced, in the same
order (the bearing wrapped by ``_angles.pxi``); and, written here first, the cut of a
mover out of a standing obstacle's cluster (``free_or_hit``, ``moving_cuts``). The
paper's Eqs. 1, 2, 3 and 6 are written once, in ``_equations.pxi``; the array forms
here are what ``clustering.py``'s equation functions call. ``clustering.py`` and ``motion_cue.py`` own the meaning;
``_loops.pyi`` gives the types."""

import numpy as np

from libc.math cimport INFINITY, atan2, fabs, hypot, rint, sqrt
from libc.stdlib cimport calloc, free

include "../_angles.pxi"
include "_equations.pxi"


cdef inline Py_ssize_t nearest_beam(double dx, double dy, double heading, Py_ssize_t n,
                                    double angle_min, double angle_increment) noexcept:
    """The beam of a scan of ``n`` taken at ``heading`` nearest the direction (``dx``,
    ``dy``) (half to even, as ``np.rint``); -1 where there is none (outside the scan, or
    a nan point)."""
    cdef double bearing = wrap_angle(atan2(dy, dx) - heading)
    cdef double beam = rint((bearing - angle_min) / angle_increment)
    if beam < 0:  # a full-circle scan started past -pi (perception's seam turn)
        beam += rint(2.0 * M_PI / fabs(angle_increment))
    if not (0 <= beam <= n - 1):
        return -1
    return <Py_ssize_t>beam


cdef inline bint free_at(double px, double py, double x, double y, double heading,
                        const double[::1] ranges, double angle_min, double angle_increment,
                        double margin) noexcept:
    """Whether the beam nearest the point and both its neighbours reached more than
    ``margin`` beyond it (a nan point: no beam)."""
    cdef Py_ssize_t n = ranges.shape[0]
    cdef double dx = px - x
    cdef double dy = py - y
    cdef Py_ssize_t b = nearest_beam(dx, dy, heading, n, angle_min, angle_increment)
    if not (1 <= b <= n - 2):
        return False
    return min(ranges[b - 1], ranges[b], ranges[b + 1]) > hypot(dx, dy) + margin


def free_or_hit(const double[:, ::1] points, double x, double y, double heading,
                const double[::1] ranges, double angle_min, double angle_increment,
                double margin, unsigned char[::1] free, unsigned char[::1] hit):
    """For each point, whether the beam nearest it and both neighbours reached more than
    ``margin`` beyond it (``free``, as ``free_at``), and whether one of those three
    ended within ``margin`` of it (``hit``: a surface was there). A point with no beam
    toward it (outside the scan, or nan) is neither."""
    cdef Py_ssize_t n = ranges.shape[0]
    cdef Py_ssize_t i, b, j
    cdef double dx, dy, distance
    for i in range(points.shape[0]):
        dx = points[i, 0] - x
        dy = points[i, 1] - y
        distance = hypot(dx, dy)
        b = nearest_beam(dx, dy, heading, n, angle_min, angle_increment)
        free[i] = 1 <= b <= n - 2 and min(ranges[b - 1], ranges[b],
                                          ranges[b + 1]) > distance + margin
        hit[i] = 0
        if b < 0:
            continue
        for j in range(max(b - 1, 0), min(b + 2, n)):
            if fabs(ranges[j] - distance) <= margin:
                hit[i] = 1
                break


def seen_free(const double[:, ::1] points, double x, double y, double heading,
              const double[::1] ranges, double angle_min, double angle_increment,
              double margin, unsigned char[::1] out):
    """For each point, whether the beams toward it and both neighbours reached more
    than ``margin`` beyond it: the beam
    the nearest to it (half to even, as ``np.rint``)."""
    cdef Py_ssize_t i
    for i in range(points.shape[0]):
        out[i] = free_at(points[i, 0], points[i, 1], x, y, heading, ranges, angle_min,
                         angle_increment, margin)


cdef bint still_side(const unsigned char[::1] stayed, const double[:, ::1] points,
                     Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t least, double span) noexcept:
    """Whether at least ``least`` of the points ``lo..hi - 1`` stayed, the first and
    last of them ``span`` m or more apart."""
    cdef Py_ssize_t j
    cdef Py_ssize_t first = -1
    cdef Py_ssize_t last = -1
    cdef Py_ssize_t count = 0
    for j in range(lo, hi):
        if stayed[j]:
            if first < 0:
                first = j
            last = j
            count += 1
    if count < least:
        return False
    return hypot(points[last, 0] - points[first, 0], points[last, 1] - points[first, 1]) >= span


def moving_cuts(const long[::1] starts, const long[::1] ends,
                const unsigned char[::1] entered, const unsigned char[::1] stayed,
                const double[:, ::1] points, Py_ssize_t min_moving, double still_span,
                long[::1] cuts):
    """The cuts of ``clustering.moving_cuts`` (which owns their meaning), in ascending
    order, into ``cuts``; returns how many. A point moved where it ``entered`` and did
    not stay."""
    cdef Py_ssize_t i, j, a, s, e
    cdef Py_ssize_t found = 0
    for i in range(starts.shape[0]):
        s = starts[i]
        e = ends[i] + 1
        j = s
        while j < e:
            if not entered[j] or stayed[j]:
                j += 1
                continue
            a = j
            while j < e and entered[j] and not stayed[j]:
                j += 1
            if j - a < min_moving:
                continue
            if still_side(stayed, points, s, a, min_moving, still_span):
                cuts[found] = a
                found += 1
            if still_side(stayed, points, j, e, min_moving, still_span):
                cuts[found] = j
                found += 1
    return found


def group_points(const long[:, ::1] cluster_beams, const long[::1] window_beams,
                 const double[:, ::1] window_points, Py_ssize_t n_beams, double reach,
                 long[::1] member, double[:, ::1] points, long[::1] counts,
                 double[:, ::1] lo, double[:, ::1] hi):
    """The window points that belong to a cluster (beams ``first..last`` of its row in
    ``cluster_beams``; a later row wins a beam two rows hold), in window order: the
    cluster of each (``member``), the point (``points``), the points per cluster
    (``counts``, added to) and each cluster's bounding box widened by ``reach``
    (``lo``, ``hi``; a cluster without points keeps +inf / -inf). Returns how many
    points were kept (the rows of ``member`` and ``points`` filled)."""
    cdef Py_ssize_t k, b, i, c
    cdef Py_ssize_t kept = 0
    cdef long[::1] owner = np.full(n_beams, -1, dtype=np.int64)
    for k in range(cluster_beams.shape[0]):
        for b in range(max(cluster_beams[k, 0], 0), min(cluster_beams[k, 1] + 1, n_beams)):
            owner[b] = k
    for c in range(lo.shape[0]):
        lo[c, 0] = INFINITY
        lo[c, 1] = INFINITY
        hi[c, 0] = -INFINITY
        hi[c, 1] = -INFINITY
    for i in range(window_beams.shape[0]):
        c = owner[window_beams[i]]
        if c < 0:
            continue
        member[kept] = c
        points[kept, 0] = window_points[i, 0]
        points[kept, 1] = window_points[i, 1]
        counts[c] += 1
        lo[c, 0] = min(lo[c, 0], window_points[i, 0])
        lo[c, 1] = min(lo[c, 1], window_points[i, 1])
        hi[c, 0] = max(hi[c, 0], window_points[i, 0])
        hi[c, 1] = max(hi[c, 1], window_points[i, 1])
        kept += 1
    for c in range(lo.shape[0]):
        lo[c, 0] -= reach
        lo[c, 1] -= reach
        hi[c, 0] += reach
        hi[c, 1] += reach
    return kept


def free_scores(const double[:, ::1] points, const long[::1] member, const long[::1] counts,
                double past_x, double past_y, double past_heading,
                const double[::1] past_ranges, double past_angle_min,
                double past_angle_increment, const double[:, ::1] past_points,
                double x, double y, double heading, const double[::1] ranges,
                double angle_min, double angle_increment, const double[:, ::1] lo,
                const double[:, ::1] hi, double margin, double[::1] scores):
    """Per cluster, the larger of the share of its points (``points`` of cluster
    ``member``, ``counts`` per cluster) that the earlier scan saw as free space
    (``free_at`` its pose and ranges), and the share of the earlier scan's points
    (``past_points``, when there are two or more) inside its box (``lo`` to ``hi``,
    closed) that the current scan sees through; 0 with no points or fewer than two
    inside. ``scores`` is filled."""
    cdef Py_ssize_t n = counts.shape[0]
    cdef Py_ssize_t i, c
    cdef double px, py, share
    cdef bint vacated = False
    cdef bint tested
    # Three counters per cluster in one C buffer (numpy arrays cost more to make than
    # the loops below take on a chain of a few clusters).
    cdef long *entered = <long *> calloc(3 * n + 1, sizeof(long))
    cdef long *near
    cdef long *gone
    if entered == NULL:
        raise MemoryError()
    near = entered + n
    gone = near + n
    try:
        for i in range(points.shape[0]):
            if free_at(points[i, 0], points[i, 1], past_x, past_y, past_heading, past_ranges,
                       past_angle_min, past_angle_increment, margin):
                entered[member[i]] += 1
        for c in range(n):
            scores[c] = <double>entered[c] / <double>counts[c] if counts[c] > 0 else 0.0
        if past_points.shape[0] < 2:
            return
        for i in range(past_points.shape[0]):
            px = past_points[i, 0]
            py = past_points[i, 1]
            tested = False  # the free-space test only for a point inside some box
            for c in range(n):
                if lo[c, 0] <= px <= hi[c, 0] and lo[c, 1] <= py <= hi[c, 1]:
                    if not tested:
                        vacated = free_at(px, py, x, y, heading, ranges, angle_min,
                                          angle_increment, margin)
                        tested = True
                    near[c] += 1
                    if vacated:
                        gone[c] += 1
        for c in range(n):
            if near[c] >= 2:
                share = <double>gone[c] / <double>near[c]
                if share > scores[c]:
                    scores[c] = share
    finally:
        free(entered)


def to_global_into(double x, double y, double heading, const double[::1] rho,
                   const double[::1] alpha, double[::1] gx, double[::1] gy):
    """Eq. 1 (``_equations.pxi``) for each (rho, alpha) seen from the robot at (x, y,
    heading), into ``gx`` and ``gy``: ``clustering.to_global``."""
    cdef Py_ssize_t i
    for i in range(rho.shape[0]):
        gx[i] = eq1_x(x, heading, rho[i], alpha[i])
        gy[i] = eq1_y(y, heading, rho[i], alpha[i])


def to_global_rows(double x, double y, double heading, const double[::1] rho,
                   const double[::1] alpha, double[:, ::1] out):
    """Eq. 1 as :func:`to_global_into`, into the rows (x, y) of ``out``."""
    cdef Py_ssize_t i
    for i in range(rho.shape[0]):
        out[i, 0] = eq1_x(x, heading, rho[i], alpha[i])
        out[i, 1] = eq1_y(y, heading, rho[i], alpha[i])


def grid_index_into(const double[::1] coord, double cell, long[::1] out):
    """Eq. 2 (``_equations.pxi``) of each coordinate: ``clustering.grid_index``."""
    cdef Py_ssize_t i
    for i in range(coord.shape[0]):
        out[i] = eq2(coord[i], cell)


def join_threshold_into(const double[::1] rho, double lambda_, double step, double gap_floor,
                        double[::1] out):
    """Eq. 3 (``_equations.pxi``) of each range: ``clustering.join_threshold``."""
    cdef Py_ssize_t i
    for i in range(rho.shape[0]):
        out[i] = eq3(rho[i], lambda_, step, gap_floor)


cpdef long box_area(long ix_min, long ix_max, long iy_min, long iy_max):
    """Eq. 6 (``_equations.pxi``) of one grid box: ``clustering.box_area``."""
    return eq6(ix_min, ix_max, iy_min, iy_max)


def box_areas_into(const long[:, ::1] boxes, long[::1] out):
    """Eq. 6 of each row of ``boxes``: ``clustering.box_area`` of an array."""
    cdef Py_ssize_t i
    for i in range(boxes.shape[0]):
        out[i] = eq6(boxes[i, 0], boxes[i, 1], boxes[i, 2], boxes[i, 3])


def window_points(const double[::1] ranges, double angle_min, double angle_increment,
                  double range_min, double range_max, double window_radius, double x,
                  double y, double heading, unsigned char[::1] valid, long[::1] beams,
                  double[::1] rho, double[::1] alpha, double[::1] px, double[::1] py,
                  double[:, ::1] xy):
    """The window of ``clustering.scan_window`` in one pass: into ``valid`` whether each
    beam has a return (``range_min <= r < range_max``; nan has none), and, filled from
    the front, the beams with a return within ``window_radius``, their ranges, their
    angles (angle_min + i angle_increment, numpy's arithmetic) and their global points
    by Eq. 1 from the robot at (x, y, heading), in ``px`` and ``py`` and as the rows of
    ``xy``. Returns how many there are."""
    cdef Py_ssize_t i, k = 0
    cdef double r, a
    cdef bint has
    for i in range(ranges.shape[0]):
        r = ranges[i]
        has = r >= range_min and r < range_max
        valid[i] = has
        if has and r <= window_radius:
            a = angle_min + <double>i * angle_increment
            beams[k] = i
            rho[k] = r
            alpha[k] = a
            px[k] = eq1_x(x, heading, r, a)
            py[k] = eq1_y(y, heading, r, a)
            xy[k, 0] = px[k]
            xy[k, 1] = py[k]
            k += 1
    return k


def run_bounds(const double[::1] px, const double[::1] py, const double[::1] rho,
               double lambda_, double step, double gap_floor, long[::1] starts,
               long[::1] ends, long[::1] counts):
    """Cut the chain of points ``(px, py)`` at ranges ``rho`` where two consecutive
    points lie farther apart than Eq. 3's join threshold of the later point (compared
    squared; ``lambda_``, ``step`` = sin|d_alpha| and ``gap_floor`` as
    ``clustering.join_threshold`` takes them): the first and last point and the number
    of points of each run (``starts``, ``ends``, ``counts``, filled from the front).
    Returns the number of runs."""
    cdef Py_ssize_t m = px.shape[0]
    cdef Py_ssize_t i
    cdef Py_ssize_t k = 1
    cdef double dx, dy, t
    starts[0] = 0
    for i in range(1, m):
        dx = px[i] - px[i - 1]
        dy = py[i] - py[i - 1]
        t = eq3(rho[i], lambda_, step, gap_floor)
        if dx * dx + dy * dy > t * t:
            ends[k - 1] = i - 1
            starts[k] = i
            k += 1
    ends[k - 1] = m - 1
    for i in range(k):
        counts[i] = ends[i] - starts[i] + 1
    return k


def run_shapes(const double[::1] px, const double[::1] py, const long[::1] starts,
               const long[::1] ends, double inset, double cell, long[:, ::1] box,
               long[::1] area, double[:, ::1] first_point, double[:, ::1] last_point,
               double[:, ::1] chord, double[::1] radius):
    """For each run of points ``starts[c]..ends[c]``: the grid box (Eq. 2 of each edge:
    ix_min, ix_max, iy_min, iy_max) of its bounding box shrunk by ``inset`` on each side,
    never past its middle, and that box's Eq. 6 ``area``; its first and last point,
    their midpoint (``chord``) and the largest distance from that midpoint to a point of
    the run (``radius``)."""
    cdef Py_ssize_t c, i
    cdef double lo_x, hi_x, lo_y, hi_y, in_x, in_y, cx, cy, ex, ey, d2, far
    for c in range(starts.shape[0]):
        lo_x = hi_x = px[starts[c]]
        lo_y = hi_y = py[starts[c]]
        for i in range(starts[c] + 1, ends[c] + 1):
            lo_x = min(lo_x, px[i])
            hi_x = max(hi_x, px[i])
            lo_y = min(lo_y, py[i])
            hi_y = max(hi_y, py[i])
        in_x = min(inset, (hi_x - lo_x) / 2)
        in_y = min(inset, (hi_y - lo_y) / 2)
        box[c, 0] = eq2(lo_x + in_x, cell)
        box[c, 1] = eq2(hi_x - in_x, cell)
        box[c, 2] = eq2(lo_y + in_y, cell)
        box[c, 3] = eq2(hi_y - in_y, cell)
        area[c] = eq6(box[c, 0], box[c, 1], box[c, 2], box[c, 3])
        first_point[c, 0] = px[starts[c]]
        first_point[c, 1] = py[starts[c]]
        last_point[c, 0] = px[ends[c]]
        last_point[c, 1] = py[ends[c]]
        cx = 0.5 * (px[starts[c]] + px[ends[c]])
        cy = 0.5 * (py[starts[c]] + py[ends[c]])
        chord[c, 0] = cx
        chord[c, 1] = cy
        far = -INFINITY
        for i in range(starts[c], ends[c] + 1):
            ex = px[i] - cx
            ey = py[i] - cy
            d2 = ex * ex + ey * ey
            far = max(far, d2)
        radius[c] = sqrt(far)


def edge_codes(const double[::1] ranges, const unsigned char[::1] valid,
               const long[:, ::1] beams, double lambda_, double step, double gap_floor,
               double cos2, double window_radius, long[:, ::1] codes):
    """The code of what lies beside each end of each cluster (``beams``: first, last
    beam), from the beam beside it (first - 1, last + 1): 2 (clipped) when that beam lies
    outside the scan, or has a return beyond ``window_radius`` within Eq. 3's join
    threshold of the larger of the two ranges of the end point (the distance by the law
    of cosines; ``cos2``: twice the cosine of the beam step); else 1 (occluded) when it
    has a return nearer than the end by more than the join threshold of the end's range;
    else 0. (``lambda_``, ``step`` and ``gap_floor`` as :func:`run_bounds` takes them.)"""
    cdef Py_ssize_t n = ranges.shape[0]
    cdef Py_ssize_t c, j, b
    cdef bint outside, has
    cdef double re, rn, d2, t
    for c in range(beams.shape[0]):
        for j in range(2):
            b = beams[c, j] + (1 if j else -1)
            outside = b < 0 or b >= n
            has = (not outside) and valid[b]
            re = ranges[beams[c, j]]
            rn = ranges[b] if has else 0.0
            d2 = re * re + rn * rn - cos2 * re * rn
            t = eq3(max(re, rn), lambda_, step, gap_floor)
            if outside or (has and rn > window_radius and d2 <= t * t):
                codes[c, j] = 2
            elif has and rn < re - eq3(re, lambda_, step, gap_floor):
                codes[c, j] = 1
            else:
                codes[c, j] = 0
