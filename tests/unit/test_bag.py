"""The MCAP layout of ``zenav record`` files, written and read without a bus."""

from __future__ import annotations

import io
import json
from pathlib import Path

import pytest
from mcap.reader import make_reader

from zenav.bag.mcapfile import BagWriter, MsgpackDecoderFactory, read_bag, recorded_robot
from zenav.schemas.codec import encode
from zenav.schemas.messages import Odometry, Pose2D, ServiceStatus, VelocityCommand

NS = 1_000_000_000


def odom(stamp: float, seq: int) -> Odometry:
    return Odometry(stamp=stamp, seq=seq, pose=Pose2D(x=1.0, y=2.0, heading=0.0), v=0.1,
                    omega=0.0)


@pytest.fixture
def bag(tmp_path: Path) -> Path:
    path = tmp_path / "run.mcap"
    with path.open("wb") as stream:
        writer = BagWriter(stream, "r7", exclude=("sim/truth",))
        writer.liveliness("zenav/r7/alive/planner", True, 5 * NS)
        writer.add("zenav/r7/odom", encode(odom(0.5, 3)), 10 * NS)
        writer.add("zenav/r7/cmd_vel", encode(VelocityCommand(stamp=0.5, seq=9, v=0.1,
                                                              omega=0.0)), 11 * NS)
        writer.add("zenav/r7/odom", encode(odom(0.6, 4)), 12 * NS)
        writer.add("zenav/r7/status/planner", encode(ServiceStatus(
            stamp=0.0, seq=0, service="planner", received={}, rejected={}, dropped={})), 13 * NS)
        writer.add("zenav/r7/sim/truth", b"excluded", 14 * NS)
        writer.add("zenav/other/odom", b"another robot", 14 * NS)
        writer.add("zenav/r7/custom/thing", b"\x80", 15 * NS)  # unknown: kept, no schema
        writer.close()
        assert writer.count == 5
    return path


def test_one_channel_per_key_with_the_message_schema_and_stamps(bag):
    with bag.open("rb") as stream:
        reader = make_reader(stream)
        summary = reader.get_summary()
        assert summary is not None
        channels = {c.topic: c for c in summary.channels.values()}
        assert set(channels) == {"zenav/r7/alive/planner", "zenav/r7/odom", "zenav/r7/cmd_vel",
                                 "zenav/r7/status/planner", "zenav/r7/custom/thing"}
        assert channels["zenav/r7/odom"].message_encoding == "msgpack"
        assert channels["zenav/r7/odom"].metadata == {"zenav_type": "odometry"}
        assert channels["zenav/r7/alive/planner"].message_encoding == "json"
        assert channels["zenav/r7/custom/thing"].schema_id == 0
        schema = summary.schemas[channels["zenav/r7/odom"].schema_id]
        assert schema.name == "zenav.Odometry" and schema.encoding == "jsonschema"
        assert json.loads(schema.data) == Odometry.model_json_schema(mode="serialization")
        messages = [(c.topic, m.log_time, m.publish_time, m.sequence)
                    for _, c, m in reader.iter_messages(log_time_order=True)]
        metadata = {r.name: r.metadata for r in reader.iter_metadata()}
    assert messages[:3] == [("zenav/r7/alive/planner", 5 * NS, 5 * NS, 0),
                            ("zenav/r7/odom", 10 * NS, NS // 2, 3),
                            ("zenav/r7/cmd_vel", 11 * NS, NS // 2, 9)]
    assert metadata["zenav"]["robot_id"] == "r7"
    assert metadata["zenav"]["schema_version"] == "1"


def test_the_decoder_factory_gives_the_pydantic_messages(bag):
    with bag.open("rb") as stream:
        reader = make_reader(stream, decoder_factories=[MsgpackDecoderFactory()])
        decoded = [d for _, _, _, d in reader.iter_decoded_messages(topics=["zenav/r7/odom"])]
    assert decoded == [odom(0.5, 3), odom(0.6, 4)]


def test_read_bag_yields_payloads_in_log_time_order_filtered_by_topic(bag):
    assert recorded_robot(bag) == "r7"
    items = list(read_bag(bag, {"odom", "cmd_vel"}))
    assert [(i.topic, i.log_time) for i in items] == [("odom", 10 * NS), ("cmd_vel", 11 * NS),
                                                      ("odom", 12 * NS)]
    assert items[0].payload == encode(odom(0.5, 3))  # byte for byte what was on the bus
    assert {i.topic for i in read_bag(bag)} == {"odom", "cmd_vel", "status/planner",
                                                "custom/thing"}  # no liveliness


def test_a_file_not_made_by_zenav_record_is_refused(tmp_path):
    from mcap.writer import Writer

    path = tmp_path / "other.mcap"
    buffer = io.BytesIO()
    writer = Writer(buffer)
    writer.start()
    writer.finish()  # type: ignore[no-untyped-call]
    path.write_bytes(buffer.getvalue())
    with pytest.raises(ValueError, match="no zenav metadata"):
        recorded_robot(path)
