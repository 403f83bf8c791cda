"""Perception for one scan: clustering (Eqs. 1-6) plus the free-space motion cue."""

from __future__ import annotations

import numpy as np

from zenav.schemas.messages import LaserScan
from zenav.services.perception.clustering import (
    Clusters,
    Pose,
    cluster_window,
    moving_cuts,
    rotate_scan,
    scan_window,
    seam_shift,
)
from zenav.services.perception.motion_cue import MotionCue, ScanSnapshot
from zenav.services.perception.params import PerceptionParams

SPLIT_MIN_BEAMS = 3
"""Beams in a row that entered free space before a cluster is cut round them
(``moving_cuts``): 7 cm at 4 m with the paper's 0.5 degree beams."""


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
        span = p.motion_split_span
        if span > 0.0 and each.shape[1]:
            # A mover pressed against a wall or a jamb gets a cluster of its own
            # (moving_cuts). Only a cluster wider than a walker, with points in space the
            # longest baseline's scan saw free, can hold one; the points are tested one by
            # one only then, and the cut clusters scored again.
            held = (clusters.radius >= 0.5 * span) & (each[:, -1] * clusters.n_beams
                                                      >= SPLIT_MIN_BEAMS)
            motion = self.cue.point_motion(scan.stamp, window.points) if held.any() else None
            if motion is not None:
                cuts = moving_cuts(np.searchsorted(window.beams, clusters.beams[:, 0]),
                                   np.searchsorted(window.beams, clusters.beams[:, 1]),
                                   *motion, window.points, SPLIT_MIN_BEAMS, span)
                if cuts.size:
                    clusters = cluster_window(window, step, pose, p, cuts)
                    each, stamps = self.cue.scores(snapshot, clusters.beams, window)
        return clusters.with_motion(each, stamps)
