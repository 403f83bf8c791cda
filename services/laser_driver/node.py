"""Laser driver service: the place where a real scanner plugs in.

Two backends, chosen by ``backend``:

- ``native``: raw frames on ``device/laser`` (the simulator, or a scanner's own driver
  process), checked against the scanner's geometry from the parameters;
- ``ros2``: a ROS 2 robot's ``sensor_msgs/msg/LaserScan`` and ``nav_msgs/msg/Odometry``
  over rmw_zenoh, any angle range and increment, turned into zenav's scan and odometry
  (see :mod:`zenav.services.ros2.convert` for how REP 117 ranges are read).

Either way it publishes :class:`LaserScan` messages on zenav's own ``scan`` key.
"""

from __future__ import annotations

from typing import Any

from zenav.schemas import keys
from zenav.schemas.messages import LaserScan, Odometry, RawLaserFrame
from zenav.services.laser_driver.params import Params
from zenav.services.laser_driver.scan import FrameError, frame_to_scan
from zenav.services.node import Node, Republisher, StampGate
from zenav.services.ros2.convert import odometry_from_ros, scan_from_ros
from zenav.services.ros2.inputs import serve_ros2
from zenav.services.ros2.node import Ros2Node
from zenav.services.ros2.wire import DEFAULT_QOS, LASER_SCAN, ODOMETRY, SENSOR_QOS
from zenav.services.transport import Subscription

__all__ = ["FrameError", "Params", "Service", "frame_to_scan"]
# Params and frame_to_scan are also read from here by zenav/inprocess.py and bench_perf.py.


class Service:
    def __init__(self, node: Node, params: Params) -> None:
        self.node = node
        self.params = params
        self.scans = node.publisher(keys.SCAN, LaserScan)
        self.gate = StampGate(node, keys.RAW_LASER)
        self.ros: Ros2Node | None = None
        self._subs: list[Subscription] = []
        if params.backend == "native":
            node.subscribe(keys.RAW_LASER, RawLaserFrame, self.on_frame, depth=2)
            return
        r = params.ros2
        self.ros = Ros2Node(node.bus, r.node_name or "zenav_laser_driver", r.domain_id,
                            r.namespace)
        self.odometry = node.publisher(keys.ODOM, Odometry)
        self.odom_gate = StampGate()
        scan_qos = SENSOR_QOS if r.scan_qos == "sensor_data" else DEFAULT_QOS
        scans = self.ros.subscribe(r.topic(r.scan_topic), LASER_SCAN, scan_qos, depth=2)
        odoms = self.ros.subscribe(r.topic(r.odom_topic), ODOMETRY, DEFAULT_QOS, depth=8)
        self._subs = [scans, odoms]
        node.add_task(serve_ros2(node, scans, LASER_SCAN, self.on_ros_scan), "ros2:scan")
        node.add_task(serve_ros2(node, odoms, ODOMETRY, self.on_ros_odometry), "ros2:odom")

    def on_ros_scan(self, key: str, msg: Any) -> None:
        scan = scan_from_ros(msg, seq=0, frame=self.params.frame)
        if self.accept(key, scan.stamp, self.gate, self.scans):
            self.scans.publish(scan.model_copy(update={"seq": self.scans.next_seq()}))

    def on_ros_odometry(self, key: str, msg: Any) -> None:
        odometry = odometry_from_ros(msg, seq=0)
        if self.accept(key, odometry.stamp, self.odom_gate, self.odometry):
            self.odometry.publish(odometry.model_copy(update={"seq": self.odometry.next_seq()}))

    def accept(self, key: str, stamp: float, gate: StampGate, output: Republisher) -> bool:
        """Order one ROS 2 input by stamp: a repeat is answered again, an older one is
        refused and counted."""
        order = gate.check(stamp)
        if order == "repeat":
            output.republish()
        elif order == "old":
            self.node.reject(key, "out_of_order", f"{key}: stamp {stamp} after {gate.last}")
        else:
            self.node.received[key] += 1
        return order == "new"

    def close(self) -> None:
        """Leave the ROS 2 graph (the runner calls this after the node stops)."""
        for sub in self._subs:
            sub.close()
        if self.ros is not None:
            self.ros.close()

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
