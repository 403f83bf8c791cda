"""Malformed input on the in-memory bus: every kind is refused, counted and survived.

Covers each subscribed key of every service (the planner's through the same
:class:`Node` runtime): random bytes, truncated msgpack, valid msgpack of the wrong
schema or version, NaN / Inf / negative ranges, a wrong beam count, oversized payloads,
and stamps from the past and from the future.
"""

from __future__ import annotations

import asyncio
import math
from typing import Any

import msgpack
import numpy as np
import pytest

from tests.service.harness import Harness, running
from zenav.schemas import keys
from zenav.schemas.codec import SCHEMA_VERSION, encode
from zenav.schemas.keys import Topic
from zenav.schemas.messages import (
    BaseCommand,
    LaserScan,
    Message,
    Odometry,
    Pose2D,
    RawLaserFrame,
    VelocityCommand,
)
from zenav.services.laser_driver.params import Params as LaserParams
from zenav.services.motor_bridge.params import Params as BridgeParams
from zenav.services.node import MAX_FUTURE, RESYNC_COUNT


def odom(t: float) -> Odometry:
    return Odometry(stamp=t, seq=0, pose=Pose2D(x=0.0, y=0.0, heading=0.0), v=0.0, omega=0.0)


def cmd(t: float, v: float = 0.1) -> VelocityCommand:
    return VelocityCommand(stamp=t, seq=0, v=v, omega=0.0)


def frame(t: float, ranges: Any = None) -> RawLaserFrame:
    r = np.full(361, 5.0, np.float32) if ranges is None else ranges
    return RawLaserFrame(stamp=t, seq=0, ranges=r)


def scan(t: float) -> LaserScan:
    return LaserScan(stamp=t, seq=0, frame="laser", angle_min=-math.pi / 2,
                     angle_max=math.pi / 2, angle_increment=math.radians(0.5), range_min=0.0,
                     range_max=8.0, ranges=np.full(361, 5.0, np.float32))


def fields(message: Message, **change: Any) -> bytes:
    """``message`` packed by hand, with fields changed (bypasses validation)."""
    data: dict[str, Any] = message.model_dump(mode="python")
    data.update(_v=SCHEMA_VERSION, _t=message.TYPE)
    data.update(change)
    packed: bytes = msgpack.packb(data, use_bin_type=True)
    return packed


def malformed(topic: Topic, good: Message) -> dict[str, bytes]:
    """One payload per malformed kind for ``topic``, derived from a valid ``good``."""
    rng = np.random.default_rng(7)
    payloads = {
        "random-bytes": rng.integers(0, 256, 200, dtype=np.uint8).tobytes(),
        "truncated": encode(good)[: len(encode(good)) // 2],
        "wrong-schema": encode(odom(1.0)) if topic != keys.ODOM else encode(cmd(1.0)),
        "wrong-version": fields(good, _v=SCHEMA_VERSION + 1),
        "not-a-map": msgpack.packb([1, 2, 3]),
        "map-key-array": b"\x81\x91\x01\x01",  # {[1]: 1}: unhashable key
        "oversized": encode(good) + b"\x00" * topic.max_bytes,
        "nan-stamp": fields(good, stamp=math.nan),
        "negative-stamp": fields(good, stamp=-1.0),
    }
    if "ranges" in type(good).model_fields:
        payloads["nan-ranges"] = fields(good, ranges=np.full(361, np.nan, "<f4").tobytes())
        payloads["inf-ranges"] = fields(good, ranges=np.full(361, np.inf, "<f4").tobytes())
        payloads["negative-ranges"] = fields(good, ranges=np.full(361, -1.0, "<f4").tobytes())
        payloads["beam-count"] = fields(good, ranges=np.full(360, 1.0, "<f4").tobytes())
    if "v" in type(good).model_fields:
        payloads["inf-speed"] = fields(good, v=math.inf)
    return payloads


def rejected_total(h: Harness) -> int:
    return sum(h.node.rejected.values())


@pytest.mark.parametrize(
    ("service", "params", "topic", "good"),
    [
        ("laser_driver", LaserParams(), keys.RAW_LASER, frame(1.0)),
        ("motor_bridge", BridgeParams(), keys.CMD_VEL, cmd(1.0)),
        ("motor_bridge", BridgeParams(), keys.ODOM, odom(1.0)),
        ("motor_bridge", BridgeParams(), keys.SCAN, scan(1.0)),
    ],
    ids=["laser_driver:device/laser", "motor_bridge:cmd_vel", "motor_bridge:odom",
         "motor_bridge:scan"],
)
async def test_every_malformed_kind_is_counted_and_the_service_goes_on(
    service: str, params: Any, topic: Topic, good: Message
) -> None:
    async with running(service, params) as h:
        payloads = malformed(topic, good)
        for payload in payloads.values():
            h.send_raw(topic, payload)
            await h.settle()
        assert rejected_total(h) == len(payloads), dict(h.node.rejected)
        assert h.node.handler_errors == 0
        assert {"msgpack", "version", "type", "envelope", "size", "invalid"} <= set(
            h.node.rejected)
        before, accepted = len(h.bus.published), h.node.received[topic.name]
        h.send(topic, good)  # a valid one still goes through
        await h.settle()
        assert h.node.received[topic.name] == accepted + 1
        if service == "laser_driver":
            assert len(h.received(keys.SCAN, LaserScan)) == 1
        if topic == keys.CMD_VEL:
            assert len(h.bus.published) > before


async def test_frames_of_the_wrong_beam_count_are_refused_by_the_driver() -> None:
    async with running("laser_driver", LaserParams()) as h:
        for stamp in (1.0, 1.0, 1.1):  # a repeated stamp is no excuse
            h.send(keys.RAW_LASER, frame(stamp, np.full(360, 1.0, np.float32)))
            await h.settle()
        assert h.node.rejected["bad_frame"] == 3
        h.send(keys.RAW_LASER, frame(2.0))
        await h.settle()
        assert [s.stamp for s in h.received(keys.SCAN, LaserScan)] == [2.0]


async def test_a_stamp_from_the_future_is_refused_and_does_not_poison_the_order() -> None:
    async with running("motor_bridge", BridgeParams(accel=10.0)) as h:
        h.send(keys.ODOM, odom(10.0))
        h.send(keys.CMD_VEL, cmd(10.0))
        await h.settle()
        h.send(keys.CMD_VEL, cmd(10.0 + MAX_FUTURE + 1.0, v=0.2))  # far ahead of odometry
        h.send(keys.ODOM, odom(1e9))
        await h.settle()
        assert h.node.rejected["future"] == 2
        for t in (10.1, 10.2):  # genuine messages after it are not "out of order"
            h.send(keys.ODOM, odom(t))
            h.send(keys.CMD_VEL, cmd(t))
            await h.settle()
        out = h.received(keys.BASE_CMD, BaseCommand)
        assert [c.stamp for c in out] == [10.0, 10.1, 10.2]
        assert all(c.reason == "command" for c in out)
        assert h.node.rejected["out_of_order"] == 0
        assert h.node.clock == 10.2


async def test_a_stamp_from_the_past_is_refused_per_key() -> None:
    async with running("motor_bridge", BridgeParams(accel=10.0)) as h:
        for t in (5.0, 5.1):
            h.send(keys.ODOM, odom(t))
            h.send(keys.CMD_VEL, cmd(t))
            await h.settle()
        h.send(keys.ODOM, odom(4.0))
        h.send(keys.CMD_VEL, cmd(4.0))
        h.send(keys.CMD_VEL, cmd(5.1))  # a retransmission (same stamp) is not out of order
        await h.settle()
        assert h.node.rejected["out_of_order"] == 2
        assert [c.stamp for c in h.received(keys.BASE_CMD, BaseCommand)] == [5.0, 5.1, 5.1]


async def test_the_order_restarts_after_a_silence_on_a_coherent_stream_only() -> None:
    """A long link cut (or a restarted publisher) must not lock a service out forever,
    and scattered bad stamps must never move its clock."""
    async with running("motor_bridge", BridgeParams(accel=10.0)) as h:
        h.node.resync_after = 0.2
        h.send(keys.ODOM, odom(100.0))
        h.send(keys.CMD_VEL, cmd(100.0))
        await h.settle()
        await asyncio.sleep(0.25)  # silence: nothing accepted for longer than resync_after
        for t in (1e6, 5e5, 2e6, 7e5, 3e6, 9e5):  # scattered future stamps: all refused
            h.send(keys.CMD_VEL, cmd(t, v=0.2))
            await h.settle()
        assert h.node.rejected["future"] == 6
        assert h.node.clock == 100.0
        jump = 100.0 + 3 * MAX_FUTURE  # the stack's clock after a long cut
        for i in range(RESYNC_COUNT):
            h.send(keys.ODOM, odom(jump + 0.1 * i))
            await h.settle()
        assert h.node.rejected["future"] == 6 + RESYNC_COUNT - 1  # the last one resyncs
        assert h.node.clock == jump + 0.1 * (RESYNC_COUNT - 1)
        h.send(keys.CMD_VEL, cmd(jump + 0.5))
        await h.settle()
        assert h.received(keys.BASE_CMD, BaseCommand)[-1].stamp == jump + 0.5
        await asyncio.sleep(0.25)
        for i in range(RESYNC_COUNT):  # a restarted simulator: its clock starts again
            h.send(keys.ODOM, odom(1.0 + 0.1 * i))
            await h.settle()
        assert h.node.rejected["out_of_order"] == RESYNC_COUNT - 1
        h.send(keys.ODOM, odom(1.6))
        await h.settle()
        assert h.node.rejected["out_of_order"] == RESYNC_COUNT - 1


async def test_a_restarted_publisher_is_answered_from_its_third_message() -> None:
    """A restarted planner (or a simulator whose clock starts again) sends stamps earlier
    than the last ones seen: after the silence its third coherent stamp restarts the
    order, and the motor bridge's gate follows the node at once (it used to refuse the
    new order for good). A repeated stamp in between neither counts nor breaks the run."""
    async with running("motor_bridge", BridgeParams(accel=10.0)) as h:
        h.node.resync_after = 0.2
        for t in (100.0, 100.1):
            h.send(keys.ODOM, odom(t))
            h.send(keys.CMD_VEL, cmd(t))
            await h.settle()
        await asyncio.sleep(0.25)  # the publisher is down longer than resync_after
        for t in (1.0, 1.0, 1.1, 1.2, 1.3):
            h.send(keys.CMD_VEL, cmd(t))
            await h.settle()
        assert RESYNC_COUNT == 3
        assert h.node.rejected["out_of_order"] == 3  # 1.0, its repeat, 1.1
        assert h.node.resyncs[h.node.keys.of(keys.CMD_VEL)] == 1
        assert [c.stamp for c in h.received(keys.BASE_CMD, BaseCommand)][-2:] == [1.2, 1.3]
