# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False
"""The planner's sequential inner loops, compiled (Cython, built at install).

numpy ran these as one pass over whole arrays per step, which costs more in call
overhead than in arithmetic: the map's update from a scan (its marks, a ray per beam
over the map, and the marking), the unicycle roll-out of every safety candidate over
the horizon, and the collision prediction's gaps between the path and each standing
obstacle's grid area; and the small ones numpy ran as a dozen calls on a few numbers
each, several times a scan: the projection on the global path and the point at an arc
length, the map's look-ups along a straight line and along each roll-out. Here they
are plain loops with the same floating-point operations, in the same order, as the
numpy code they replaced (angles wrapped by ``_angles.pxi``, ``hypot``,
``np.linspace``'s points and the floors of the cell indices as numpy has them), so the
results are the same to the bit. The ray tracing alone is not a copy: it walks each
beam's cells one grid line at a time, where the numpy code sampled points every half
cell (about 58,000 a scan of 361 beams out to 8 m, two divisions each). The Python
callers (``costmap.py``, ``safety.py``, ``prediction.py``, ``global_path.py``) own the
meaning; ``_loops.pyi`` gives their types.
"""

import numpy as np

cimport cython
from libc.math cimport INFINITY, cos, fma, hypot, isnan, sin, sqrt
from libc.stdint cimport uint64_t
from libc.string cimport memcmp, memcpy, memset

include "../_angles.pxi"


@cython.cdivision(True)
cdef inline Py_ssize_t cell_index(double offset, double resolution) noexcept nogil:
    """``floor(offset / resolution)`` as an integer, as ``Costmap.cell_of`` has it,
    without a call to ``floor``: the quotient truncated toward zero, one less if that
    is above it (a negative quotient with a fraction). (``resolution`` is never 0: the
    map's own arithmetic divides by it first.)"""
    cdef double q = offset / resolution
    cdef Py_ssize_t i = <Py_ssize_t>q
    return i - (i > q)


cdef inline unsigned char flag_at(double x, double y, double ox, double oy,
                                  double resolution, const unsigned char[::1] grid,
                                  Py_ssize_t nx, Py_ssize_t ny,
                                  unsigned char outside) noexcept nogil:
    """The flag of the cell (x, y) falls in (``Costmap.cell_of``'s arithmetic) in the
    flat grid (``nx`` columns of ``ny`` cells), or ``outside`` beyond it."""
    cdef Py_ssize_t ix = cell_index(x - ox, resolution)
    cdef Py_ssize_t iy = cell_index(y - oy, resolution)
    if (<size_t>ix < <size_t>nx) & (<size_t>iy < <size_t>ny):
        return grid[ix * ny + iy]
    return outside


cdef inline double dot(double ax, double ay, double bx, double by) noexcept nogil:
    """a . b as numpy's ``@`` gives it for two 2-vectors here (its BLAS): the product of
    the x parts, rounded, then the y parts' product added with one rounding, a fused
    multiply-add: fma(a_y, b_y, a_x b_x)."""
    return fma(ay, by, ax * bx)


def floor_quotients(const double[::1] offsets, double resolution, long[::1] out):
    """``cell_index`` of every offset into ``out`` (for the tests that pin it to
    ``np.floor(offsets / resolution)``)."""
    cdef Py_ssize_t i
    for i in range(offsets.shape[0]):
        out[i] = cell_index(offsets[i], resolution)


def return_bounds(double x, double y, const double[::1] ux, const double[::1] uy,
                  const double[::1] ranges, double range_min, double range_max):
    """(x_lo, y_lo, x_hi, y_hi): the box of the robot at (x, y) and every return
    (a range in [range_min, range_max)) at ``x + range * ux``, ``y + range * uy``."""
    cdef double x_lo = x, x_hi = x, y_lo = y, y_hi = y, px, py
    cdef Py_ssize_t b
    for b in range(ranges.shape[0]):
        if not (ranges[b] < range_max and ranges[b] >= range_min):
            continue
        px = x + ranges[b] * ux[b]
        py = y + ranges[b] * uy[b]
        x_lo = min(x_lo, px)
        x_hi = max(x_hi, px)
        y_lo = min(y_lo, py)
        y_hi = max(y_hi, py)
    return x_lo, y_lo, x_hi, y_hi


@cython.cdivision(True)
cdef inline Py_ssize_t grid_lines(double u, double q, double resolution, double* every,
                                  double* first) noexcept nogil:
    """Along one axis, for a beam of direction component ``u`` from a point ``q`` cells
    into its cell (0 to 1): the step of the cell index (1, -1, or 0 along the other
    axis), and through ``every`` and ``first`` the distance along the beam between two
    crossings of this axis's grid lines and to the first one."""
    if u > 0.0:
        every[0] = resolution / u
        first[0] = (1.0 - q) * every[0]
        return 1
    if u < 0.0:
        every[0] = -resolution / u
        first[0] = q * every[0]
        return -1
    every[0] = INFINITY
    first[0] = INFINITY
    return 0


@cython.cdivision(True)
def trace_scan(double x, double y, const double[::1] ux, const double[::1] uy,
               const double[::1] ranges, double range_min, double range_max,
               const double[:, ::1] movers, double ox, double oy, double resolution,
               Py_ssize_t ny, unsigned char[::1] returned, double stamp, double confirm,
               double[::1] seen, unsigned char[::1] occupied, double[::1] hit_since,
               unsigned char[::1] walls):
    """One scan from (x, y) into the flat grids (``ny`` cells a column), as
    ``Costmap.update`` defines it. Beam b points along ``(ux[b], uy[b])``; a range in
    [range_min, range_max) is a return, at ``(x, y) + range * (ux, uy)``.

    1. The cells of the returns, except those within ``resolution`` of a mover disc
       (rows ``(x, y, radius)`` of ``movers``: ``hypot`` to its centre minus its
       radius) or outside the grid, are the marks; ``returned`` (all 0, one byte a
       cell) flags them meanwhile and is all 0 again on return.
    2. Clearing: every cell the segment from (x, y) to the beam's reach passes through
       (the reach: half a cell short of its return, never beyond ``range_max``) is
       seen at ``stamp``, free, and no wall, unless a mark falls in it. The cells are
       walked in order, one cell boundary at a time (Amanatides and Woo's traversal:
       the distance along the beam to the next vertical and the next horizontal grid
       line, the nearer one crossed); where the beam passes exactly through a grid
       corner, the cell across the horizontal line comes first and the diagonal one is
       not visited.
    3. Marking: each marked cell is seen at ``stamp`` and occupied (its occupied spell
       starting now, ``hit_since``, unless it was occupied already), and a wall once
       that spell has lasted ``confirm`` seconds.

    A return's cell is found with the arithmetic of ``Costmap.cell_of``
    (``cell_index``), and so is the robot's, where every walk starts. A walk ends at
    its reach, or at its first cell beyond the grid after one inside it (a straight
    line never comes back).
    """
    cdef Py_ssize_t n = ranges.shape[0]
    cdef Py_ssize_t nx = seen.shape[0] // ny
    cdef Py_ssize_t b, m, ix, iy, cell, count = 0, sx, sy, start_x, start_y
    cdef double step = resolution / 2
    cdef double rho, reach, px, py, qx, qy, tx, ty, dtx, dty
    cdef bint entered
    cdef bint clear_of_movers
    marks = np.empty(n, dtype=np.intp)
    cdef Py_ssize_t[::1] marked = marks
    for b in range(n):
        rho = ranges[b]
        if not (rho < range_max and rho >= range_min):
            continue
        px = x + rho * ux[b]
        py = y + rho * uy[b]
        clear_of_movers = True
        for m in range(movers.shape[0]):
            if not hypot(px - movers[m, 0], py - movers[m, 1]) - movers[m, 2] > resolution:
                clear_of_movers = False
                break
        if not clear_of_movers:
            continue
        ix = cell_index(px - ox, resolution)
        iy = cell_index(py - oy, resolution)
        if not ((<size_t>ix < <size_t>nx) & (<size_t>iy < <size_t>ny)):
            continue
        cell = ix * ny + iy
        marked[count] = cell
        count += 1
        returned[cell] = 1
    # The robot's cell, and where in it the robot stands, in cells (0 to 1 each way).
    start_x = cell_index(x - ox, resolution)
    start_y = cell_index(y - oy, resolution)
    qx = (x - ox) / resolution - start_x
    qy = (y - oy) / resolution - start_y
    for b in range(n):
        rho = ranges[b]
        reach = rho - step if rho < range_max and rho >= range_min else rho
        if reach > range_max:
            reach = range_max
        if not reach >= 0.0:  # a nan, or a return nearer than half a cell: no cell
            continue
        # tx, ty: the distance along the beam at which it crosses the next vertical
        # (horizontal) grid line; dtx, dty: the distance between two such crossings.
        sx = grid_lines(ux[b], qx, resolution, &dtx, &tx)
        sy = grid_lines(uy[b], qy, resolution, &dty, &ty)
        ix, iy = start_x, start_y
        entered = False
        while True:
            if (<size_t>ix < <size_t>nx) & (<size_t>iy < <size_t>ny):
                entered = True
                cell = ix * ny + iy
                if not returned[cell]:
                    seen[cell] = stamp
                    occupied[cell] = 0
                    walls[cell] = 0
            elif entered:
                break
            if tx < ty:
                if tx > reach:
                    break
                ix += sx
                tx += dtx
            else:
                if ty > reach:
                    break
                iy += sy
                ty += dty
    for m in range(count):
        returned[marked[m]] = 0
    for m in range(count):
        cell = marked[m]
        if not occupied[cell]:
            hit_since[cell] = stamp
        seen[cell] = stamp
        occupied[cell] = 1
        if hit_since[cell] <= stamp - confirm:
            walls[cell] = 1


@cython.cdivision(True)
def returns_near(const unsigned char[::1] occupied, const double[::1] seen, Py_ssize_t ny,
                 Py_ssize_t i0, Py_ssize_t i1, Py_ssize_t j0, Py_ssize_t j1, double since,
                 double ox, double oy, double resolution, double ax, double ay, double bx,
                 double by, double distance):
    """Whether a cell of columns ``i0..i1 - 1`` and rows ``j0..j1 - 1`` of the flat grids
    (``ny`` cells a column) is occupied and was seen at ``since`` or later, with its
    centre (``Costmap.centre_of``) within ``distance`` of the segment from (ax, ay) to
    (bx, by): the nearest point of the segment at the clipped projection of the centre
    on it, its gap by ``hypot`` (an infinite ``distance``: any such cell)."""
    cdef Py_ssize_t i, j, cell
    cdef double dx = bx - ax, dy = by - ay
    cdef double length2 = dx * dx + dy * dy
    cdef double rx, ry, t
    for i in range(i0, i1):
        for j in range(j0, j1):
            cell = i * ny + j
            if not occupied[cell] or not seen[cell] >= since:
                continue
            rx = ox + (<double>i + 0.5) * resolution - ax
            ry = oy + (<double>j + 0.5) * resolution - ay
            t = 0.0
            if length2 > 0.0:
                t = min(max((rx * dx + ry * dy) / length2, 0.0), 1.0)
            if hypot(rx - t * dx, ry - t * dy) <= distance:
                return True
    return False


def look_up(const double[:, ::1] points, double ox, double oy, double resolution,
            const unsigned char[::1] grid, Py_ssize_t ny, unsigned char outside,
            unsigned char[::1] out):
    """For each point (x, y), the flag of the cell it falls in (``Costmap.cell_of``'s
    arithmetic) in the flat grid (``ny`` cells a column), or ``outside`` beyond it."""
    cdef Py_ssize_t nx = grid.shape[0] // ny
    cdef Py_ssize_t i
    for i in range(points.shape[0]):
        out[i] = flag_at(points[i, 0], points[i, 1], ox, oy, resolution, grid, nx, ny,
                         outside)


@cython.cdivision(True)
def first_flagged_on(const double[:, ::1] points, const double[::1] lengths,
                     const double[::1] s, double ox, double oy, double resolution,
                     const unsigned char[::1] grid, Py_ssize_t ny, unsigned char outside):
    """The index of the first arc length of ``s`` (non-decreasing) whose point on the
    path (``points``, their non-decreasing arc ``lengths``) falls in a flagged cell of
    the flat grid (``look_up``'s cells; ``outside`` beyond it), -1 when none does. The
    point is ``np.interp(s, lengths, points[:, k])`` for each k, with numpy's
    arithmetic: the ends' values outside the lengths, a vertex's own value at its
    length, else slope (s - length_j) + value_j on segment j (from its far end if
    that gives nan, and the near end's value if both do and the ends are equal)."""
    cdef Py_ssize_t n = lengths.shape[0], nx = grid.shape[0] // ny
    cdef Py_ssize_t i, j = 0, k
    cdef double x, slope
    cdef double at[2]
    for i in range(s.shape[0]):
        x = s[i]
        for k in range(2):
            if isnan(x):
                at[k] = x
            elif x < lengths[0]:
                at[k] = points[0, k]
            elif x >= lengths[n - 1]:
                at[k] = points[n - 1, k]
            else:
                while lengths[j + 1] <= x:  # (x below the last length: j + 1 < n)
                    j += 1
                if lengths[j] == x:
                    at[k] = points[j, k]
                else:
                    slope = ((points[j + 1, k] - points[j, k])
                             / (lengths[j + 1] - lengths[j]))
                    at[k] = slope * (x - lengths[j]) + points[j, k]
                    if isnan(at[k]):
                        at[k] = slope * (x - lengths[j + 1]) + points[j + 1, k]
                        if isnan(at[k]) and points[j, k] == points[j + 1, k]:
                            at[k] = points[j, k]
        if flag_at(at[0], at[1], ox, oy, resolution, grid, nx, ny, outside):
            return i
    return -1


def squares_clear(const unsigned char[::1] grid, Py_ssize_t ny, double ox, double oy,
                  double resolution, double px, double py, double span, double clearance):
    """Whether every flagged cell of the flat grid (``ny`` cells a column) whose square
    meets the box (px, py) +- ``span`` lies at least ``clearance`` from (px, py): the
    box's cells by ``Costmap.cell_of``'s arithmetic, each square's lower corner
    (ox + i resolution, oy + j resolution), the gap along each axis
    max(max(corner - p, 0), p - (corner + resolution)), their ``hypot``."""
    cdef Py_ssize_t nx = grid.shape[0] // ny
    cdef Py_ssize_t i, j
    cdef Py_ssize_t i0 = max(cell_index(px - span - ox, resolution), 0)
    cdef Py_ssize_t j0 = max(cell_index(py - span - oy, resolution), 0)
    cdef Py_ssize_t i1 = min(cell_index(px + span - ox, resolution) + 1, nx)
    cdef Py_ssize_t j1 = min(cell_index(py + span - oy, resolution) + 1, ny)
    cdef double cx, cy, gx, gy
    for i in range(i0, i1):
        for j in range(j0, j1):
            if not grid[i * ny + j]:
                continue
            cx = ox + <double>i * resolution
            cy = oy + <double>j * resolution
            gx = max(max(cx - px, 0.0), px - (cx + resolution))
            gy = max(max(cy - py, 0.0), py - (cy + resolution))
            if not hypot(gx, gy) >= clearance:
                return False
    return True


def look_up_rows(const double[:, ::1] xs, const double[:, ::1] ys, double ox, double oy,
                 double resolution, const unsigned char[::1] grid, Py_ssize_t ny,
                 unsigned char[::1] out):
    """For each row of points (``xs[i, k]``, ``ys[i, k]``), whether any falls in a
    flagged cell of the flat grid (``ny`` cells a column; beyond it: no), each found as
    ``look_up`` finds it."""
    cdef Py_ssize_t nx = grid.shape[0] // ny
    cdef Py_ssize_t i, k
    for i in range(xs.shape[0]):
        out[i] = 0
        for k in range(xs.shape[1]):
            if flag_at(xs[i, k], ys[i, k], ox, oy, resolution, grid, nx, ny, 0):
                out[i] = 1
                break


cdef inline unsigned char lethal_at(Py_ssize_t c, const unsigned char[::1] occupied,
                                   const double[::1] seen, const double[::1] hit_since,
                                   const unsigned char[::1] walls, double known_from,
                                   double confirmed_by, double wall_known_from,
                                   double wall_confirm) noexcept nogil:
    """Whether cell ``c`` is lethal (:func:`lethal_cells`)."""
    return ((occupied[c] != 0) & (seen[c] >= known_from) & (hit_since[c] <= confirmed_by)
            | (walls[c] != 0) & (seen[c] >= wall_known_from)
            & (seen[c] - hit_since[c] >= wall_confirm))


def lethal_cells(const unsigned char[::1] occupied, const double[::1] seen,
                 const double[::1] hit_since, const unsigned char[::1] walls,
                 double known_from, double confirmed_by, double wall_known_from,
                 double wall_confirm, const unsigned char[::1] before,
                 unsigned char[::1] out):
    """Into ``out`` (one byte a cell of the flat grids) the lethal cells of
    ``Costmap.lethal``: occupied, seen at ``known_from`` or later, and occupied since
    ``confirmed_by`` or earlier; or a wall seen at ``wall_known_from`` or later (the
    same comparisons: a nan is neither); whether they differ from ``before`` (a grid of
    the same size, the last lethal cells). Most cells are neither occupied nor a wall:
    eight at a time are passed over when none of them is, and their times are not
    read."""
    cdef Py_ssize_t c = 0, k, n = occupied.shape[0]
    cdef uint64_t occupied8, walls8
    if n == 0:
        return False
    memset(&out[0], 0, n)
    while c + 8 <= n:
        memcpy(&occupied8, &occupied[c], 8)
        memcpy(&walls8, &walls[c], 8)
        if occupied8 | walls8:
            for k in range(c, c + 8):
                out[k] = lethal_at(k, occupied, seen, hit_since, walls, known_from,
                                   confirmed_by, wall_known_from, wall_confirm)
        c += 8
    for k in range(c, n):
        out[k] = lethal_at(k, occupied, seen, hit_since, walls, known_from, confirmed_by,
                           wall_known_from, wall_confirm)
    return memcmp(&out[0], &before[0], n) != 0


def stamp_discs(const long[::1] centres, Py_ssize_t nx, Py_ssize_t ny,
                const long[::1] di, const long[::1] dj, unsigned char[::1] out):
    """Flag in ``out`` (the flat grid, ``ny`` cells a column) every cell within the
    grid at an offset ``(di[k], dj[k])`` from one of the ``centres`` (flat indices)."""
    cdef Py_ssize_t c, k, i, j, a, b
    for c in range(centres.shape[0]):
        i = centres[c] // ny
        j = centres[c] % ny
        for k in range(di.shape[0]):
            a = i + di[k]
            b = j + dj[k]
            if (<size_t>a < <size_t>nx) & (<size_t>b < <size_t>ny):
                out[a * ny + b] = 1


def closed_off(const unsigned char[::1] walls, Py_ssize_t nx, Py_ssize_t ny,
               const long[::1] di, const long[::1] dj, Py_ssize_t si, Py_ssize_t sj,
               Py_ssize_t gi, Py_ssize_t gj, Py_ssize_t reach):
    """Whether no way of free cells joins the start's window to the goal's, in the flat
    grid ``walls`` (``nx`` by ``ny``, ``ny`` cells a column): a cell is free when no
    wall cell lies at an offset ``(di[k], dj[k])`` from it (``stamp_discs`` round the
    walls), a way is a run of free cells each beside the last (4 neighbours, as
    ``scipy.ndimage.label``'s default joins them), and a cell's window is the cells at
    most ``reach`` from it along each axis (within the grid). A flood from the free
    cells of the start's window, stopping at the first cell of the goal's. A goal whose
    window holds no free cell at all is not closed off but covered: False."""
    cdef Py_ssize_t size = nx * ny, c, i, j, k, head = 0, tail = 0, a, b
    cdef bint covered
    state_array = np.zeros(size, dtype=np.uint8)  # 0 free, 1 blocked, 2 reached
    queue_array = np.empty((size, 2), dtype=np.int32)  # (i, j) of the cells reached
    cdef unsigned char[::1] state = state_array
    cdef int[:, ::1] queue = queue_array
    for i in range(nx):
        for j in range(ny):
            if walls[i * ny + j]:
                for k in range(di.shape[0]):
                    a = i + di[k]
                    b = j + dj[k]
                    if (<size_t>a < <size_t>nx) & (<size_t>b < <size_t>ny):
                        state[a * ny + b] = 1
    covered = True
    for i in range(max(gi - reach, 0), min(gi + reach + 1, nx)):
        for j in range(max(gj - reach, 0), min(gj + reach + 1, ny)):
            if state[i * ny + j] == 0:
                covered = False
    if covered:
        return False
    for i in range(max(si - reach, 0), min(si + reach + 1, nx)):
        for j in range(max(sj - reach, 0), min(sj + reach + 1, ny)):
            if state[i * ny + j] == 0:
                state[i * ny + j] = 2
                queue[tail, 0] = <int>i
                queue[tail, 1] = <int>j
                tail += 1
    while head < tail:
        i = queue[head, 0]
        j = queue[head, 1]
        head += 1
        if gi - reach <= i <= gi + reach and gj - reach <= j <= gj + reach:
            return False
        for k in range(4):
            a = i + (k == 0) - (k == 1)
            b = j + (k == 2) - (k == 3)
            if (<size_t>a < <size_t>nx) & (<size_t>b < <size_t>ny) and state[a * ny + b] == 0:
                state[a * ny + b] = 2
                queue[tail, 0] = <int>a
                queue[tail, 1] = <int>b
                tail += 1
    return True


@cython.cdivision(True)
def drive(const double[::1] headings, const double[::1] speeds, double dt, double x0,
          double y0, double theta0, double v0, double gain, double max_omega,
          double accel, double decel, bint has_goal, double gx, double gy, double within,
          double[:, ::1] xs, double[:, ::1] ys, long[::1] ends):
    """The unicycle of ``safety.drive_out``, candidate by candidate, step by step, into
    ``xs`` and ``ys`` (n, k): the heading error wrapped as ``wrap_angles`` does, the
    turn rate and the speed clipped to their limits. With ``has_goal``, a roll-out whose
    point comes within ``within`` of (gx, gy) (``hypot``, as ``np.hypot``) stands there
    for the rest of its steps; into ``ends[i]`` how many steps roll-out i drives: up to
    and including that point, else all of them."""
    cdef double x, y, theta, v, error, omega, wanted, c
    cdef Py_ssize_t i, k, j, steps = xs.shape[1]
    for i in range(headings.shape[0]):
        x, y, theta, v = x0, y0, theta0, v0
        ends[i] = steps
        for k in range(steps):
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
            if has_goal and hypot(x - gx, y - gy) <= within:
                ends[i] = k + 1
                for j in range(k + 1, steps):
                    xs[i, j] = x
                    ys[i, j] = y
                break


def holding(double x, double y, const double[:, ::1] positions, const double[::1] radii,
            const double[::1] top_speeds, const double[::1] ages, double robot_radius,
            double margin, double growth, double[::1] out):
    """``safety.holding`` for the robot at (x, y): into ``out[j]`` its distance to mover
    j when that is below the mover's clearance now (robot radius + the mover's radius +
    half the margin + growth x its top speed x its age), else inf."""
    cdef double now, clearance
    cdef Py_ssize_t j
    for j in range(radii.shape[0]):
        now = hypot(positions[j, 0] - x, positions[j, 1] - y)
        clearance = robot_radius + radii[j] + margin / 2 + growth * top_speeds[j] * ages[j]
        out[j] = now if now < clearance else INFINITY


cdef inline double spaced(Py_ssize_t i, Py_ssize_t count, double length,
                          double step) noexcept nogil:
    """``np.linspace(0, length, count)[i]`` to the bit (``count`` >= 2, ``step`` =
    ``length / (count - 1)``): ``i * step`` (or ``i / (count - 1) * length`` when the step
    is 0), plus the start 0, and the last point ``length`` itself."""
    if i == count - 1:
        return length
    if step == 0.0:
        return (<double>i / <double>(count - 1)) * length + 0.0
    return <double>i * step + 0.0


def line_any(double sx, double sy, double dx, double dy, double length, Py_ssize_t count,
             double ox, double oy, double resolution, const unsigned char[::1] grid,
             Py_ssize_t ny, unsigned char outside):
    """Whether any of the ``count`` points of ``prediction.path_points`` from (sx, sy)
    along (dx, dy) for ``length`` m falls in a flagged cell of the flat grid (``ny``
    cells a column; ``outside`` beyond it), as ``look_up`` finds each point's flag."""
    cdef Py_ssize_t nx = grid.shape[0] // ny
    cdef Py_ssize_t i
    cdef double step = length / <double>(count - 1), s
    for i in range(count):
        s = spaced(i, count, length, step)
        if flag_at(sx + s * dx, sy + s * dy, ox, oy, resolution, grid, nx, ny, outside):
            return True
    return False


def max_along(double sx, double sy, double dx, double dy, Py_ssize_t count, double ox,
              double oy, double resolution, const double[::1] grid, Py_ssize_t ny):
    """The highest value of the flat grid (``ny`` cells a column) at the cells of the
    ``count`` points ``(sx, sy) + t (dx, dy)``, ``t`` the points of
    ``np.linspace(0, 1, count)`` (``count`` >= 2), each found as ``Costmap.cell_of``
    finds it; the points beyond the grid skipped; 0 if none is in it or all are below.
    (``global_path._cost_along``, leg by leg.)"""
    cdef Py_ssize_t nx = grid.shape[0] // ny
    cdef Py_ssize_t i, ix, iy
    cdef double step = 1.0 / <double>(count - 1), t, worst = 0.0
    for i in range(count):
        t = spaced(i, count, 1.0, step)
        ix = cell_index(sx + t * dx - ox, resolution)
        iy = cell_index(sy + t * dy - oy, resolution)
        if (<size_t>ix < <size_t>nx) & (<size_t>iy < <size_t>ny):
            if grid[ix * ny + iy] > worst:
                worst = grid[ix * ny + iy]
    return worst


def project_on(const double[:, ::1] points, const double[::1] lengths, double px,
               double py):
    """(s, d) of ``global_path.project``: the arc length of the point of the polyline
    ``points`` (n >= 2, cumulative ``lengths`` at its vertices) nearest (px, py), and
    the distance to it; each segment's numbers as numpy had them (the squared length
    at least 1e-18, the fraction clipped to [0, 1] as ``np.clip`` does, ``hypot``), the
    first nearest segment winning, as ``np.argmin`` has it. (The arc lengths are the
    caller's: they change only with the path.)"""
    cdef Py_ssize_t k, best = 0
    cdef double ax, ay, abx, aby, l2, t, d, best_d = INFINITY, best_t = 0.0, best_l2 = 1.0
    if points.shape[0] < 2:
        raise ValueError("a path needs two points to project on")
    for k in range(points.shape[0] - 1):
        ax, ay = points[k, 0], points[k, 1]
        abx = points[k + 1, 0] - ax
        aby = points[k + 1, 1] - ay
        l2 = abx * abx + aby * aby
        l2 = 1e-18 if l2 < 1e-18 else l2  # (a nan stays nan, as in numpy)
        t = ((px - ax) * abx + (py - ay) * aby) / l2
        t = 0.0 if t <= 0.0 else t
        t = 1.0 if t >= 1.0 else t
        d = hypot(ax + t * abx - px, ay + t * aby - py)
        if k == 0 or d < best_d or (d != d and best_d == best_d):  # the first nan wins
            best, best_d, best_t, best_l2 = k, d, t, l2
    return lengths[best] + best_t * sqrt(best_l2), best_d


@cython.cdivision(True)
def straight_on(const double[:, ::1] points, const double[::1] lengths, double s0,
                double rx, double ry, double dx, double dy):
    """How far the path (``points``, arc ``lengths``) runs on straight from (rx, ry)
    along (dx, dy) (unit), from arc length ``s0`` on (the robot's projection): the
    distance to the last vertex past ``s0 + 1e-6`` before the first whose leg from
    (rx, ry) turns off the direction (cosine under 0.999; a vertex within 1e-9 m never
    does), 0 when the first one does. The cosine is the dot product (``dot``) over
    ``hypot``."""
    cdef Py_ssize_t i = 0, n = points.shape[0]
    cdef double lx, ly, d
    cdef double end = 0.0
    while i < n and lengths[i] <= s0 + 1e-6:
        i += 1
    while i < n:
        lx = points[i, 0] - rx
        ly = points[i, 1] - ry
        d = hypot(lx, ly)
        if d > 1e-9 and dot(lx, ly, dx, dy) / d < 0.999:
            break
        end = d
        i += 1
    return end


def point_on(const double[:, ::1] points, const double[::1] lengths, double s):
    """(x, y) of ``global_path.point_at``: the point of the polyline ``points`` (n >= 2,
    cumulative ``lengths``) at arc length ``s``, clamped to [0, length] as Python's
    ``min`` and ``max`` do; the segment the one ``np.searchsorted(lengths, s, "right")``
    finds (the last for a nan), its fraction 0 on a segment shorter than 1e-12."""
    cdef Py_ssize_t n = points.shape[0], k = 0
    cdef double seg, t
    if n < 2:
        raise ValueError("a path needs two points to find a point on")
    s = 0.0 if 0.0 > s else s
    s = lengths[n - 1] if lengths[n - 1] < s else s
    if s != s:
        k = n
    while k < n and lengths[k] <= s:
        k += 1
    k = min(k - 1, n - 2)
    seg = lengths[k + 1] - lengths[k]
    t = 0.0 if seg < 1e-12 else (s - lengths[k]) / seg
    return (points[k, 0] + t * (points[k + 1, 0] - points[k, 0]),
            points[k, 1] + t * (points[k + 1, 1] - points[k, 1]))


def box_gaps(double sx, double sy, double dx, double dy, double length, Py_ssize_t count,
             const long[:, ::1] cells, double cell, const double[::1] clearances,
             long[::1] first, double[::1] least):
    """For each grid box j (row ix_min, ix_max, iy_min, iy_max of ``cells``; cell i
    spans [(i - 1/2) cell, (i + 1/2) cell]) the gap to it of every one of the ``count``
    points of ``prediction.path_points`` from (sx, sy) along (dx, dy) for ``length`` m,
    as ``prediction.assess`` measures it: ``hypot`` of how far the point is outside the
    box along each axis, less ``clearances[j]``. Into ``first[j]`` the index of the first
    point with a negative gap (-1: none), into ``least[j]`` the smallest gap."""
    cdef double lo_x, lo_y, hi_x, hi_y, out_x, out_y, gap, smallest, s
    cdef double step = length / <double>(count - 1)
    cdef Py_ssize_t i, j, hit
    xs_array = np.empty(count, dtype=np.float64)
    ys_array = np.empty(count, dtype=np.float64)
    cdef double[::1] xs = xs_array, ys = ys_array
    for i in range(count):
        s = spaced(i, count, length, step)
        xs[i] = sx + s * dx
        ys[i] = sy + s * dy
    for j in range(cells.shape[0]):
        lo_x = (<double>cells[j, 0] - 0.5) * cell
        hi_x = (<double>cells[j, 1] + 0.5) * cell
        lo_y = (<double>cells[j, 2] - 0.5) * cell
        hi_y = (<double>cells[j, 3] + 0.5) * cell
        hit = -1
        smallest = INFINITY
        for i in range(count):
            out_x = max(max(lo_x - xs[i], xs[i] - hi_x), 0.0)
            out_y = max(max(lo_y - ys[i], ys[i] - hi_y), 0.0)
            gap = hypot(out_x, out_y) - clearances[j]
            if gap < 0.0 and hit < 0:
                hit = i
            smallest = min(smallest, gap)
        first[j] = hit
        least[j] = smallest


def c_hypot(double x, double y):
    """The C library's ``hypot``, the one numpy's ``np.hypot`` calls, for two Python
    numbers without the cost of a numpy call (``math.hypot`` rounds its own way and
    differs from it in the last bit at times)."""
    return hypot(x, y)


def fused_dot(double ax, double ay, double bx, double by):
    """a . b by ``dot`` (fma(a_y, b_y, a_x b_x)), for Python callers."""
    return dot(ax, ay, bx, by)


def mover_numbers(double px, double py, double vx, double vy, double rx, double ry,
                  double dx, double dy, double speed):
    """A mover at (px, py) going (vx, vy), against the robot at (rx, ry) going along
    (dx, dy) (unit) at ``speed``: its centre from the robot, its velocity relative to the
    robot's, and four dot products, as ``prediction.assess_all`` takes them: rel . d
    (how far ahead), v . d (its speed along the robot's way), w . w and rel . w (for the
    closest approach), w the relative velocity; each dot product by ``dot``."""
    cdef double relx = px - rx, rely = py - ry
    cdef double wx = vx - dx * speed, wy = vy - dy * speed
    return (relx, rely, wx, wy, dot(relx, rely, dx, dy), dot(vx, vy, dx, dy),
            dot(wx, wy, wx, wy), dot(relx, rely, wx, wy))


@cython.cdivision(True)
def contacts(const double[:, ::1] xs, const double[:, ::1] ys, const double[::1] times,
             const double[:, ::1] positions, const double[:, ::1] velocities,
             const double[::1] radii, const double[::1] top_speeds, const double[::1] ages,
             double robot_radius, double margin, double growth, double comfort, double tau,
             const double[::1] inside, const long[::1] ends, double[:, ::1] worst,
             double[::1] first_t, long[::1] who):
    """The passes of every roll-out (rows of ``xs``, ``ys``: positions at ``times``; row
    i's first ``ends[i]`` steps, at least one, are driven) by every mover, as
    ``safety.contact_costs`` defines them: into ``worst`` (n, m) the
    largest cost of a pass by each mover over the horizon, into ``first_t`` the time of
    the roll-out's first contact (inf: none) and into ``who`` its mover (the first by
    index at that time; -1: none). ``inside[j]``: the robot's distance now to mover j
    when its clearance holds the robot now (its clearance is capped there, and a contact
    costs 1 + 10 x its depth: no less than any pass outside it), else inf. (``tau``, and
    ``comfort`` when above 0, are never 0: ``Settings`` come from the planner's
    parameters.)"""
    cdef Py_ssize_t n = xs.shape[0], m = radii.shape[0], steps = times.shape[0]
    cdef Py_ssize_t i, j, k, first_k
    cdef double px, py, gap, clearance, near, depth, cost, largest
    cdef bint held
    for i in range(n):
        first_k = steps
        who[i] = -1
        for j in range(m):
            largest = -INFINITY
            held = inside[j] < INFINITY
            for k in range(ends[i]):
                px = positions[j, 0] + velocities[j, 0] * times[k]
                py = positions[j, 1] + velocities[j, 1] * times[k]
                clearance = (robot_radius + radii[j] + margin / 2
                             + growth * top_speeds[j] * (ages[j] + times[k]))
                if held:  # (below the clearance of every step: it grows with time)
                    clearance = inside[j]
                gap = hypot(xs[i, k] - px, ys[i, k] - py) - clearance
                if gap < 0.0:
                    depth = min(max(-gap / clearance, 0.0), 1.0)
                    cost = 1.0 + 10.0 * depth if held else 10.0 * (1.0 + depth)
                    if k < first_k:
                        first_k = k
                        who[i] = j
                elif comfort > 0:
                    cost = min(max(1.0 - gap / comfort, 0.0), 1.0)
                else:
                    cost = 0.0
                largest = max(largest, cost * (1.0 / (1.0 + times[k] / tau)))
            worst[i, j] = largest
        first_t[i] = times[first_k] if first_k < steps else INFINITY
