"""ROS 2 <-> zenav conversions: scans as REP 117 defines them, odometry, velocities."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from tests.ros2 import samples
from zenav.services.ros2 import convert
from zenav.services.ros2.convert import ConversionError
from zenav.services.ros2.wire import LASER_SCAN, message_class


def ros_scan(ranges: Any, angle_min: float = -1.0, inc: float = 0.01, rmin: float = 0.1,
             rmax: float = 10.0, stamp: float = 3.25, angle_max: float | None = None) -> Any:
    ranges = np.asarray(ranges, dtype=np.float32)
    return message_class(LASER_SCAN)(
        header=convert.header(stamp, "base_scan"), angle_min=angle_min,
        angle_max=angle_min + inc * (ranges.size - 1) if angle_max is None else angle_max,
        angle_increment=inc, time_increment=0.0, scan_time=0.1, range_min=rmin,
        range_max=rmax, ranges=ranges, intensities=np.zeros(0, dtype=np.float32))


def test_rep117_ranges():
    msg = ros_scan([1.0, math.inf, -math.inf, math.nan, 0.05, 12.0, 0.0, 10.0])
    scan = convert.scan_from_ros(msg, seq=0)
    assert scan.ranges.tolist() == pytest.approx([1.0, 10.0, 0.1, 10.0, 10.0, 10.0, 10.0, 10.0])
    assert scan.stamp == 3.25 and scan.frame == "base_scan"


def test_any_angle_range_and_increment():
    # 360 degrees at 1 degree, starting behind the robot, as many 2D lidars publish
    n = 360
    msg = ros_scan(np.full(n, 2.0), angle_min=-math.pi, inc=2 * math.pi / n,
                   angle_max=math.pi)  # angle_max one step past the last beam, as some do
    scan = convert.scan_from_ros(msg, seq=0, frame="laser")
    assert scan.ranges.size == n and scan.frame == "laser"
    assert scan.angles()[0] == pytest.approx(-math.pi)
    assert scan.angles()[-1] == pytest.approx(math.pi - 2 * math.pi / n)


def test_clockwise_scan_is_reversed():
    msg = ros_scan([1.0, 2.0, 3.0], angle_min=0.5, inc=-0.25)
    scan = convert.scan_from_ros(msg, seq=0)
    assert scan.angle_increment == pytest.approx(0.25)
    assert scan.angle_min == pytest.approx(0.0)
    assert scan.ranges.tolist() == [3.0, 2.0, 1.0]  # beam at 0.0 rad was the last one


@pytest.mark.parametrize("bad", [
    dict(ranges=[]), dict(ranges=[1.0], inc=0.0), dict(ranges=[1.0], rmin=2.0, rmax=1.0),
    dict(ranges=[1.0], rmax=math.inf), dict(ranges=[1.0], angle_min=math.nan),
])
def test_unusable_scans_are_refused(bad):
    with pytest.raises(ConversionError):
        convert.scan_from_ros(ros_scan(**bad), seq=0)


def test_scan_round_trip_keeps_geometry_and_marks_no_return_as_inf():
    scan = samples.scan()
    msg = convert.scan_to_ros(scan)
    assert math.isinf(msg.ranges[10]) and msg.ranges[0] == pytest.approx(0.5)
    back = convert.scan_from_ros(msg, seq=scan.seq)
    assert back.stamp == scan.stamp
    assert back.angle_min == pytest.approx(scan.angle_min)
    assert back.angle_max == pytest.approx(scan.angle_max)
    np.testing.assert_array_equal(back.ranges, scan.ranges)


def test_odometry_both_ways():
    odom = samples.odometry()
    msg = convert.odometry_to_ros(odom, "odom", "base_link")
    assert msg.header.frame_id == "odom" and msg.child_frame_id == "base_link"
    assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == (12, 500_000_000)
    back = convert.odometry_from_ros(msg, seq=4)
    assert back.pose.heading == pytest.approx(2.0)
    assert back.model_copy(update={"pose": odom.pose}) == odom


def test_odometry_with_nan_is_refused():
    msg = convert.odometry_to_ros(samples.odometry(), "odom", "base_link")
    msg.pose.pose.position.x = math.nan
    with pytest.raises(ConversionError):
        convert.odometry_from_ros(msg, seq=0)


def test_stamps_survive_the_sec_nanosec_split():
    for stamp in (0.0, 0.1, 0.3, 57.6, 1_700_000_000.123456789):
        assert convert.stamp_of(convert.ros_time(stamp)) == pytest.approx(stamp, abs=1e-9)
    assert convert.stamp_of(convert.ros_time(0.3)) == 0.3


def test_twists():
    assert convert.velocity_from_twist(convert.twist(0.2, -0.5)) == (0.2, -0.5)
    stamped = convert.twist_stamped(4.5, "base_link", 0.2, 0.1)
    assert stamped.header.frame_id == "base_link"
    assert convert.stamp_of(stamped.header.stamp) == 4.5
    bad = convert.twist(math.inf, 0.0)
    with pytest.raises(ConversionError):
        convert.velocity_from_twist(bad)
