"""Foxglove channels in zenav's recordings, and the shared "zenav sample -> Foxglove
messages" step of recording and live serving.

A recording keeps zenav's exact msgpack channels and gains one protobuf channel per
Foxglove topic (:data:`zenav.foxglove.scene.TOPICS`), with the schema the Foxglove SDK
publishes for each message type, so the file opens in Foxglove with nothing to install.
"""

from __future__ import annotations

from typing import Any

from mcap.writer import Writer

from zenav.bag.mcapfile import topic_message
from zenav.foxglove.scene import TOPICS, SceneBuilder
from zenav.schemas.codec import DecodeError, decode
from zenav.schemas.keys import Keys

ENCODING = "protobuf"


class SampleConverter:
    """Raw zenav samples (key, msgpack payload) in, Foxglove (topic, message) out."""

    def __init__(self, robot_id: str) -> None:
        self.keys = Keys(robot_id)
        self._prefix = self.keys.prefix + "/"
        self.scene = SceneBuilder()
        self.rejected = 0

    def convert(self, key: str, payload: bytes) -> list[tuple[str, Any, int]]:
        """(Foxglove topic, message, the zenav stamp in ns) for one sample."""
        if not key.startswith(self._prefix):
            return []
        message_type = topic_message(key[len(self._prefix):])
        if message_type is None:
            return []
        try:
            message = decode(payload, message_type, key, max_bytes=len(payload) + 1)
        except DecodeError:
            self.rejected += 1
            return []
        stamp_ns = round(message.stamp * 1e9)
        return [(topic, out, stamp_ns) for topic, out in self.scene.convert(message)]


class FoxgloveChannels:
    """Adds the Foxglove topics to an MCAP writer that is already started."""

    def __init__(self, writer: Writer, robot_id: str) -> None:
        self.writer = writer
        self.converter = SampleConverter(robot_id)
        self._channels: dict[str, int] = {}
        self.count = 0

    def _channel(self, topic: str) -> int:
        channel = self._channels.get(topic)
        if channel is None:
            schema = TOPICS[topic].get_schema()
            schema_id = self.writer.register_schema(schema.name, schema.encoding,
                                                    bytes(schema.data))
            channel = self.writer.register_channel(topic, ENCODING, schema_id)
            self._channels[topic] = channel
        return channel

    def add(self, key: str, payload: bytes, log_time_ns: int) -> None:
        for topic, message, stamp_ns in self.converter.convert(key, payload):
            self.writer.add_message(self._channel(topic), log_time=log_time_ns,
                                    data=bytes(message.encode()), publish_time=stamp_ns)
            self.count += 1
