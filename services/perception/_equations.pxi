# The paper's Eqs. 1, 2, 3 and 6 for compiled code, written once here and included where
# they are used: perception's _loops.pyx (the window, the runs, the edge codes, and the
# array forms that clustering.py's to_global, grid_index, join_threshold and box_area
# call) and the planner's (each beam's direction in the map). So the functions the
# equation tests pin and the loops that run every scan compute each equation by the
# same lines. ``alpha`` is counter-clockwise from the heading (clustering.py's notes).
from libc.math cimport cos, floor, sin


cdef inline double eq1_x(double x_r, double heading, double rho, double alpha) noexcept nogil:
    """Eq. 1, the global x of the point at range ``rho`` and beam angle ``alpha`` seen from
    a robot at x ``x_r`` facing ``heading``."""
    return x_r + rho * cos(heading + alpha)


cdef inline double eq1_y(double y_r, double heading, double rho, double alpha) noexcept nogil:
    """Eq. 1, the global y (as :func:`eq1_x`)."""
    return y_r + rho * sin(heading + alpha)


cdef inline long eq2(double coord, double cell) noexcept nogil:
    """Eq. 2, the grid index floor(coord / cell + 1/2) (cell k is centred on k cell)."""
    return <long>floor(coord / cell + 0.5)


cdef inline double eq3(double rho, double lambda_, double step, double gap_floor) noexcept nogil:
    """Eq. 3, the join threshold lambda rho sin(d_alpha) + gap_floor, ``step`` being
    sin(|d_alpha|) of the scan."""
    return lambda_ * rho * step + gap_floor


cdef inline long eq6(long ix_min, long ix_max, long iy_min, long iy_max) noexcept nogil:
    """Eq. 6, the cells of the inclusive grid box (ix_min, ix_max, iy_min, iy_max)."""
    return (ix_max - ix_min + 1) * (iy_max - iy_min + 1)
