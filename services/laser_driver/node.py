"""Laser driver service: the place where a real scanner plugs in.

It reads raw frames from a device backend, checks them against the scanner's geometry
from its parameters, and publishes :class:`LaserScan` messages. The backend here is the
simulator's raw frames on ``device/laser``; a hardware backend would publish the same
frames from the scanner's own protocol.
"""

from __future__ import annotations

from zenav.schemas import keys
from zenav.schemas.messages import LaserScan, RawLaserFrame
from zenav.services.laser_driver.params import Params
from zenav.services.laser_driver.scan import FrameError, frame_to_scan
from zenav.services.node import Node, StampGate

__all__ = ["FrameError", "Params", "Service", "frame_to_scan"]
# Params and frame_to_scan are also read from here by zenav/inprocess.py and bench_perf.py.


class Service:
    def __init__(self, node: Node, params: Params) -> None:
        self.node = node
        self.params = params
        self.scans = node.publisher(keys.SCAN, LaserScan)
        self.gate = StampGate(node, keys.RAW_LASER)
        node.subscribe(keys.RAW_LASER, RawLaserFrame, self.on_frame, depth=2)

    def on_frame(self, frame: RawLaserFrame) -> None:
        try:  # checked before the stamp order: a bad frame must not pass as a repeat
            scan = frame_to_scan(frame, self.params, seq=0)
        except FrameError as exc:
            self.node.reject(self.node.keys.of(keys.RAW_LASER), "bad_frame", str(exc))
            return
        if not self.gate.admit(frame.stamp, self.scans):
            return
        self.scans.publish(scan.model_copy(update={"seq": self.scans.next_seq()}))


if __name__ == "__main__":
    from zenav.services.runner import main

    raise SystemExit(main("laser_driver"))
