"""zenav foxglove, live: a WebSocket client speaking Foxglove's protocol subscribes to the
scan and the tracks, and decodes what arrives with the schemas the server advertised."""

from __future__ import annotations

import asyncio
import base64
import json
import socket
import struct
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import zenoh
from google.protobuf import descriptor_pb2, descriptor_pool, message_factory

from tests.ros2 import samples
from zenav.schemas.codec import encode

pytestmark = pytest.mark.integration

websockets = pytest.importorskip("websockets")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def message_class(channel: dict[str, Any]) -> Any:
    """A protobuf class from a channel's advertised schema (a FileDescriptorSet)."""
    assert channel["encoding"] == "protobuf" and channel["schemaEncoding"] == "protobuf"
    files = descriptor_pb2.FileDescriptorSet.FromString(base64.b64decode(channel["schema"]))
    pool = descriptor_pool.DescriptorPool()
    for file in files.file:
        pool.Add(file)
    return message_factory.GetMessageClass(pool.FindMessageTypeByName(channel["schemaName"]))


async def receive(url: str, publish: Callable[[], None],
                  timeout: float = 30.0) -> dict[str, Any]:
    """Subscribe to the scan and tracks; publish zenav messages until both arrive."""
    got: dict[str, Any] = {}
    async with websockets.connect(url, subprotocols=["foxglove.sdk.v1", "foxglove.websocket.v1"],
                                  open_timeout=10) as ws:
        channels: dict[str, dict[str, Any]] = {}
        deadline = time.monotonic() + timeout
        while not {"/foxglove/scan", "/foxglove/tracks"} <= set(channels):
            frame = json.loads(await asyncio.wait_for(ws.recv(), deadline - time.monotonic()))
            if frame.get("op") == "advertise":
                channels.update({c["topic"]: c for c in frame["channels"]})
        wanted = {1: channels["/foxglove/scan"], 2: channels["/foxglove/tracks"]}
        await ws.send(json.dumps({"op": "subscribe", "subscriptions": [
            {"id": sid, "channelId": c["id"]} for sid, c in wanted.items()]}))
        classes = {sid: message_class(c) for sid, c in wanted.items()}
        while len(got) < 2:
            if time.monotonic() > deadline:
                raise AssertionError(f"only {sorted(got)} arrived")
            publish()
            try:
                frame = await asyncio.wait_for(ws.recv(), 0.3)
            except TimeoutError:
                continue
            if isinstance(frame, bytes) and frame[0] == 0x01:
                sid, _log_time = struct.unpack_from("<IQ", frame, 1)
                got[wanted[sid]["topic"]] = classes[sid].FromString(frame[13:])
    return got


def test_live_scan_and_scene_update_reach_a_websocket_client(tmp_path: Path):
    zport, wport = free_port(), free_port()
    endpoint = f"tcp/127.0.0.1:{zport}"
    conf = zenoh.Config()
    conf.insert_json5("mode", '"router"')
    conf.insert_json5("listen/endpoints", json.dumps([endpoint]))
    conf.insert_json5("scouting/multicast/enabled", "false")
    with zenoh.open(conf) as router:
        log = (tmp_path / "foxglove.log").open("w")
        proc = subprocess.Popen([sys.executable, "-m", "zenav", "foxglove", "--connect",
                                 endpoint, "--port", str(wport), "--duration", "60"],
                                stdout=log, stderr=subprocess.STDOUT)
        try:
            scan_pub = router.declare_publisher("zenav/robot0/scan")
            tracks_pub = router.declare_publisher("zenav/robot0/tracks")
            stamp = [1.0]

            def publish() -> None:
                stamp[0] += 0.1
                scan_pub.put(encode(samples.scan(stamp[0])))
                tracks_pub.put(encode(samples.tracks(stamp[0])))

            deadline = time.monotonic() + 20
            while True:  # the server is up when its port accepts connections
                with socket.socket() as s:
                    if s.connect_ex(("127.0.0.1", wport)) == 0:
                        break
                assert proc.poll() is None, (tmp_path / "foxglove.log").read_text()
                assert time.monotonic() < deadline, "zenav foxglove did not start"
                time.sleep(0.2)
            got = asyncio.run(receive(f"ws://127.0.0.1:{wport}", publish))
        finally:
            proc.terminate()
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()
    scan = got["/foxglove/scan"]
    assert scan.frame_id == "laser" and len(scan.ranges) == 361
    assert scan.ranges[0] == pytest.approx(0.5)
    update = got["/foxglove/tracks"]
    assert {e.id for e in update.entities} == {"track-1", "track-2", "track-3"}
    assert len(next(e for e in update.entities if e.id == "track-1").arrows) == 1
