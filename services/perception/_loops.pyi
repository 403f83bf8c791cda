"""Types of the compiled loop in ``_loops.pyx``."""

import numpy as np
import numpy.typing as npt

def seen_free(points: npt.NDArray[np.float64], x: float, y: float, heading: float,
              ranges: npt.NDArray[np.float64], angle_min: float, angle_increment: float,
              margin: float, out: npt.NDArray[np.uint8]) -> None: ...
def group_points(cluster_beams: npt.NDArray[np.int64], window_beams: npt.NDArray[np.int64],
                 window_points: npt.NDArray[np.float64], n_beams: int, reach: float,
                 member: npt.NDArray[np.int64], points: npt.NDArray[np.float64],
                 counts: npt.NDArray[np.int64], lo: npt.NDArray[np.float64],
                 hi: npt.NDArray[np.float64]) -> int: ...
def free_scores(points: npt.NDArray[np.float64], member: npt.NDArray[np.int64],
                counts: npt.NDArray[np.int64], past_x: float, past_y: float,
                past_heading: float, past_ranges: npt.NDArray[np.float64],
                past_angle_min: float, past_angle_increment: float,
                past_points: npt.NDArray[np.float64], x: float, y: float, heading: float,
                ranges: npt.NDArray[np.float64], angle_min: float, angle_increment: float,
                lo: npt.NDArray[np.float64], hi: npt.NDArray[np.float64], margin: float,
                scores: npt.NDArray[np.float64]) -> None: ...
