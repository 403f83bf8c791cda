"""Every ROS 2 message type zenav uses, built by zenav's own conversions, through CDR
and back with rosbags: what zenav sends is what a ROS 2 node reads."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from tests.ros2 import samples
from zenav.schemas.messages import BaseCommand, OccupancyMap
from zenav.services.motor_bridge.output import command_to_ros
from zenav.services.ros2 import convert, view, wire
from zenav.services.ros2.params import Ros2Params


def through_cdr(message: Any, ros_type: str) -> Any:
    payload = wire.serialize(message, ros_type)
    assert payload[:4] == b"\x00\x01\x00\x00"  # CDR little-endian encapsulation
    return wire.deserialize(payload, ros_type)


def test_laser_scan():
    scan = samples.scan()
    back = convert.scan_from_ros(through_cdr(convert.scan_to_ros(scan), wire.LASER_SCAN), 3)
    assert (back.stamp, back.frame, back.range_max) == (scan.stamp, scan.frame, scan.range_max)
    # float32 on the ROS wire: angles to float32 precision
    for name in ("angle_min", "angle_max", "angle_increment", "scan_time"):
        assert getattr(back, name) == pytest.approx(getattr(scan, name), rel=1e-6)
    assert back.ranges.tolist() == scan.ranges.tolist()


def test_odometry():
    odom = samples.odometry()
    back = through_cdr(convert.odometry_to_ros(odom, "odom", "base_link"), wire.ODOMETRY)
    assert back.child_frame_id == "base_link"
    got = convert.odometry_from_ros(back, 4)
    assert got.pose.heading == pytest.approx(odom.pose.heading)
    assert (got.pose.x, got.pose.y, got.v, got.omega) == (1.25, -0.5, 0.3, -0.4)


@pytest.mark.parametrize("stamped", [False, True])
def test_twist_and_twist_stamped_as_the_motor_bridge_sends_them(stamped):
    params = Ros2Params(twist_stamped=stamped, base_frame="base_footprint")
    command = BaseCommand(stamp=7.25, seq=1, v=0.15, omega=-0.3)
    back = through_cdr(command_to_ros(command, params), params.cmd_vel_type)
    if stamped:
        assert back.header.frame_id == "base_footprint"
        assert convert.stamp_of(back.header.stamp) == 7.25
        back = back.twist
    assert convert.velocity_from_twist(back) == (0.15, -0.3)
    assert (back.linear.y, back.linear.z, back.angular.x, back.angular.y) == (0, 0, 0, 0)


def test_marker_array():
    tracks = samples.tracks()
    back = through_cdr(view.tracks_to_markers(tracks, "odom", samples.state()),
                       wire.MARKER_ARRAY)
    markers = back.markers
    assert markers[0].action == view.DELETEALL
    cylinders = {m.id: m for m in markers if m.ns == "tracks"}
    assert set(cylinders) == {1, 2, 3}
    assert (cylinders[1].color.r, cylinders[1].color.g) == pytest.approx(
        view.COLOURS["dynamic"][:2])
    assert cylinders[2].color.r == pytest.approx(view.COLOURS["static"][0])
    assert cylinders[1].pose.position.x == 3.0 and cylinders[1].scale.x == pytest.approx(0.6)
    arrows = [m for m in markers if m.ns == "velocity"]
    assert [m.id for m in arrows] == [1]  # only the moving track
    start, end = arrows[0].points
    assert (end.x - start.x, end.y - start.y) == pytest.approx((0.4, 0.3))
    text = next(m for m in markers if m.ns == "planner")
    assert text.type == view.TEXT and text.text == "(c) slow 0.10 m/s"
    assert all(m.header.frame_id == "odom" for m in markers[1:])


def test_path():
    points = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0)]
    back = through_cdr(view.path_to_ros(points, 3.5, "odom"), wire.PATH)
    assert [(p.pose.position.x, p.pose.position.y) for p in back.poses] == points
    assert convert.yaw_of(back.poses[1].pose.orientation) == pytest.approx(math.pi / 2)
    assert back.header.frame_id == "odom"


def test_occupancy_grid():
    cells = np.array([-1, 0, 100, 0, 0, -1], dtype=np.int8)  # 3 x 2, row by row
    grid = OccupancyMap(stamp=2.25, seq=0, origin=(1.5, -2.0), resolution=0.05, width=3,
                        height=2, cells=cells)
    back = through_cdr(view.map_to_ros(grid, "odom"), wire.OCCUPANCY_GRID)
    assert back.data.tolist() == cells.tolist()
    assert (back.info.width, back.info.height) == (3, 2)
    assert back.info.resolution == pytest.approx(0.05)
    assert (back.info.origin.position.x, back.info.origin.position.y) == (1.5, -2.0)
    assert convert.stamp_of(back.info.map_load_time) == 2.25
    assert back.header.frame_id == "odom"
