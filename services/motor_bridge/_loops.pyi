"""Types of the compiled functions in ``_loops.pyx``."""

import numpy as np
import numpy.typing as npt

def zone_hit(ranges: npt.NDArray[np.float64], cosines: npt.NDArray[np.float64],
             sines: npt.NDArray[np.float64], range_max: float, length: float,
             half_width: float) -> bool: ...
