"""Types of the compiled loops in ``_loops.pyx``."""

import numpy as np
import numpy.typing as npt

_F = npt.NDArray[np.float64]
_U8 = npt.NDArray[np.uint8]

_I = npt.NDArray[np.int_]

def floor_quotients(offsets: _F, resolution: float, out: _I) -> None: ...
def return_bounds(x: float, y: float, ux: _F, uy: _F, ranges: _F, range_min: float,
                  range_max: float) -> tuple[float, float, float, float]: ...
def trace_scan(x: float, y: float, ux: _F, uy: _F, ranges: _F, range_min: float,
               range_max: float, movers: _F, ox: float, oy: float, resolution: float,
               ny: int, returned: _U8, stamp: float, confirm: float, seen: _F,
               occupied: _U8, hit_since: _F, walls: _U8) -> None: ...
def look_up(points: _F, ox: float, oy: float, resolution: float, grid: _U8, ny: int,
            outside: int, out: _U8) -> None: ...
def stamp_discs(centres: _I, nx: int, ny: int, di: _I, dj: _I, out: _U8) -> None: ...
def drive(headings: _F, speeds: _F, dt: float, x0: float, y0: float, theta0: float,
          v0: float, gain: float, max_omega: float, accel: float, decel: float, xs: _F,
          ys: _F) -> None: ...
def box_gaps(points: _F, cells: _I, cell: float, clearances: _F, first: _I,
             least: _F) -> None: ...
