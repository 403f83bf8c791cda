"""The simulator's ROS 2 face: the simulated robot as a ROS 2 node over rmw_zenoh.

It publishes ``sensor_msgs/msg/LaserScan`` (sensor-data QoS) and
``nav_msgs/msg/Odometry`` and takes velocity commands from ``cmd_vel``, with the
liveliness tokens a ROS 2 node declares, exactly as a real robot running rmw_zenoh_cpp
would. zenav's ros2 backends (laser driver, motor bridge) are then the only way the stack
reaches it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt

from zenav.schemas.messages import BaseCommand, LaserScan, Odometry
from zenav.services.node import Node
from zenav.services.ros2.convert import (
    odometry_to_ros,
    scan_to_ros,
    stamp_of,
    velocity_from_twist,
)
from zenav.services.ros2.inputs import serve_ros2
from zenav.services.ros2.node import Ros2Node
from zenav.services.ros2.params import Ros2Params
from zenav.services.ros2.wire import DEFAULT_QOS, LASER_SCAN, ODOMETRY, SENSOR_QOS
from zenav.sim.scenario import LaserSpec


class Ros2Face:
    """The robot's ROS 2 topics; commands reach ``on_command`` as base commands."""

    def __init__(self, node: Node, params: Ros2Params, laser: LaserSpec,
                 on_command: Callable[[BaseCommand], None],
                 now: Callable[[], float]) -> None:
        self.params = params
        self.laser = laser
        self.on_command = on_command
        self.now = now
        self.node = node
        self.ros = Ros2Node(node.bus, params.node_name or "zenav_sim_robot", params.domain_id,
                            params.namespace)
        self.scan = self.ros.publisher(params.topic(params.scan_topic), LASER_SCAN, SENSOR_QOS)
        self.odom = self.ros.publisher(params.topic(params.odom_topic), ODOMETRY, DEFAULT_QOS)
        self.commands = self.ros.subscribe(params.topic(params.cmd_vel_topic),
                                           params.cmd_vel_type)
        node.add_task(serve_ros2(node, self.commands, params.cmd_vel_type, self.on_ros_command),
                      "ros2:cmd_vel")

    def on_ros_command(self, key: str, msg: Any) -> None:
        """A velocity command as the base takes it: a TwistStamped's stamp says which scan
        it answers; a plain Twist counts for now."""
        if self.params.twist_stamped:
            stamp, (v, omega) = stamp_of(msg.header.stamp), velocity_from_twist(msg.twist)
        else:
            stamp, (v, omega) = self.now(), velocity_from_twist(msg)
        self.node.received[key] += 1
        self.on_command(BaseCommand(stamp=stamp, seq=0, v=v, omega=omega))

    def publish_odometry(self, odometry: Odometry) -> None:
        self.odom.publish(odometry_to_ros(odometry, self.params.odom_frame,
                                          self.params.base_frame))

    def publish_scan(self, stamp: float, ranges: npt.NDArray[np.float32]) -> None:
        laser = self.laser
        scan = LaserScan(stamp=stamp, seq=0, frame=self.params.laser_frame,
                         angle_min=laser.angle_min_rad, angle_max=-laser.angle_min_rad,
                         angle_increment=laser.angle_increment_rad, scan_time=laser.period,
                         range_min=0.0, range_max=laser.max_range, ranges=ranges)
        self.scan.publish(scan_to_ros(scan))

    def republish(self) -> None:
        """Send this tick's odometry and scan again (lockstep retransmission)."""
        for publisher in (self.odom, self.scan):
            if publisher.last is not None:
                publisher.publish(publisher.last)

    def close(self) -> None:
        self.commands.close()
        self.ros.close()
