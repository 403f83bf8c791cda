"""The MCAP file of ``zenav record`` (layout in :mod:`zenav.bag`): writing, reading and
decoding it."""


from __future__ import annotations

import json
import struct
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

from mcap.decoder import DecoderFactory
from mcap.exceptions import McapError
from mcap.reader import make_reader
from mcap.records import Schema
from mcap.writer import Writer

import zenav
from zenav.schemas import keys
from zenav.schemas.codec import SCHEMA_VERSION, decode, peek_stamp
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
    """The message's stamp (ns) and seq for the MCAP index, without validating the rest."""
    stamp, seq = peek_stamp(payload)
    stamp_ns = None if stamp is None else round(stamp * 1e9)
    return stamp_ns, 0 if seq is None else seq % 2**32


class BagWriter:
    """Writes one robot's messages and liveliness changes to an MCAP stream."""

    def __init__(self, stream: IO[bytes], robot_id: str, exclude: tuple[str, ...] = (),
                 foxglove: bool = False) -> None:
        """``foxglove``: also write the Foxglove channels (:mod:`zenav.foxglove`)."""
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
        self.foxglove: Any = None
        if foxglove:
            from zenav.foxglove.recording import FoxgloveChannels  # imports this module

            self.foxglove = FoxgloveChannels(self._writer, robot_id)

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
        if self.foxglove is not None:
            self.foxglove.add(key, payload, log_time_ns)

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


def bag_contents(path: Path) -> tuple[str, set[str]]:
    """(robot id, topics with messages) of a file made by ``zenav record``; ValueError with
    one line when it is not one (unreadable, not MCAP, no zenav metadata)."""
    try:
        robot = recorded_robot(path)
        prefix = f"{ROOT}/{robot}/"
        with path.open("rb") as stream:
            summary = make_reader(stream).get_summary()
            if summary is not None:
                channels = summary.channels.values()
                counts = summary.statistics.channel_message_counts if summary.statistics else {}
                topics = {c.topic[len(prefix):] for c in channels
                          if c.topic.startswith(prefix) and c.message_encoding == MESSAGE_ENCODING
                          and counts.get(c.id, 1) > 0}
                return robot, topics
        return robot, {item.topic for item in read_bag(path)}
    except OSError as exc:
        raise ValueError(f"{path}: cannot read ({exc.strerror or exc})") from None
    except (McapError, struct.error):  # struct.error: shorter than MCAP's 8-byte magic
        raise ValueError(f"{path}: not an MCAP file (or cut short)") from None


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
