"""Perception for one scan: clustering (Eqs. 1-6) plus the free-space motion cue."""

from __future__ import annotations

from zenav.schemas.messages import LaserScan
from zenav.services.perception.clustering import Clusters, Pose, cluster_window, scan_window
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
        window = scan_window(scan.ranges, scan.angle_min, scan.angle_increment, scan.range_min,
                             scan.range_max, pose, self.params.window_radius)
        clusters = cluster_window(window, scan.angle_increment, pose, self.params)
        # (the window's ranges are the scan's as float64, the copy the cue keeps)
        snapshot = ScanSnapshot(scan.stamp, pose, window.ranges, scan.angle_min,
                                scan.angle_increment, scan.range_max)
        each, stamps = self.cue.score_each(snapshot, scan.range_min, clusters.beams, window)
        return clusters.with_motion(each, stamps)
