"""Perception for one scan: clustering (Eqs. 1-6) plus the free-space motion cue."""

from __future__ import annotations

from zenav.schemas.messages import LaserScan
from zenav.services.perception.clustering import (
    Clusters,
    Pose,
    cluster_window,
    rotate_scan,
    scan_window,
    seam_shift,
)
from zenav.services.perception.motion_cue import MotionCue, ScanSnapshot
from zenav.services.perception.params import PerceptionParams


class Perceiver:
    """Turns each scan, with the pose it was taken from, into the obstacle chain."""

    def __init__(self, params: PerceptionParams) -> None:
        self.params = params
        self.cue = MotionCue(params.motion_baselines, params.motion_margin, params.motion_reach,
                             params.window_radius)

    def process(self, scan: LaserScan, pose: Pose) -> Clusters:
        # The window's returns and their global points once, for clustering and the cue.
        p, step = self.params, scan.angle_increment
        angle_min = scan.angle_min
        window = scan_window(scan.ranges, angle_min, step, scan.range_min, scan.range_max,
                             pose, p.window_radius)
        clusters = cluster_window(window, step, pose, p)
        shift = seam_shift(clusters, window, step, p)
        if shift is not None:
            # A full circle whose seam cuts an obstacle (a walker straight behind) in two:
            # the scan again, started at a break between clusters. Beam numbers from here
            # on (the clusters', the cue's) are those of the turned scan.
            ranges, angle_min = rotate_scan(window.ranges, angle_min, step, shift)
            window = scan_window(ranges, angle_min, step, scan.range_min, scan.range_max,
                                 pose, p.window_radius)
            clusters = cluster_window(window, step, pose, p)
        # (the window's ranges are the scan's as float64, the copy the cue keeps)
        snapshot = ScanSnapshot(scan.stamp, pose, window.ranges, angle_min, step,
                                scan.range_max)
        each, stamps = self.cue.score_each(snapshot, scan.range_min, clusters.beams, window)
        return clusters.with_motion(each, stamps)
