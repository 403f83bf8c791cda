# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False
"""The planner's two sequential inner loops, compiled (Cython, built at install).

numpy runs these as one pass over whole arrays per step, which costs more in call
overhead than in arithmetic: a ray per beam over the map (about 58,000 samples a scan)
and the unicycle roll-out of every safety candidate over the horizon. Here they are
plain loops with the same floating-point operations, in the same order, as the numpy
code they replaced (angles wrapped by ``_angles.pxi``), so the results are the same to
the bit. The Python callers (``costmap.py``, ``safety.py``) own the
meaning; ``_loops.pyi`` gives their types.
"""

from libc.math cimport cos, floor, sin

include "../_angles.pxi"


def clear_beams(double x, double y, const double[::1] ux, const double[::1] uy,
                const double[::1] reach, double step, double ox, double oy,
                double resolution, Py_ssize_t ny, const unsigned char[::1] returned,
                double stamp, double[::1] seen, unsigned char[::1] occupied,
                unsigned char[::1] walls):
    """Mark free, seen at ``stamp``, every cell of the flat grids (``ny`` cells a
    column) that a point ``s = 0, step, 2 step, ...`` m along a beam from (x, y) falls
    in, up to the beam's ``reach`` (direction ``(ux, uy)``), except the cells
    ``returned`` flags. A cell is found with the arithmetic of ``Costmap.cell_of``."""
    cdef Py_ssize_t nx = seen.shape[0] // ny
    cdef Py_ssize_t b, k, ix, iy, cell
    cdef double s
    for b in range(ux.shape[0]):
        k = 0
        while k * step <= reach[b]:
            s = k * step
            k += 1
            ix = <Py_ssize_t>floor((ux[b] * s + x - ox) / resolution)
            iy = <Py_ssize_t>floor((uy[b] * s + y - oy) / resolution)
            if ix < 0 or ix >= nx or iy < 0 or iy >= ny:
                continue
            cell = ix * ny + iy
            if returned[cell]:
                continue
            seen[cell] = stamp
            occupied[cell] = 0
            walls[cell] = 0


def drive(const double[::1] headings, const double[::1] speeds, double dt, double x0,
          double y0, double theta0, double v0, double gain, double max_omega,
          double accel, double decel, double[:, ::1] xs, double[:, ::1] ys):
    """The unicycle of ``safety.rollout``, candidate by candidate, step by step, into
    ``xs`` and ``ys`` (n, k): the heading error wrapped as ``wrap_angles`` does, the
    turn rate and the speed clipped to their limits."""
    cdef double x, y, theta, v, error, omega, wanted, c
    cdef Py_ssize_t i, k
    for i in range(headings.shape[0]):
        x, y, theta, v = x0, y0, theta0, v0
        for k in range(xs.shape[1]):
            error = wrap_angle(headings[i] - theta)
            omega = min(max(gain * error, -max_omega), max_omega)
            c = cos(error)
            wanted = speeds[i] * (c if c > 0.0 else 0.0)
            v = min(max(wanted, v - decel * dt), v + accel * dt)
            theta = theta + omega * dt
            x = x + v * cos(theta) * dt
            y = y + v * sin(theta) * dt
            xs[i, k] = x
            ys[i, k] = y
