"""The rmw_zenoh wire: keys, type hashes, QoS strings, attachments, liveliness tokens.

The expected strings are the examples of rmw_zenoh's design document (docs/design.md),
which were taken from running ROS 2 nodes, and the Twist hash that public rmw_zenoh
examples use for /cmd_vel.
"""

from __future__ import annotations

import struct

import pytest
import xxhash

from zenav.services.ros2 import wire
from zenav.services.ros2.wire import Attachment, NodeIdentity, QoS, WireError

STRING_HASH = "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"


def test_twist_hash_is_the_one_robots_use():
    assert wire.type_hash(wire.TWIST) == (
        "RIHS01_9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a")


def test_string_hash_and_chatter_key_match_the_design_document():
    assert wire.type_hash("std_msgs/msg/String") == STRING_HASH
    assert wire.topic_key(0, "/chatter", "std_msgs/msg/String") == (
        f"0/chatter/std_msgs::msg::dds_::String_/{STRING_HASH}")
    assert wire.topic_key(0, wire.qualify("chatter", "/robot1"), "std_msgs/msg/String") == (
        f"0/robot1/chatter/std_msgs::msg::dds_::String_/{STRING_HASH}")


def test_every_used_type_has_a_hash_and_a_dds_name():
    for ros_type in wire.USED_TYPES:
        assert wire.type_hash(ros_type).startswith("RIHS01_")
        assert len(wire.type_hash(ros_type)) == len("RIHS01_") + 64
    assert wire.dds_type_name(wire.LASER_SCAN) == "sensor_msgs::msg::dds_::LaserScan_"
    assert wire.dds_type_name(wire.MARKER_ARRAY) == "visualization_msgs::msg::dds_::MarkerArray_"


def test_liveliness_tokens_match_the_design_document():
    talker = NodeIdentity(domain_id=2, session_id="8b20917502ee955ac4476e0266340d5c",
                          name="talker")
    assert talker.entity_token(10, "MP", "/chatter", "std_msgs/msg/String", QoS(depth=7)) == (
        "@ros2_lv/2/8b20917502ee955ac4476e0266340d5c/0/10/MP/%/%/talker/%chatter/"
        f"std_msgs::msg::dds_::String_/{STRING_HASH}/::,7:,:,:,,")
    listener = NodeIdentity(domain_id=2, session_id="aac3178e146ba6f1fc6e6a4085e77f21",
                            name="listener")
    assert listener.node_token() == (
        "@ros2_lv/2/aac3178e146ba6f1fc6e6a4085e77f21/0/0/NN/%/%/listener")
    assert listener.entity_token(10, "MS", "/chatter", "std_msgs/msg/String", QoS()) == (
        "@ros2_lv/2/aac3178e146ba6f1fc6e6a4085e77f21/0/10/MS/%/%/listener/%chatter/"
        f"std_msgs::msg::dds_::String_/{STRING_HASH}/::,10:,:,:,,")


def test_namespaced_node_token_mangles_every_slash():
    node = NodeIdentity(domain_id=0, session_id="ab", name="zenav", namespace="/robot1/nav")
    token = node.entity_token(3, "MP", "/robot1/nav/cmd_vel", wire.TWIST, wire.DEFAULT_QOS)
    assert "/%robot1%nav/zenav/%robot1%nav%cmd_vel/" in token
    info = wire.parse_token(token)
    assert (info.namespace, info.node_name, info.topic, info.kind) == (
        "/robot1/nav", "zenav", "/robot1/nav/cmd_vel", "MP")
    assert info.type_hash == wire.type_hash(wire.TWIST)


def test_qos_strings():
    assert wire.SENSOR_QOS.to_keyexpr() == "2::,5:,:,:,,"
    assert QoS(depth=42).to_keyexpr() == "::,:,:,:,,"
    assert QoS(durability="transient_local", depth=1).to_keyexpr() == ":1:,1:,:,:,,"
    assert QoS(history="keep_all").to_keyexpr() == "::2,10:,:,:,,"


def test_attachment_layout_is_seq_time_then_length_prefixed_gid():
    gid = bytes(range(16))
    data = Attachment(7, 1_700_000_000_123_456_789, gid).encode()
    assert len(data) == 33
    assert data[:8] == struct.pack("<q", 7)
    assert data[8:16] == struct.pack("<q", 1_700_000_000_123_456_789)
    assert data[16] == 16 and data[17:] == gid
    assert Attachment.decode(data) == Attachment(7, 1_700_000_000_123_456_789, gid)


@pytest.mark.parametrize("data", [b"", bytes(32), bytes(16) + b"\x08" + bytes(16)])
def test_bad_attachments_are_refused(data):
    with pytest.raises(WireError):
        Attachment.decode(data)


def test_gid_is_xxh3_128_of_the_token_low_half_first():
    token = "@ros2_lv/0/ab/0/1/MP/%/%/n/%t/std_msgs::msg::dds_::String_/x/::,10:,:,:,,"
    gid = wire.gid_of(token)
    value = xxhash.xxh3_128(token.encode()).intdigest()
    assert gid[:8] == (value & (2**64 - 1)).to_bytes(8, "little")
    assert gid[8:] == (value >> 64).to_bytes(8, "little")


@pytest.mark.parametrize(("name", "namespace"), [("", "/"), ("scan/", "/"), ("9scan", "/"),
                                                 ("scan", "robot"), ("a//b", "/")])
def test_bad_names_are_refused(name, namespace):
    with pytest.raises(WireError):
        wire.qualify(name, namespace)


def test_bad_identities_and_types_are_refused():
    with pytest.raises(WireError):
        NodeIdentity(domain_id=300, session_id="ab", name="n")
    with pytest.raises(WireError):
        NodeIdentity(domain_id=0, session_id="ab", name="my-node")
    with pytest.raises(WireError):
        wire.type_hash("geometry_msgs/msg/NoSuchThing")
    with pytest.raises(WireError):
        wire.parse_token("zenav/robot0/alive/planner")


def test_truncated_cdr_is_a_wire_error():
    payload = wire.serialize(wire.message_class(wire.TWIST)(
        linear=wire.message_class("geometry_msgs/msg/Vector3")(x=1.0, y=0.0, z=0.0),
        angular=wire.message_class("geometry_msgs/msg/Vector3")(x=0.0, y=0.0, z=0.5)),
        wire.TWIST)
    with pytest.raises(WireError):
        wire.deserialize(payload[:20], wire.TWIST)
