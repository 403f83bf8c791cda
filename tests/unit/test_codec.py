"""Codec round trips and every validation error, with the key and reason named."""

from __future__ import annotations

import math

import msgpack
import numpy as np
import pytest

from zenav.schemas import keys
from zenav.schemas.codec import SCHEMA_VERSION, DecodeError, decode, encode
from zenav.schemas.keys import Keys
from zenav.schemas.messages import (
    ALL_MESSAGES,
    BaseCommand,
    LaserScan,
    Obstacle,
    ObstacleChain,
    Odometry,
    Pose2D,
    RunResult,
    VelocityCommand,
)

KEY = "zenav/robot0/scan"


def scan(**overrides: object) -> LaserScan:
    fields: dict[str, object] = dict(
        stamp=1.5, seq=3, frame="laser", angle_min=-math.pi / 2, angle_max=math.pi / 2,
        angle_increment=math.radians(0.5), range_min=0.0, range_max=8.0,
        ranges=np.linspace(0.5, 7.5, 361, dtype=np.float32),
    )
    fields.update(overrides)
    return LaserScan.model_validate(fields)


def raw_scan_fields(**overrides: object) -> bytes:
    fields = scan().model_dump(mode="python")
    fields.update({"_v": SCHEMA_VERSION, "_t": LaserScan.TYPE})
    fields.update(overrides)
    return msgpack.packb(fields, use_bin_type=True)


def test_scan_round_trip_keeps_every_value():
    original = scan()
    decoded = decode(encode(original), LaserScan, KEY)
    assert decoded.stamp == 1.5 and decoded.seq == 3 and decoded.frame == "laser"
    assert decoded.ranges.dtype == np.float32
    np.testing.assert_array_equal(decoded.ranges, original.ranges)
    assert decoded.angles()[180] == pytest.approx(0.0)


def test_ranges_travel_as_raw_float32_bytes():
    fields = msgpack.unpackb(encode(scan()), raw=False)
    assert isinstance(fields["ranges"], bytes)
    assert len(fields["ranges"]) == 361 * 4
    assert len(encode(scan())) < 1700


def test_nested_messages_round_trip():
    chain = ObstacleChain(
        stamp=2.0, seq=0, pose=Pose2D(x=1.0, y=2.0, heading=0.5), window_radius=4.0, cell=0.5,
        obstacles=[Obstacle(x=3.0, y=2.0, rho=2.0, alpha=0.1, cells=(5, 7, 3, 4), area=6,
                            beams=(170, 190), n_beams=21, first=(3.0, 1.8), last=(3.0, 2.2),
                            chord=(3.0, 2.0), radius=0.2, edges=(0, 1))],
    )
    assert decode(encode(chain), ObstacleChain) == chain


def test_trajectory_array_round_trip():
    rows = np.arange(20, dtype=np.float64).reshape(4, 5)
    result = RunResult(stamp=3.0, seq=0, scenario="x", outcome="reached", time=3.0,
                       path_length=1.0, min_clearance=math.inf, trajectory=rows)
    decoded = decode(encode(result), RunResult, max_bytes=10**6)
    np.testing.assert_array_equal(decoded.trajectory, rows)
    assert math.isinf(decoded.min_clearance)


@pytest.mark.parametrize(
    ("payload", "kind", "words"),
    [
        (b"\xc1\x00\xff garbage", "msgpack", "not a msgpack"),
        (encode(scan())[:-40], "msgpack", "not a msgpack"),
        (msgpack.packb([1, 2, 3]), "envelope", "expected a map"),
        (msgpack.packb({"stamp": 1.0}), "envelope", "missing '_v'"),
        (raw_scan_fields(_v=SCHEMA_VERSION + 1), "version", "schema version 2"),
        (raw_scan_fields(_t="odometry"), "type", "expected 'laser_scan'"),
        (raw_scan_fields(ranges=np.full(360, 1.0, np.float32).tobytes()), "invalid",
         "wrong beam count"),
        (raw_scan_fields(ranges=np.full(361, np.nan, np.float32).tobytes()), "invalid",
         "non-finite range"),
        (raw_scan_fields(ranges=np.full(361, np.inf, np.float32).tobytes()), "invalid",
         "non-finite range"),
        (raw_scan_fields(ranges=np.full(361, -1.0, np.float32).tobytes()), "invalid",
         "negative range"),
        (raw_scan_fields(ranges=np.full(361, 9.0, np.float32).tobytes()), "invalid",
         "above range_max"),
        (raw_scan_fields(ranges=b"\x00\x01\x02"), "invalid", "not a multiple of 4"),
        (raw_scan_fields(stamp=-1.0), "invalid", "stamp"),
        (raw_scan_fields(stamp=float("nan")), "invalid", "stamp"),
        (raw_scan_fields(extra_field=1), "invalid", "extra_field"),
        (raw_scan_fields(seq="seven"), "invalid", "seq"),
        (b"\x00" * 70_000, "size", "exceeds"),
    ],
    ids=["random-bytes", "truncated", "not-a-map", "no-envelope", "version", "wrong-type",
         "beam-count", "nan", "inf", "negative", "over-max", "ragged-bytes", "past-stamp",
         "nan-stamp", "unknown-field", "wrong-type-field", "oversized"],
)
def test_bad_payloads_give_a_typed_error_naming_key_and_reason(payload, kind, words):
    with pytest.raises(DecodeError) as caught:
        decode(payload, LaserScan, KEY)
    assert caught.value.kind == kind
    assert caught.value.key == KEY
    assert words in str(caught.value)
    assert str(caught.value).startswith(KEY)


def test_non_finite_pose_is_rejected():
    fields = {"_v": SCHEMA_VERSION, "_t": "odometry", "stamp": 0.0, "seq": 0,
              "pose": {"x": float("inf"), "y": 0.0, "heading": 0.0}, "v": 0.0, "omega": 0.0}
    with pytest.raises(DecodeError, match=r"pose\.x"):
        decode(msgpack.packb(fields), Odometry, "zenav/r/odom")


def test_every_message_type_has_a_unique_wire_name_and_json_schema():
    names = [m.TYPE for m in ALL_MESSAGES]
    assert len(set(names)) == len(names)
    for message in ALL_MESSAGES:
        schema = message.model_json_schema(mode="serialization")
        assert "stamp" in schema["properties"] and "seq" in schema["properties"]


def test_keys_carry_the_robot_id():
    k = Keys("r2")
    assert k.of(keys.CMD_VEL) == "zenav/r2/cmd_vel"
    assert k.alive("planner") == "zenav/r2/alive/planner"
    with pytest.raises(ValueError, match="robot id"):
        Keys("bad/id")
    with pytest.raises(ValueError, match="robot id"):
        Keys("*")


def test_commands_reject_non_finite_speeds():
    with pytest.raises(ValueError):
        VelocityCommand(stamp=0.0, seq=0, v=math.nan, omega=0.0)
    with pytest.raises(ValueError):
        BaseCommand(stamp=0.0, seq=0, v=0.0, omega=math.inf)


def test_peek_stamp_reads_the_envelope_and_refuses_nothing() -> None:
    from zenav.schemas.codec import peek_stamp
    from zenav.schemas.messages import VelocityCommand

    payload = encode(VelocityCommand(stamp=12.5, seq=7, v=0.1, omega=0.0))
    assert peek_stamp(payload) == (12.5, 7)
    assert peek_stamp(b"\xc1 not msgpack") == (None, None)
    assert peek_stamp(msgpack.packb([1, 2])) == (None, None)
    assert peek_stamp(msgpack.packb({"stamp": -1.0, "seq": True})) == (None, None)
    assert peek_stamp(msgpack.packb({"stamp": float("nan"), "seq": 3})) == (None, 3)
