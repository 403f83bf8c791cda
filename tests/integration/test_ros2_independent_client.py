"""zenav against a ROS-2-over-Zenoh implementation nobody here wrote: the
``zenoh-ros2-sdk`` package plays the robot. It computes its own type hashes, keys and
tokens from message definitions given to it locally (it would otherwise clone them),
publishes LaserScan and Odometry, receives zenav's Twist, and lists zenav's nodes and
topics from their liveliness tokens, as ``ros2 topic info`` would on a real robot.

Topology as on a robot with rmw_zenoh: a Zenoh router on loopback; the SDK as a peer
connected to it (its rmw_zenoh-like default); zenav's laser driver and motor bridge as
separate processes, clients of the router.
"""

from __future__ import annotations

import contextlib
import json
import math
import socket
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import zenoh

from zenav.schemas.codec import decode, encode
from zenav.schemas.messages import LaserScan, Odometry, VelocityCommand
from zenav.services.ros2 import wire

pytestmark = pytest.mark.integration

sdk = pytest.importorskip("zenoh_ros2_sdk")

TYPES = (wire.LASER_SCAN, wire.ODOMETRY, wire.TWIST)
SEPARATOR = "=" * 80 + "\n"


def write_definitions(root: Path) -> None:
    """Every .msg file the SDK needs, laid out as <package>/msg/<Name>.msg, from the
    definitions that rosbags carries (the SDK parses and hashes them itself)."""
    for ros_type in TYPES:
        text, _ = wire.typestore().generate_msgdef(ros_type, ros_version=2)
        sections = text.split(SEPARATOR)
        names = [ros_type] + [s.split("\n", 1)[0].removeprefix("MSG: ") for s in sections[1:]]
        bodies = [sections[0]] + [s.split("\n", 1)[1] for s in sections[1:]]
        for name, body in zip(names, bodies, strict=True):
            package, *_, msg = name.split("/")
            path = root / package / "msg" / f"{msg}.msg"
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(body)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def wait_for(what: str, check: Callable[[], bool], action: Callable[[], None] | None = None,
             timeout: float = 30.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if action is not None:
            action()
        if check():
            return
        time.sleep(0.2)
    raise AssertionError(f"timed out waiting for {what}")


@pytest.fixture
def network(tmp_path: Path) -> Iterator[dict[str, Any]]:
    port = free_port()
    endpoint = f"tcp/127.0.0.1:{port}"
    conf = zenoh.Config()
    conf.insert_json5("mode", '"router"')
    conf.insert_json5("listen/endpoints", json.dumps([endpoint]))
    conf.insert_json5("scouting/multicast/enabled", "false")
    stack = contextlib.ExitStack()
    stack.enter_context(zenoh.open(conf))  # the router, as rmw_zenohd would be
    procs = []
    for name in ("laser_driver", "motor_bridge"):
        log = (tmp_path / f"{name}.log").open("w")
        procs.append(subprocess.Popen(
            [sys.executable, "-m", "zenav", "service", name, "--set", "backend=ros2",
             "--mode", "client", "--connect", endpoint],
            stdout=log, stderr=subprocess.STDOUT))
    client_conf = zenoh.Config()
    client_conf.insert_json5("mode", '"client"')
    client_conf.insert_json5("connect/endpoints", json.dumps([endpoint]))
    zenav_side = stack.enter_context(zenoh.open(client_conf))
    defs = tmp_path / "msg"
    write_definitions(defs)
    from zenoh_ros2_sdk import message_registry

    message_registry._registry = None  # a fresh registry over the local definitions
    message_registry.get_registry(str(defs))
    try:
        yield {"port": port, "zenav": zenav_side, "logs": tmp_path}
    finally:
        from zenoh_ros2_sdk.session import ZenohSession

        for proc in procs:
            proc.terminate()
        for proc in procs:
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()
        if ZenohSession._instance is not None:
            ZenohSession._instance.close()
        message_registry._registry = None
        stack.close()


def test_sdk_robot_and_zenav_understand_each_other(network):
    from zenoh_ros2_sdk import ROS2Publisher, ROS2Subscriber, get_message_class, get_topic_info
    from zenoh_ros2_sdk.attachment import Attachment as SdkAttachment
    from zenoh_ros2_sdk.session import ZenohSession

    port, zenav_side = network["port"], network["zenav"]
    where = {"router_ip": "127.0.0.1", "router_port": port}
    scan_pub = ROS2Publisher("/scan", wire.LASER_SCAN, node_name="robot_lidar", **where,
                             qos="2::,5:,:,:,,")
    odom_pub = ROS2Publisher("/odom", wire.ODOMETRY, node_name="robot_base", **where)
    twists: list[Any] = []
    ROS2Subscriber("/cmd_vel", wire.TWIST, twists.append, node_name="robot_base_cmd", **where)
    # the SDK's own keys for the three topics are the ones zenav computes
    assert scan_pub.keyexpr == wire.topic_key(0, "/scan", wire.LASER_SCAN)
    assert odom_pub.keyexpr == wire.topic_key(0, "/odom", wire.ODOMETRY)

    # raw view of /cmd_vel from the SDK's session, for the attachment
    attachments: list[bytes] = []
    raw = ZenohSession.get_instance().session.declare_subscriber(
        wire.topic_key(0, "/cmd_vel", wire.TWIST),
        lambda s: attachments.append(s.attachment.to_bytes()) if s.attachment else None)

    zenav_scans: list[LaserScan] = []
    zenav_odoms: list[Odometry] = []
    subs = [
        zenav_side.declare_subscriber("zenav/robot0/scan", lambda s: zenav_scans.append(
            decode(s.payload.to_bytes(), LaserScan, "scan"))),
        zenav_side.declare_subscriber("zenav/robot0/odom", lambda s: zenav_odoms.append(
            decode(s.payload.to_bytes(), Odometry, "odom"))),
    ]
    Header, Time = get_message_class("std_msgs/msg/Header"), get_message_class(
        "builtin_interfaces/msg/Time")
    n = 720  # a 360-degree lidar at 0.5 degrees
    ranges = np.full(n, 4.0, dtype=np.float32)
    ranges[5], ranges[6] = math.inf, math.nan
    stamp = [100.0]

    def send_scan() -> None:
        stamp[0] += 0.1
        scan_pub.publish(
            header=Header(stamp=Time(sec=int(stamp[0]), nanosec=round(stamp[0] % 1 * 1e9)),
                          frame_id="base_scan"),
            angle_min=-math.pi, angle_max=math.pi - math.pi / 360,
            angle_increment=math.pi / 360, time_increment=0.0, scan_time=0.1, range_min=0.12,
            range_max=3.5 + 8.0, ranges=ranges, intensities=np.zeros(0, dtype=np.float32))

    wait_for("zenav's scan from the SDK's LaserScan", lambda: bool(zenav_scans), send_scan)
    got = zenav_scans[-1]
    assert got.ranges.size == n and got.angle_min == pytest.approx(-math.pi)
    assert got.ranges[5] == got.ranges[6] == pytest.approx(11.5)  # no return
    assert got.ranges[0] == 4.0 and got.frame == "laser"

    yaw = 0.7

    def send_odometry() -> None:
        cls = get_message_class
        position = cls("geometry_msgs/msg/Point")(x=1.0, y=2.0, z=0.0)
        q = cls("geometry_msgs/msg/Quaternion")(x=0.0, y=0.0, z=math.sin(yaw / 2),
                                                w=math.cos(yaw / 2))
        pose = cls("geometry_msgs/msg/PoseWithCovariance")(
            pose=cls("geometry_msgs/msg/Pose")(position=position, orientation=q),
            covariance=np.zeros(36))
        v3 = cls("geometry_msgs/msg/Vector3")
        twist = cls("geometry_msgs/msg/TwistWithCovariance")(
            twist=cls(wire.TWIST)(linear=v3(x=0.25, y=0.0, z=0.0),
                                  angular=v3(x=0.0, y=0.0, z=0.1)),
            covariance=np.zeros(36))
        odom_pub.publish(header=Header(stamp=Time(sec=int(stamp[0]), nanosec=0),
                                       frame_id="odom"),
                         child_frame_id="base_footprint", pose=pose, twist=twist)

    wait_for("zenav's odometry from the SDK's Odometry", lambda: bool(zenav_odoms), send_odometry)
    odom = zenav_odoms[-1]
    assert (odom.pose.x, odom.pose.y, odom.v, odom.omega) == (1.0, 2.0, 0.25, 0.1)
    assert odom.pose.heading == pytest.approx(yaw)

    command = zenav_side.declare_publisher("zenav/robot0/cmd_vel")
    seq = [0]

    def send_command() -> None:
        seq[0] += 1
        command.put(encode(VelocityCommand(stamp=stamp[0] + seq[0] * 0.1, seq=seq[0], v=0.04,
                                           omega=0.1)))

    wait_for("the SDK's Twist from zenav's motor bridge", lambda: bool(twists), send_command)
    twist = twists[0]
    assert (twist.linear.x, twist.angular.z) == pytest.approx((0.04, 0.1))
    wait_for("the attachment", lambda: bool(attachments))
    att = SdkAttachment.from_bytes(attachments[0])
    assert len(att.gid) == 16 and att.timestamp_ns > 1_600_000_000 * 10**9

    info = get_topic_info("/cmd_vel", verbose=True, **where, timeout=2.0)
    assert info is not None
    assert [p.node_name for p in info.publishers] == ["zenav_motor_bridge"]
    assert info.publishers[0].topic_type == wire.TWIST
    for topic, node in (("/scan", "zenav_laser_driver"), ("/odom", "zenav_laser_driver")):
        info = get_topic_info(topic, verbose=True, **where, timeout=2.0)
        assert info is not None and node in [s.node_name for s in info.subscribers]
    raw.undeclare()
    for sub in subs:
        sub.undeclare()
    command.undeclare()
