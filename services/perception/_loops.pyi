"""Types of the compiled loop in ``_loops.pyx``."""

import numpy as np
import numpy.typing as npt

def seen_free(points: npt.NDArray[np.float64], x: float, y: float, heading: float,
              ranges: npt.NDArray[np.float64], angle_min: float, angle_increment: float,
              margin: float, out: npt.NDArray[np.uint8]) -> None: ...
def free_or_hit(points: npt.NDArray[np.float64], x: float, y: float, heading: float,
                ranges: npt.NDArray[np.float64], angle_min: float, angle_increment: float,
                margin: float, free: npt.NDArray[np.uint8],
                hit: npt.NDArray[np.uint8]) -> None: ...
def moving_cuts(starts: npt.NDArray[np.int64], ends: npt.NDArray[np.int64],
                entered: npt.NDArray[np.uint8], stayed: npt.NDArray[np.uint8],
                points: npt.NDArray[np.float64], min_moving: int, still_span: float,
                cuts: npt.NDArray[np.int64]) -> int: ...
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
def to_global_into(x: float, y: float, heading: float, rho: npt.NDArray[np.float64],
                   alpha: npt.NDArray[np.float64], gx: npt.NDArray[np.float64],
                   gy: npt.NDArray[np.float64]) -> None: ...
def to_global_rows(x: float, y: float, heading: float, rho: npt.NDArray[np.float64],
                   alpha: npt.NDArray[np.float64], out: npt.NDArray[np.float64]) -> None: ...
def grid_index_into(coord: npt.NDArray[np.float64], cell: float,
                    out: npt.NDArray[np.int64]) -> None: ...
def join_threshold_into(rho: npt.NDArray[np.float64], lambda_: float, step: float,
                        gap_floor: float, out: npt.NDArray[np.float64]) -> None: ...
def box_area(ix_min: int, ix_max: int, iy_min: int, iy_max: int) -> int: ...
def box_areas_into(boxes: npt.NDArray[np.int64], out: npt.NDArray[np.int64]) -> None: ...
def window_points(ranges: npt.NDArray[np.float64], angle_min: float, angle_increment: float,
                  range_min: float, range_max: float, window_radius: float, x: float,
                  y: float, heading: float, valid: npt.NDArray[np.uint8],
                  beams: npt.NDArray[np.int64], rho: npt.NDArray[np.float64],
                  alpha: npt.NDArray[np.float64], px: npt.NDArray[np.float64],
                  py: npt.NDArray[np.float64], xy: npt.NDArray[np.float64]) -> int: ...
def run_bounds(px: npt.NDArray[np.float64], py: npt.NDArray[np.float64],
               rho: npt.NDArray[np.float64], lambda_: float, step: float, gap_floor: float,
               starts: npt.NDArray[np.int64], ends: npt.NDArray[np.int64],
               counts: npt.NDArray[np.int64]) -> int: ...
def run_shapes(px: npt.NDArray[np.float64], py: npt.NDArray[np.float64],
               starts: npt.NDArray[np.int64], ends: npt.NDArray[np.int64], inset: float,
               cell: float, box: npt.NDArray[np.int64], area: npt.NDArray[np.int64],
               first_point: npt.NDArray[np.float64], last_point: npt.NDArray[np.float64],
               chord: npt.NDArray[np.float64], radius: npt.NDArray[np.float64]) -> None: ...
def edge_codes(ranges: npt.NDArray[np.float64], valid: npt.NDArray[np.uint8],
               beams: npt.NDArray[np.int64], lambda_: float, step: float, gap_floor: float,
               cos2: float, window_radius: float, codes: npt.NDArray[np.int64]) -> None: ...
