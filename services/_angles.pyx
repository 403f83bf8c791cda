# cython: language_level=3, boundscheck=False, wraparound=False
"""The compiled loops' angle wrap (``_angles.pxi``), callable from Python for the tests
that pin it to ``geometry.wrap_angles``."""

import numpy as np

include "_angles.pxi"


def wrap_angles(const double[::1] angles):
    """``wrap_angle`` of every element, as a new array."""
    out = np.empty(angles.shape[0])
    cdef double[::1] view = out
    cdef Py_ssize_t i
    for i in range(angles.shape[0]):
        view[i] = wrap_angle(angles[i])
    return out
