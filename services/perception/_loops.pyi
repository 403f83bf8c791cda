"""Types of the compiled loop in ``_loops.pyx``."""

import numpy as np
import numpy.typing as npt

def seen_free(points: npt.NDArray[np.float64], x: float, y: float, heading: float,
              ranges: npt.NDArray[np.float64], angle_min: float, angle_increment: float,
              margin: float, out: npt.NDArray[np.uint8]) -> None: ...
def count_in_boxes(points: npt.NDArray[np.float64], flags: npt.NDArray[np.uint8],
                   lo: npt.NDArray[np.float64], hi: npt.NDArray[np.float64],
                   inside: npt.NDArray[np.int64], flagged: npt.NDArray[np.int64]) -> None: ...
