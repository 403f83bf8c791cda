# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False
"""Perception's compiled inner loops (Cython, built at install): the motion cue's
free-space test, point by point, the grouping of a scan's points by cluster and the
scores against an earlier scan, with the floating-point operations of the numpy code
they replaced, in the same order (the bearing wrapped by ``_angles.pxi``).
``motion_cue.py`` owns the meaning; ``_loops.pyi`` gives the types."""

import numpy as np

from libc.math cimport INFINITY, atan2, hypot, rint

include "../_angles.pxi"


cdef inline bint free_at(double px, double py, double x, double y, double heading,
                        const double[::1] ranges, double angle_min, double angle_increment,
                        double margin) noexcept:
    """Whether the beam nearest the point (half to even, as ``np.rint``) and both its
    neighbours reached more than ``margin`` beyond it (a nan point: no beam)."""
    cdef Py_ssize_t n = ranges.shape[0]
    cdef Py_ssize_t b
    cdef double dx = px - x
    cdef double dy = py - y
    cdef double distance = hypot(dx, dy)
    cdef double bearing = wrap_angle(atan2(dy, dx) - heading)
    cdef double beam = rint((bearing - angle_min) / angle_increment)
    if not (1 <= beam <= n - 2):
        return False
    b = <Py_ssize_t>beam
    return min(ranges[b - 1], ranges[b], ranges[b + 1]) > distance + margin


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
    cdef bint vacated
    cdef long[::1] entered = np.zeros(n, dtype=np.int64)
    cdef long[::1] near = np.zeros(n, dtype=np.int64)
    cdef long[::1] gone = np.zeros(n, dtype=np.int64)
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
        vacated = free_at(px, py, x, y, heading, ranges, angle_min, angle_increment, margin)
        for c in range(n):
            if lo[c, 0] <= px <= hi[c, 0] and lo[c, 1] <= py <= hi[c, 1]:
                near[c] += 1
                if vacated:
                    gone[c] += 1
    for c in range(n):
        if near[c] >= 2:
            share = <double>gone[c] / <double>near[c]
            if share > scores[c]:
                scores[c] = share
