# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False
"""Tracking's compiled arithmetic (Cython, built at install): the paper's Eqs. 7-14 pair
by pair, and the gated distances the association is solved on.

Each equation is one ``cpdef`` function, callable from Python (the equation tests pin
these very functions) and called in C by :func:`best_match`, which runs them over every
(current, previous) pair of two chains. The floating-point operations are those of the
numpy code they replaced, in the same order: the same inputs give the same bits. The
areas S_k come in from ``clustering.box_area`` (Eq. 6 has one home). ``_loops.pyi``
gives the types; ``correlation.py`` documents the decisions the paper leaves open."""

import numpy as np

from cpython.mem cimport PyMem_Free, PyMem_Malloc
from libc.math cimport INFINITY, hypot, sqrt


ctypedef (long long, long long, long long, long long) Box
ctypedef (double, double) Point


cpdef long long overlap_cells(Box a, Box b):
    """Eqs. 7-9: grid cells shared by two inclusive boxes ``(ix_min, ix_max, iy_min,
    iy_max)``, 0 when disjoint.

    Eq. 8: disjoint when one box's max is below the other's min on x or on y. Eq. 9:
    sorting the four x bounds x_b1 <= x_b2 <= x_b3 <= x_b4 of overlapping boxes, x_b2 is
    the larger of the two mins and x_b3 the smaller of the two maxes, so the overlap holds
    (x_b3 - x_b2 + 1) * (y_b3 - y_b2 + 1) cells. A negative extent means disjoint and
    counts 0, which covers Eq. 8. Eq. 7 (full overlap) is the case of two equal boxes."""
    cdef long long ex = min(a[1], b[1]) - max(a[0], b[0]) + 1
    cdef long long ey = min(a[3], b[3]) - max(a[2], b[2]) + 1
    if ex < 0:  # Eq. 8
        ex = 0
    if ey < 0:
        ey = 0
    return ex * ey


cpdef long long union_cells(long long area_a, long long area_b, long long inter):
    """Eq. 10: cells covered by either box, S(t) + S(t-1) - S(t) n S(t-1)."""
    return area_a + area_b - inter


cpdef double coincidence(long long inter, long long area_cur):
    """Eq. 11: xi = (S(t) n S(t-1)) / S(t), in [0, 1]."""
    return <double>inter / <double>area_cur


cpdef double non_overlap_rate(long long inter, long long union):
    """Eq. 13: eta = 1 - (S1 n S2) / (S1 u S2): 0 for identical boxes, 1 for disjoint."""
    return 1.0 - <double>inter / <double>union


cpdef double centre_distance(Point a, Point b, double cell):
    """Eq. 13: delta = ||Z_k1(t) - Z_k2(t-1)||, in grid cells (metres / cell)."""
    return hypot(a[0] - b[0], a[1] - b[1]) / cell


cpdef double spatial_correlation(double delta, double eta, double y_delta=0.5,
                                 double y_eta=0.5):
    """Eq. 12: varsigma = y_delta / (delta + 1) + y_eta / (eta + 1).

    With y_delta = y_eta = 0.5, delta >= 0 and eta in [0, 1], varsigma lies in (0.25, 1]:
    1 for the same place and box, 0.25 in the limit of far and disjoint."""
    return y_delta / (delta + 1.0) + y_eta / (eta + 1.0)


def best_match(list centre_cur, list box_cur, list area_cur, list centre_prev,
               list box_prev, list area_prev, double cell, double y_delta=0.5,
               double y_eta=0.5):
    """Eq. 14 for each current obstacle: varsigma_max over the previous chain (the first
    maximum on ties, a nan counting as the largest, as ``np.argmax``), with the index,
    delta and xi of the pair attaining it; Eqs. 9-13 for every pair on the way.

    Chains are lists, one entry per obstacle: Eq. 5 centres ``(x, y)`` (metres), grid
    boxes ``(ix_min, ix_max, iy_min, iy_max)`` and their areas S_k (Eq. 6, cells).
    Returns four lists (varsigma_max, index, delta, xi); with an empty previous chain
    every obstacle gets varsigma_max 0, index -1, delta inf and xi 0."""
    cdef Py_ssize_t n = len(centre_cur)
    cdef Py_ssize_t m = len(centre_prev)
    cdef Py_ssize_t i, j, best_j
    cdef Box bc
    cdef Point cc
    cdef long long ac, inter
    cdef double xi, eta, delta, v, best_v, best_delta, best_xi
    cdef list out_v = [], out_j = [], out_delta = [], out_xi = []
    cdef Box* bp = NULL
    cdef Point* cp = NULL
    cdef long long* ap = NULL
    if m == 0:
        return [0.0] * n, [-1] * n, [INFINITY] * n, [0.0] * n
    bp = <Box*>PyMem_Malloc(m * sizeof(Box))
    cp = <Point*>PyMem_Malloc(m * sizeof(Point))
    ap = <long long*>PyMem_Malloc(m * sizeof(long long))
    if bp == NULL or cp == NULL or ap == NULL:
        PyMem_Free(bp)
        PyMem_Free(cp)
        PyMem_Free(ap)
        raise MemoryError()
    try:
        for j in range(m):
            bp[j] = box_prev[j]
            cp[j] = centre_prev[j]
            ap[j] = area_prev[j]
        for i in range(n):
            bc = box_cur[i]
            cc = centre_cur[i]
            ac = area_cur[i]
            best_j = -1
            best_v = best_delta = best_xi = 0.0
            for j in range(m):
                inter = overlap_cells(bc, bp[j])  # Eqs. 7-9
                xi = coincidence(inter, ac)  # Eq. 11
                eta = non_overlap_rate(inter, union_cells(ac, ap[j], inter))  # Eqs. 10, 13
                delta = centre_distance(cc, cp[j], cell)  # Eq. 13, cells
                v = spatial_correlation(delta, eta, y_delta, y_eta)  # Eq. 12
                if best_j < 0 or v > best_v or v != v:  # Eq. 14
                    best_j, best_v, best_delta, best_xi = j, v, delta, xi
                    if v != v:
                        break
            out_v.append(best_v)
            out_j.append(best_j)
            out_delta.append(best_delta)
            out_xi.append(best_xi)
    finally:
        PyMem_Free(bp)
        PyMem_Free(cp)
        PyMem_Free(ap)
    return out_v, out_j, out_delta, out_xi


def gated_distances(const double[:, ::1] points, list tracks, double gate, double no_match):
    """(n, k) cost of giving cluster point i to track j: their distance when it is within
    the track's gate (its radius + ``gate``), else ``no_match``. ``tracks``: one
    ``(x, y, radius)`` per track, the predicted position."""
    cdef Py_ssize_t n = points.shape[0]
    cdef Py_ssize_t k = len(tracks)
    cdef Py_ssize_t i, j
    cdef double tx, ty, tr, dx, dy, dist
    cost = np.empty((n, k))
    cdef double[:, ::1] c = cost
    for j in range(k):
        tx, ty, tr = tracks[j]
        tr = tr + gate
        for i in range(n):
            dx = points[i, 0] - tx
            dy = points[i, 1] - ty
            dist = sqrt(dx * dx + dy * dy)
            c[i, j] = dist if dist <= tr else no_match
    return cost



def lone_pairs(const double[:, ::1] cost, double no_match):
    """The pairs within their gate (cost < ``no_match``) as each row's column (-1: none),
    when no row and no column has more than one; None when some do (then an assignment
    has to choose between them).

    With lone pairs only, every optimal assignment takes them all: one left out would
    leave its row and column to pairs costing ``no_match`` each (or to nothing), which
    taking it beats by about ``no_match``."""
    cdef Py_ssize_t n = cost.shape[0]
    cdef Py_ssize_t k = cost.shape[1]
    cdef Py_ssize_t i, j, found
    cdef list owner = [-1] * n
    cdef unsigned char* taken = <unsigned char*>PyMem_Malloc(k if k > 0 else 1)
    if taken == NULL:
        raise MemoryError()
    try:
        for j in range(k):
            taken[j] = 0
        for i in range(n):
            found = -1
            for j in range(k):
                if cost[i, j] < no_match:
                    if found >= 0 or taken[j]:
                        return None
                    found = j
                    taken[j] = 1
            if found >= 0:
                owner[i] = found
    finally:
        PyMem_Free(taken)
    return owner
