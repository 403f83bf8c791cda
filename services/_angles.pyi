"""Types of ``_angles.pyx``."""

import numpy as np
import numpy.typing as npt

def wrap_angles(angles: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
