"""Types of the compiled loops in ``_loops.pyx``."""

import numpy as np
import numpy.typing as npt

_F = npt.NDArray[np.float64]
_U8 = npt.NDArray[np.uint8]

def clear_beams(x: float, y: float, ux: _F, uy: _F, reach: _F, step: float, ox: float,
                oy: float, resolution: float, ny: int, returned: _U8, stamp: float,
                seen: _F, occupied: _U8, walls: _U8) -> None: ...
def drive(headings: _F, speeds: _F, dt: float, x0: float, y0: float, theta0: float,
          v0: float, gain: float, max_omega: float, accel: float, decel: float, xs: _F,
          ys: _F) -> None: ...
