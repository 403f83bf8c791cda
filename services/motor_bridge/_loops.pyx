# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False
"""The stop zone's test over a scan's beams, compiled (Cython, built at install).

``stop_zone.zone_blocked`` ran it as a dozen numpy passes over every beam, twice a scan
(the planner's check, then the motor bridge's). Here it is one loop with the same
floating-point operations, which stops at the first return inside the zone.
``stop_zone.py`` owns the meaning; ``_loops.pyi`` gives the types.
"""

from libc.math cimport fabs


def zone_hit(const double[::1] ranges, const double[::1] cosines,
             const double[::1] sines, double range_max, double length,
             double half_width):
    """Whether a beam's return (a range below ``range_max``; a nan is none) lies at
    ``0 < x <= length`` and ``|y| <= half_width`` in the robot frame, beam b pointing
    along (``cosines[b]``, ``sines[b]``)."""
    cdef Py_ssize_t b
    cdef double r, x
    for b in range(ranges.shape[0]):
        r = ranges[b]
        if r < range_max:
            x = r * cosines[b]
            if x > 0.0 and x <= length and fabs(r * sines[b]) <= half_width:
                return True
    return False
