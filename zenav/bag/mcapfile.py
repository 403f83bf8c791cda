"""``zenav record`` and ``zenav replay``: a robot's messages in an MCAP file.

MCAP is the robotics log format (Foxglove, ROS 2's default bag format); the ``mcap``
tools (``mcap info``, ``mcap cat``) and libraries read these files. Layout:

- one **channel per key** (``zenav/<robot>/scan``, ...), message encoding ``msgpack``:
  each message's data is the exact payload that was on the bus (zenav's msgpack map with
  its ``_v``/``_t`` envelope), so a replay is byte for byte what the services saw;
- one **schema per message type**, encoding ``jsonschema``, named ``zenav.<Type>``: the
  pydantic model's JSON Schema (serialization mode), as ``zenav schemas`` writes it;
- **log time**: wall clock (ns) when the recorder received the message, taken in Zenoh's
  callback; **publish time**: the message's own ``stamp`` (ns on the stack's clock:
  simulated seconds in simulation); **sequence**: the message's ``seq``;
- liveliness changes as channels ``zenav/<robot>/alive/<service>``, encoding ``json``,
  data ``{"alive": true|false}``;
- metadata record ``zenav``: robot id, schema version, zenav version.

``MsgpackDecoderFactory`` lets ``mcap.reader.make_reader(f, decoder_factories=[...])``
``.iter_decoded_messages()`` return the pydantic messages.

A replay publishes the recorded payloads on the same keys (or another robot id's), in
log-time order, at the recorded pace divided by ``--rate``. Services remember the latest
stamp they saw: start them afresh before each replay.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import json
import sys
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

import msgpack
from mcap.decoder import DecoderFactory
from mcap.reader import make_reader
from mcap.records import Schema
from mcap.writer import Writer

import zenav
from zenav.schemas import keys
from zenav.schemas.codec import SCHEMA_VERSION, decode
from zenav.schemas.keys import ROOT, Keys
from zenav.schemas.messages import ALL_MESSAGES, Message

MESSAGE_ENCODING = "msgpack"
SCHEMA_ENCODING = "jsonschema"
LIVELINESS_ENCODING = "json"

_BY_SCHEMA_NAME: dict[str, type[Message]] = {f"zenav.{m.__name__}": m for m in ALL_MESSAGES}
_TOPICS: dict[str, keys.Topic] = {t.name: t for t in keys.TOPICS}


def topic_message(topic: str) -> type[Message] | None:
    """The message type a topic (key after ``zenav/<robot>/``) carries, if known."""
    if topic.startswith(keys.STATUS.name + "/"):
        return keys.STATUS.message
    known = _TOPICS.get(topic)
    return known.message if known is not None else None


def schema_name(message: type[Message]) -> str:
    return f"zenav.{message.__name__}"


def json_schema(message: type[Message]) -> bytes:
    return json.dumps(message.model_json_schema(mode="serialization"), sort_keys=True).encode()


def _stamp_and_seq(payload: bytes) -> tuple[int | None, int]:
    """The message's stamp (ns) and seq, without validating the rest."""
    try:
        fields = msgpack.unpackb(payload, raw=False)
        stamp, seq = fields.get("stamp"), fields.get("seq", 0)
        stamp_ns = round(float(stamp) * 1e9) if stamp is not None and stamp >= 0 else None
        return stamp_ns, int(seq) % 2**32 if isinstance(seq, int) and seq >= 0 else 0
    except Exception:
        return None, 0


class BagWriter:
    """Writes one robot's messages and liveliness changes to an MCAP stream."""

    def __init__(self, stream: IO[bytes], robot_id: str, exclude: tuple[str, ...] = ()) -> None:
        self.keys = Keys(robot_id)
        self._prefix = self.keys.prefix + "/"
        self._exclude = set(exclude)
        self._writer = Writer(stream)
        self._writer.start(profile="", library=f"zenav {zenav.__version__}")
        self._writer.add_metadata("zenav", {
            "robot_id": robot_id, "schema_version": str(SCHEMA_VERSION),
            "zenav_version": zenav.__version__,
            "started": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        })
        self._schemas: dict[type[Message], int] = {}
        self._channels: dict[str, int] = {}
        self.count = 0
        self._closed = False

    def _schema(self, message: type[Message]) -> int:
        if message not in self._schemas:
            self._schemas[message] = self._writer.register_schema(
                schema_name(message), SCHEMA_ENCODING, json_schema(message))
        return self._schemas[message]

    def _channel(self, key: str, encoding: str, message: type[Message] | None) -> int:
        channel = self._channels.get(key)
        if channel is None:
            schema = self._schema(message) if message is not None else 0
            metadata = {"zenav_type": message.TYPE} if message is not None else {}
            channel = self._writer.register_channel(key, encoding, schema, metadata)
            self._channels[key] = channel
        return channel

    def add(self, key: str, payload: bytes, log_time_ns: int) -> None:
        if self._closed or not key.startswith(self._prefix):
            return
        topic = key[len(self._prefix):]
        if topic in self._exclude:
            return
        channel = self._channel(key, MESSAGE_ENCODING, topic_message(topic))
        stamp_ns, seq = _stamp_and_seq(payload)
        self._writer.add_message(channel, log_time=log_time_ns, data=payload,
                                 publish_time=stamp_ns if stamp_ns is not None else log_time_ns,
                                 sequence=seq)
        self.count += 1

    def liveliness(self, key: str, alive: bool, log_time_ns: int) -> None:
        if self._closed:
            return
        channel = self._channel(key, LIVELINESS_ENCODING, None)
        self._writer.add_message(channel, log_time=log_time_ns,
                                 data=json.dumps({"alive": alive}).encode(),
                                 publish_time=log_time_ns)

    def close(self) -> None:
        if not self._closed:
            self._closed = True
            self._writer.finish()  # type: ignore[no-untyped-call]  # unannotated in mcap


class MsgpackDecoderFactory(DecoderFactory):
    """Decodes zenav's msgpack channels into the pydantic messages."""

    def decoder_for(self, message_encoding: str,
                    schema: Schema | None) -> Callable[[bytes], Any] | None:
        if message_encoding != MESSAGE_ENCODING or schema is None:
            return None
        message = _BY_SCHEMA_NAME.get(schema.name)
        if message is None:
            return None
        return lambda data: decode(data, message, schema.name, max_bytes=len(data))


@dataclass(frozen=True)
class Recorded:
    key: str
    topic: str  # the key after zenav/<robot>/
    payload: bytes
    log_time: int
    publish_time: int


def recorded_robot(path: Path) -> str:
    """The robot id a file was recorded from."""
    with path.open("rb") as stream:
        for record in make_reader(stream).iter_metadata():
            if record.name == "zenav":
                return record.metadata["robot_id"]
    raise ValueError(f"{path}: no zenav metadata record (not made by zenav record)")


def read_bag(path: Path, topics: set[str] | None = None) -> Iterator[Recorded]:
    """The file's msgpack messages in log-time order, optionally only some topics."""
    robot = recorded_robot(path)
    prefix = f"{ROOT}/{robot}/"
    with path.open("rb") as stream:
        for _, channel, message in make_reader(stream).iter_messages(log_time_order=True):
            if channel.message_encoding != MESSAGE_ENCODING or not channel.topic.startswith(prefix):
                continue
            topic = channel.topic[len(prefix):]
            if topics is not None and topic not in topics:
                continue
            yield Recorded(channel.topic, topic, message.data, message.log_time,
                           message.publish_time)


# --- the processes ----------------------------------------------------------------------


async def _wait_until(event: asyncio.Event, timeout: float | None) -> bool:
    try:
        await asyncio.wait_for(event.wait(), timeout=timeout)
    except TimeoutError:
        return False
    return True


async def record(transport: Any, robot_id: str, path: Path, *, duration: float | None,
                 exclude: tuple[str, ...]) -> tuple[int, int]:
    """Record until SIGINT/SIGTERM or ``duration``; (messages, liveliness changes)."""
    from zenav.services.transport import ZenohBus
    from zenav.tooling import StampedSubscriber, stop_on_signals

    loop = asyncio.get_running_loop()
    stop = asyncio.Event()
    stop_on_signals(stop)
    changes = 0
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("wb") as stream:
        writer = BagWriter(stream, robot_id, exclude)
        bus = ZenohBus(transport, loop)
        try:
            subscriber = StampedSubscriber(bus, writer.keys.everything, writer.add)

            def on_liveliness(key: str, alive: bool) -> None:
                nonlocal changes
                changes += 1
                writer.liveliness(key, alive, time.time_ns())

            bus.watch_liveliness(writer.keys.alive_any, on_liveliness)
            # Announced once subscribed: a simulator told to wait for `record` starts its
            # clock only when nothing can be missed.
            token = bus.declare_token(writer.keys.alive("record"))
            print(f"zenav record: recording {writer.keys.everything} to {path}", flush=True)
            await _wait_until(stop, duration)
            token.undeclare()
            subscriber.close()
        finally:
            bus.close()
            writer.close()
    return writer.count, changes


async def replay(transport: Any, path: Path, *, rate: float, topics: set[str] | None,
                 as_robot: str | None, wait_for: list[str], timeout: float) -> int:
    """Publish the file's messages again; the number published."""
    from zenav.services.transport import ZenohBus
    from zenav.tooling import stop_on_signals

    if rate <= 0:
        raise ValueError(f"--rate must be > 0 (got {rate})")
    source = recorded_robot(path)
    target = Keys(as_robot or source)
    loop = asyncio.get_running_loop()
    stop = asyncio.Event()
    stop_on_signals(stop)
    bus = ZenohBus(transport, loop)
    published = 0
    try:
        if wait_for:
            alive: set[str] = set()
            changed = asyncio.Event()

            def on_liveliness(key: str, is_alive: bool) -> None:
                service = key.rsplit("/", 1)[-1]
                (alive.add if is_alive else alive.discard)(service)
                changed.set()

            bus.watch_liveliness(target.alive_any, on_liveliness)
            deadline = loop.time() + timeout
            while missing := set(wait_for) - alive:
                left = deadline - loop.time()
                if left <= 0:
                    raise TimeoutError(f"not alive after {timeout:.0f} s: "
                                       f"{', '.join(sorted(missing))}")
                changed.clear()
                await _wait_until(changed, left)
        publishers: dict[str, Any] = {}
        start_wall: float | None = None
        start_log = 0
        for item in read_bag(path, topics):
            if stop.is_set():
                break
            if start_wall is None:
                start_wall, start_log = loop.time(), item.log_time
            due = start_wall + (item.log_time - start_log) / 1e9 / rate
            delay = due - loop.time()
            if delay > 0 and await _wait_until(stop, delay):
                break
            key = f"{target.prefix}/{item.topic}"
            publisher = publishers.get(key)
            if publisher is None:
                publisher = publishers[key] = bus.publisher(key, reliable=True)
            publisher.put(item.payload)
            published += 1
        await asyncio.sleep(0.2)  # let the last messages leave before the session closes
    finally:
        bus.close()
    return published


def record_main(args: argparse.Namespace) -> int:
    from zenav.tooling import tool_setup

    setup = tool_setup(args, "record")
    if setup is None:
        return 2
    robot_id, transport = setup
    started = time.monotonic()
    with contextlib.suppress(KeyboardInterrupt):
        count, changes = asyncio.run(record(transport, robot_id, args.file,
                                            duration=args.duration, exclude=tuple(args.exclude)))
        print(f"zenav record: {count} messages and {changes} liveliness changes in "
              f"{time.monotonic() - started:.1f} s -> {args.file} "
              f"({args.file.stat().st_size} B)", flush=True)
    return 0


def replay_main(args: argparse.Namespace) -> int:
    from zenav.services.config import ConfigError
    from zenav.tooling import tool_transport

    topics = {t.strip() for t in args.topics.split(",") if t.strip()} or None
    wait_for = [s.strip() for s in args.wait_for.split(",") if s.strip()]
    try:
        transport = tool_transport(args)
        if args.as_robot is not None:
            Keys(args.as_robot)
        started = time.monotonic()
        count = asyncio.run(replay(transport, args.file, rate=args.rate, topics=topics,
                                   as_robot=args.as_robot, wait_for=wait_for,
                                   timeout=args.timeout))
    except TimeoutError as exc:  # before OSError, of which it is a subclass
        print(f"zenav replay: {exc}", file=sys.stderr)
        return 1
    except (ConfigError, ValueError, OSError) as exc:
        print(f"zenav replay: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 0
    print(f"zenav replay: {count} messages in {time.monotonic() - started:.1f} s "
          f"at rate {args.rate:g}", flush=True)
    return 0
