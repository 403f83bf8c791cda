# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False
"""Perception's compiled inner loop (Cython, built at install): the motion cue's
free-space test, point by point, with the floating-point operations of the numpy code it
replaced, in the same order (the bearing wrapped by ``_angles.pxi``).
``motion_cue.seen_free`` owns the meaning; ``_loops.pyi`` gives the types."""

from libc.math cimport atan2, hypot, rint

include "../_angles.pxi"


def seen_free(const double[:, ::1] points, double x, double y, double heading,
              const double[::1] ranges, double angle_min, double angle_increment,
              double margin, unsigned char[::1] out):
    """For each point, whether the beams toward it and both neighbours reached more
    than ``margin`` beyond it: the beam
    the nearest to it (half to even, as ``np.rint``)."""
    cdef Py_ssize_t n = ranges.shape[0]
    cdef Py_ssize_t i, b
    cdef double dx, dy, distance, bearing, beam, reach
    for i in range(points.shape[0]):
        dx = points[i, 0] - x
        dy = points[i, 1] - y
        distance = hypot(dx, dy)
        bearing = wrap_angle(atan2(dy, dx) - heading)
        beam = rint((bearing - angle_min) / angle_increment)
        if not (1 <= beam <= n - 2):  # (a nan point: no beam either)
            out[i] = 0
            continue
        b = <Py_ssize_t>beam
        reach = min(ranges[b - 1], ranges[b], ranges[b + 1])
        out[i] = reach > distance + margin


def count_in_boxes(const double[:, ::1] points, const unsigned char[::1] flags,
                   const double[:, ::1] lo, const double[:, ::1] hi, long[::1] inside,
                   long[::1] flagged):
    """For each box (closed, ``lo`` to ``hi``), how many of the points lie in it
    (``inside``) and how many of those are flagged (``flagged``), both added to."""
    cdef Py_ssize_t i, c
    cdef double px, py
    for i in range(points.shape[0]):
        px = points[i, 0]
        py = points[i, 1]
        for c in range(lo.shape[0]):
            if lo[c, 0] <= px <= hi[c, 0] and lo[c, 1] <= py <= hi[c, 1]:
                inside[c] += 1
                if flags[i]:
                    flagged[c] += 1
