"""The ros2 backends on the in-memory bus: the laser driver reads a ROS 2 robot's
LaserScan and Odometry from rmw_zenoh keys, the motor bridge sends it Twist or
TwistStamped with the rmw_zenoh attachment, and both announce themselves with the
liveliness tokens ``ros2 node list`` / ``ros2 topic list`` read."""

from __future__ import annotations

import numpy as np

from tests.ros2 import samples
from tests.service.harness import running
from zenav.schemas import keys
from zenav.schemas.messages import BaseCommand, LaserScan, Odometry, VelocityCommand
from zenav.services.laser_driver.params import Params as LaserParams
from zenav.services.motor_bridge.params import Params as BridgeParams
from zenav.services.ros2 import convert, wire
from zenav.services.ros2.params import Ros2Params

SCAN_KEY = wire.topic_key(0, "/scan", wire.LASER_SCAN)
ODOM_KEY = wire.topic_key(0, "/odom", wire.ODOMETRY)


def tokens(h) -> list[wire.TokenInfo]:
    return [wire.parse_token(k) for k in sorted(h.bus._alive) if k.startswith("@ros2_lv/")]


async def test_laser_driver_reads_ros2_scans_and_odometry():
    params = LaserParams(backend="ros2")
    async with running("laser_driver", params) as h:
        ros_scan = convert.scan_to_ros(samples.scan())
        h.bus.deliver(SCAN_KEY, wire.serialize(ros_scan, wire.LASER_SCAN))
        odom = convert.odometry_to_ros(samples.odometry(), "odom", "base_link")
        h.bus.deliver(ODOM_KEY, wire.serialize(odom, wire.ODOMETRY))
        await h.settle()
        scans = h.received(keys.SCAN, LaserScan)
        odoms = h.received(keys.ODOM, Odometry)
        graph = tokens(h)
    assert len(scans) == 1 and scans[0].stamp == 12.5 and scans[0].frame == "laser"
    np.testing.assert_array_equal(scans[0].ranges, samples.scan().ranges)
    assert len(odoms) == 1 and (odoms[0].pose.x, odoms[0].v) == (1.25, 0.3)
    kinds = {(t.kind, t.topic) for t in graph}
    assert kinds == {("NN", None), ("MS", "/scan"), ("MS", "/odom")}
    assert {t.node_name for t in graph} == {"zenav_laser_driver"}
    scan_token = next(t for t in graph if t.topic == "/scan")
    assert scan_token.qos == "2::,5:,:,:,," and scan_token.type_hash == wire.type_hash(
        wire.LASER_SCAN)


async def test_laser_driver_counts_bad_ros2_input_and_carries_on():
    async with running("laser_driver", LaserParams(backend="ros2")) as h:
        bad = convert.scan_to_ros(samples.scan())
        bad.angle_increment = 0.0
        for payload in (b"\x00\x01\x00\x00not a scan", wire.serialize(bad, wire.LASER_SCAN),
                        wire.serialize(convert.scan_to_ros(samples.scan(1.0)), wire.LASER_SCAN),
                        wire.serialize(convert.scan_to_ros(samples.scan(0.5)), wire.LASER_SCAN)):
            h.bus.deliver(SCAN_KEY, payload)  # the last one is older: refused
            await h.settle()
        assert h.node.rejected["bad_ros2"] == 2
        assert h.node.rejected["out_of_order"] == 1
        assert [s.stamp for s in h.received(keys.SCAN, LaserScan)] == [1.0]


async def test_laser_driver_namespace_domain_and_topic_names_are_parameters():
    r2 = Ros2Params(domain_id=7, namespace="/robot1", scan_topic="lidar/scan",
                    odom_topic="/wheel/odom", node_name="nav_input")
    async with running("laser_driver", LaserParams(backend="ros2", ros2=r2)) as h:
        key = wire.topic_key(7, "/robot1/lidar/scan", wire.LASER_SCAN)
        h.bus.deliver(key, wire.serialize(convert.scan_to_ros(samples.scan()), wire.LASER_SCAN))
        h.bus.deliver(SCAN_KEY, wire.serialize(convert.scan_to_ros(samples.scan(20.0)),
                                               wire.LASER_SCAN))  # domain 0: not ours
        await h.settle()
        assert [s.stamp for s in h.received(keys.SCAN, LaserScan)] == [12.5]
        graph = tokens(h)
    assert {(t.domain_id, t.namespace, t.node_name) for t in graph} == {(7, "/robot1", "nav_input")}
    assert {t.topic for t in graph} == {None, "/robot1/lidar/scan", "/wheel/odom"}


async def bridge_out(params: BridgeParams):
    async with running("motor_bridge", params) as h:
        h.send(keys.CMD_VEL, VelocityCommand(stamp=2.0, seq=0, v=0.05, omega=0.2))
        await h.settle()
        key = wire.topic_key(0, "/cmd_vel", params.ros2.cmd_vel_type)
        sent = [(i, p) for i, (k, p) in enumerate(h.bus.published) if k == key]
        native = h.received(keys.BASE_CMD, BaseCommand)
        mp = [k for k in h.bus._alive if "/MP/" in k]
        return h, sent, native, tokens(h), mp


async def test_motor_bridge_sends_twist_with_the_rmw_zenoh_attachment():
    h, sent, native, graph, mp = await bridge_out(BridgeParams(backend="ros2"))
    assert len(sent) == 1 and len(native) == 1
    index, payload = sent[0]
    twist = wire.deserialize(payload, wire.TWIST)
    assert convert.velocity_from_twist(twist) == (native[0].v, native[0].omega)
    attachment = wire.Attachment.decode(h.bus.attachments[index])
    publisher = next(t for t in graph if t.kind == "MP")
    assert attachment.sequence_number == 1 and attachment.source_timestamp_ns > 0
    assert publisher.topic == "/cmd_vel" and publisher.qos == "::,10:,:,:,,"
    assert len(mp) == 1 and attachment.gid == wire.gid_of(mp[0])


async def test_motor_bridge_sends_twist_stamped_when_asked():
    params = BridgeParams(backend="ros2", ros2=Ros2Params(twist_stamped=True))
    _, sent, native, graph, _ = await bridge_out(params)
    msg = wire.deserialize(sent[0][1], wire.TWIST_STAMPED)
    assert convert.stamp_of(msg.header.stamp) == 2.0 and msg.header.frame_id == "base_link"
    assert convert.velocity_from_twist(msg.twist) == (native[0].v, native[0].omega)
    assert any(t.dds_type == "geometry_msgs::msg::dds_::TwistStamped_" for t in graph)


async def test_native_backends_declare_nothing_on_ros2():
    _, sent, native, graph, _ = await bridge_out(BridgeParams())
    assert sent == [] and len(native) == 1 and graph == []
