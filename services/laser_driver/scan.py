"""Raw frames checked against the scanner's geometry and turned into scans (pure, no I/O)."""

from __future__ import annotations

import math

import numpy as np

from zenav.schemas.messages import LaserScan, RawLaserFrame
from zenav.services.laser_driver.params import Params


class FrameError(ValueError):
    """A raw frame that does not fit the scanner."""


def frame_to_scan(frame: RawLaserFrame, params: Params, seq: int) -> LaserScan:
    """Check a raw frame and turn it into a scan; raises :class:`FrameError`."""
    ranges = frame.ranges
    if ranges.size != params.beam_count:
        raise FrameError(f"frame has {ranges.size} beams, the scanner has {params.beam_count}")
    if not np.isfinite(ranges).all():
        raise FrameError(f"non-finite range at beam {int(np.flatnonzero(~np.isfinite(ranges))[0])}")
    if (ranges < 0).any():
        raise FrameError(f"negative range at beam {int(np.flatnonzero(ranges < 0)[0])}")
    clipped = np.minimum(ranges, np.float32(params.range_max))
    half = math.radians(params.fov_deg) / 2
    return LaserScan(
        stamp=frame.stamp,
        seq=seq,
        frame=params.frame,
        angle_min=-half,
        angle_max=half,
        angle_increment=math.radians(params.resolution_deg),
        scan_time=1.0 / params.rate_hz,
        range_min=params.range_min,
        range_max=params.range_max,
        ranges=clipped,
    )
