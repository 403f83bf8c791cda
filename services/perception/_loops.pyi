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
def window_beams(ranges: npt.NDArray[np.float64], angle_min: float, angle_increment: float,
                 range_min: float, range_max: float, window_radius: float,
                 valid: npt.NDArray[np.uint8], beams: npt.NDArray[np.int64],
                 rho: npt.NDArray[np.float64], alpha: npt.NDArray[np.float64]) -> int: ...
def run_bounds(px: npt.NDArray[np.float64], py: npt.NDArray[np.float64],
               threshold: npt.NDArray[np.float64], starts: npt.NDArray[np.int64],
               ends: npt.NDArray[np.int64], counts: npt.NDArray[np.int64]) -> int: ...
def run_shapes(px: npt.NDArray[np.float64], py: npt.NDArray[np.float64],
               starts: npt.NDArray[np.int64], ends: npt.NDArray[np.int64], inset: float,
               edges: npt.NDArray[np.float64], first_point: npt.NDArray[np.float64],
               last_point: npt.NDArray[np.float64], chord: npt.NDArray[np.float64],
               radius: npt.NDArray[np.float64]) -> None: ...
def edge_ranges(ranges: npt.NDArray[np.float64], valid: npt.NDArray[np.uint8],
                beams: npt.NDArray[np.int64], rho_edge: npt.NDArray[np.float64],
                rho_next: npt.NDArray[np.float64], rho_top: npt.NDArray[np.float64],
                has: npt.NDArray[np.uint8], outside: npt.NDArray[np.uint8]) -> None: ...
def edge_codes(rho_edge: npt.NDArray[np.float64], rho_next: npt.NDArray[np.float64],
               has: npt.NDArray[np.uint8], outside: npt.NDArray[np.uint8],
               join_top: npt.NDArray[np.float64], join_edge: npt.NDArray[np.float64],
               cos2: float, window_radius: float, codes: npt.NDArray[np.int64]) -> None: ...
