"""Conversions between ROS 2 messages (rosbags objects) and zenav messages (pure).

ROS scans follow REP 117: ``+inf`` is no return within reach, ``-inf`` is an object
too close to measure, ``NaN`` is an erroneous reading, and any finite value outside
``[range_min, range_max]`` is not a valid measurement. zenav's scan has one code for
"nothing here": ``range_max``. So ``+inf``, ``NaN``, values above ``range_max`` and
finite values below ``range_min`` all become ``range_max``; ``-inf`` (something closer
than the scanner can measure) becomes ``range_min``, which the stop zone and perception
see as an obstacle right at the scanner. A scan with a negative increment (a scanner
turning clockwise) is reversed, so beams always run counter-clockwise.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from zenav.schemas.messages import LaserScan, Odometry, Pose2D
from zenav.services.ros2.wire import (
    LASER_SCAN,
    ODOMETRY,
    TWIST,
    TWIST_STAMPED,
    message_class,
)


class ConversionError(ValueError):
    """A ROS 2 message zenav cannot use; the text says why."""


# --- time and frames ------------------------------------------------------------------


def ros_time(stamp: float) -> Any:
    """A ``builtin_interfaces/msg/Time`` for ``stamp`` seconds."""
    sec = math.floor(stamp)
    nanosec = round((stamp - sec) * 1e9)
    if nanosec >= 1_000_000_000:
        sec, nanosec = sec + 1, nanosec - 1_000_000_000
    return message_class("builtin_interfaces/msg/Time")(sec=int(sec), nanosec=int(nanosec))


def stamp_of(time: Any) -> float:
    """Seconds of a ``builtin_interfaces/msg/Time``."""
    return round(float(time.sec) + float(time.nanosec) * 1e-9, 9)


def header(stamp: float, frame_id: str) -> Any:
    return message_class("std_msgs/msg/Header")(stamp=ros_time(stamp), frame_id=frame_id)


def yaw_of(q: Any) -> float:
    """Heading (rotation about z) of a quaternion, rad."""
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def quaternion(yaw: float) -> Any:
    return message_class("geometry_msgs/msg/Quaternion")(
        x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))


def vector3(x: float = 0.0, y: float = 0.0, z: float = 0.0) -> Any:
    return message_class("geometry_msgs/msg/Vector3")(x=x, y=y, z=z)


def point(x: float = 0.0, y: float = 0.0, z: float = 0.0) -> Any:
    return message_class("geometry_msgs/msg/Point")(x=x, y=y, z=z)


def pose(x: float, y: float, yaw: float) -> Any:
    return message_class("geometry_msgs/msg/Pose")(position=point(x, y),
                                                   orientation=quaternion(yaw))


# --- scan -----------------------------------------------------------------------------


def scan_from_ros(msg: Any, seq: int, frame: str | None = None) -> LaserScan:
    """zenav's scan from a ``sensor_msgs/msg/LaserScan``; raises :class:`ConversionError`."""
    ranges = np.asarray(msg.ranges, dtype=np.float64)
    inc = float(msg.angle_increment)
    rmin, rmax = float(msg.range_min), float(msg.range_max)
    stamp = stamp_of(msg.header.stamp)
    if ranges.size == 0:
        raise ConversionError("scan has no ranges")
    if not math.isfinite(inc) or inc == 0.0:
        raise ConversionError(f"scan angle_increment {inc} is zero or not finite")
    if not (math.isfinite(rmax) and rmax > 0 and math.isfinite(rmin) and 0 <= rmin < rmax):
        raise ConversionError(f"scan range limits [{rmin}, {rmax}] are not 0 <= min < max")
    if not math.isfinite(float(msg.angle_min)):
        raise ConversionError(f"scan angle_min {msg.angle_min} is not finite")
    if stamp < 0:
        raise ConversionError(f"scan stamp {stamp} is before the epoch")
    angle_min = float(msg.angle_min)
    if inc < 0:  # clockwise scanner: reverse so that beams turn counter-clockwise
        angle_min = angle_min + inc * (ranges.size - 1)
        ranges, inc = ranges[::-1], -inc
    out = ranges.copy()
    out[np.isnan(ranges) | (ranges > rmax) | ((ranges < rmin) & np.isfinite(ranges))] = rmax
    out[np.isneginf(ranges)] = rmin
    return LaserScan(
        stamp=stamp, seq=seq, frame=frame or msg.header.frame_id or "laser",
        angle_min=angle_min, angle_max=angle_min + inc * (ranges.size - 1),
        angle_increment=inc, scan_time=max(float(msg.scan_time), 0.0)
        if math.isfinite(float(msg.scan_time)) else 0.0,
        range_min=rmin, range_max=rmax, ranges=out.astype(np.float32),
    )


def scan_to_ros(scan: LaserScan) -> Any:
    """A ``sensor_msgs/msg/LaserScan`` of a zenav scan (no-return beams as ``+inf``)."""
    ranges = np.asarray(scan.ranges, dtype=np.float32).copy()
    ranges[ranges >= np.float32(scan.range_max)] = np.inf
    return message_class(LASER_SCAN)(
        header=header(scan.stamp, scan.frame), angle_min=scan.angle_min,
        angle_max=scan.angle_max, angle_increment=scan.angle_increment, time_increment=0.0,
        scan_time=scan.scan_time, range_min=scan.range_min, range_max=scan.range_max,
        ranges=ranges, intensities=np.zeros(0, dtype=np.float32),
    )


# --- odometry -------------------------------------------------------------------------


def odometry_from_ros(msg: Any, seq: int) -> Odometry:
    """zenav's odometry from a ``nav_msgs/msg/Odometry``: the pose's planar part and the
    body-frame forward speed and turn rate."""
    p = msg.pose.pose
    values = (p.position.x, p.position.y, p.orientation.x, p.orientation.y, p.orientation.z,
              p.orientation.w, msg.twist.twist.linear.x, msg.twist.twist.angular.z)
    if not all(math.isfinite(float(v)) for v in values):
        raise ConversionError("odometry has a non-finite pose or twist value")
    stamp = stamp_of(msg.header.stamp)
    if stamp < 0:
        raise ConversionError(f"odometry stamp {stamp} is before the epoch")
    return Odometry(
        stamp=stamp, seq=seq,
        pose=Pose2D(x=float(p.position.x), y=float(p.position.y), heading=yaw_of(p.orientation)),
        v=float(msg.twist.twist.linear.x), omega=float(msg.twist.twist.angular.z),
    )


def odometry_to_ros(odometry: Odometry, odom_frame: str, base_frame: str) -> Any:
    p = odometry.pose
    cov = np.zeros(36, dtype=np.float64)
    pwc = message_class("geometry_msgs/msg/PoseWithCovariance")(
        pose=pose(p.x, p.y, p.heading), covariance=cov)
    twist = message_class(TWIST)(linear=vector3(odometry.v), angular=vector3(z=odometry.omega))
    twc = message_class("geometry_msgs/msg/TwistWithCovariance")(twist=twist, covariance=cov.copy())
    return message_class(ODOMETRY)(header=header(odometry.stamp, odom_frame),
                                   child_frame_id=base_frame, pose=pwc, twist=twc)


# --- velocity -------------------------------------------------------------------------


def twist(v: float, omega: float) -> Any:
    """A ``geometry_msgs/msg/Twist``: forward speed on x, turn rate about z."""
    return message_class(TWIST)(linear=vector3(v), angular=vector3(z=omega))


def twist_stamped(stamp: float, frame_id: str, v: float, omega: float) -> Any:
    return message_class(TWIST_STAMPED)(header=header(stamp, frame_id), twist=twist(v, omega))


def velocity_from_twist(msg: Any) -> tuple[float, float]:
    """(forward speed, turn rate) of a ``Twist``; a unicycle ignores the other axes."""
    v, omega = float(msg.linear.x), float(msg.angular.z)
    if not (math.isfinite(v) and math.isfinite(omega)):
        raise ConversionError("twist has a non-finite speed or turn rate")
    return v, omega

