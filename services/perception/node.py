"""Perception service: laser scan + odometry in, obstacle chain O_chain(t) out.

Each scan is clustered with the robot pose at the scan's own time (Eq. 1 needs it). The
pose comes from odometry matched by stamp, interpolated between two odometry messages
when the stamps fall between them. A scan that arrives before its odometry waits for it
(one scan at most, newest wins), so the result does not depend on which message the
network delivered first.
"""

from __future__ import annotations

import bisect
from collections import deque

from zenav.schemas import keys
from zenav.schemas.messages import LaserScan, ObstacleChain, Odometry
from zenav.services.geometry import wrap_angle
from zenav.services.node import Node, StampGate
from zenav.services.perception.clustering import Pose
from zenav.services.perception.params import PerceptionParams
from zenav.services.perception.perceive import Perceiver
from zenav.services.perception.wire import to_message

POSE_HISTORY = 200
"""Odometry messages kept for matching scans to poses (20 s at 10 Hz)."""


class PoseHistory:
    """Recent robot poses by stamp."""

    def __init__(self, size: int = POSE_HISTORY) -> None:
        self.stamps: deque[float] = deque(maxlen=size)
        self.poses: deque[Pose] = deque(maxlen=size)

    def add(self, odometry: Odometry) -> None:
        if self.stamps and odometry.stamp <= self.stamps[-1]:
            return  # a repeat or out of order: the history only grows forward
        p = odometry.pose
        self.stamps.append(odometry.stamp)
        self.poses.append((p.x, p.y, p.heading))

    @property
    def newest(self) -> float | None:
        return self.stamps[-1] if self.stamps else None

    def at(self, stamp: float, tolerance: float = 1e-6) -> Pose | None:
        """The pose at ``stamp``: exact, interpolated, or None when not covered."""
        if not self.stamps or stamp > self.stamps[-1] + tolerance:
            return None
        i = bisect.bisect_left(self.stamps, stamp - tolerance)
        if i < len(self.stamps) and abs(self.stamps[i] - stamp) <= tolerance:
            return self.poses[i]
        if i == 0:
            return None  # older than anything kept
        t0, t1 = self.stamps[i - 1], self.stamps[i]
        (x0, y0, h0), (x1, y1, h1) = self.poses[i - 1], self.poses[i]
        f = (stamp - t0) / (t1 - t0)
        return (x0 + f * (x1 - x0), y0 + f * (y1 - y0), wrap_angle(h0 + f * wrap_angle(h1 - h0)))


class Service:
    def __init__(self, node: Node, params: PerceptionParams) -> None:
        self.node = node
        self.params = params
        self.chains = node.publisher(keys.OBSTACLES, ObstacleChain)
        self.gate = StampGate(node, keys.SCAN)
        self.history = PoseHistory()
        self.waiting: LaserScan | None = None
        self.perceiver = Perceiver(params)
        node.subscribe(keys.SCAN, LaserScan, self.on_scan, depth=2)
        node.subscribe(keys.ODOM, Odometry, self.on_odometry, depth=16)

    def on_odometry(self, odometry: Odometry) -> None:
        self.history.add(odometry)
        if self.waiting is not None:
            pose = self.history.at(self.waiting.stamp)
            if pose is not None:
                scan, self.waiting = self.waiting, None
                self.process(scan, pose)

    def on_scan(self, scan: LaserScan) -> None:
        if not self.gate.admit(scan.stamp, self.chains):
            return
        pose = self.history.at(scan.stamp)
        if pose is not None:
            self.process(scan, pose)
        elif self.history.newest is None or scan.stamp > self.history.newest:
            if self.waiting is not None:  # one scan waits at most: the newer one wins
                self.node.reject(self.node.keys.of(keys.SCAN), "superseded",
                                 f"scan of t={self.waiting.stamp} replaced by t={scan.stamp} "
                                 "before its odometry came")
            self.waiting = scan  # its odometry is still on the way
        else:
            self.node.reject(
                self.node.keys.of(keys.SCAN), "no_pose", f"no odometry around t={scan.stamp}"
            )

    def process(self, scan: LaserScan, pose: Pose) -> None:
        clusters = self.perceiver.process(scan, pose)
        self.chains.publish(
            to_message(clusters, scan.stamp, self.chains.next_seq(), self.params.window_radius)
        )


if __name__ == "__main__":
    from zenav.services.runner import main

    raise SystemExit(main("perception"))
