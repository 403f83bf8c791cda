"""A ROS 2 node on zenav's bus: the thin part that declares what rmw_zenoh would.

One :class:`Ros2Node` is one entry in ``ros2 node list``. Its publishers put CDR with
the rmw_zenoh attachment on the topic's key and announce themselves with an ``MP``
liveliness token; its subscriptions listen on the key and announce an ``MS`` token. The
pure parts (keys, tokens, attachment, CDR) are in :mod:`zenav.services.ros2.wire`.
"""

from __future__ import annotations

import time
from typing import Any

from zenav.services.ros2.wire import (
    DEFAULT_QOS,
    Attachment,
    EntityKind,
    NodeIdentity,
    QoS,
    gid_of,
    serialize,
    topic_key,
)
from zenav.services.transport import Bus, Subscription, Token


class Ros2Publisher:
    """Publishes one ROS 2 topic, numbering samples as rmw_zenoh does (from 1)."""

    def __init__(self, node: Ros2Node, topic: str, ros_type: str, qos: QoS) -> None:
        self.topic = topic
        self.ros_type = ros_type
        self.key = topic_key(node.identity.domain_id, topic, ros_type)
        self.token = node.declare("MP", topic, ros_type, qos)
        self.gid = gid_of(self.token)
        self._publisher = node.bus.publisher(self.key, reliable=qos.reliability == "reliable")
        self.sequence = 0
        self.last: Any = None

    def publish(self, message: Any) -> bytes:
        """Serialise ``message`` (a rosbags object of ``ros_type``) and send it."""
        payload = serialize(message, self.ros_type)
        self.sequence += 1
        attachment = Attachment(self.sequence, time.time_ns(), self.gid)
        self._publisher.put(payload, attachment.encode())
        self.last = message
        return payload


class Ros2Node:
    """A ROS 2 node's identity and liveliness on ``bus``."""

    def __init__(self, bus: Bus, name: str, domain_id: int = 0, namespace: str = "/") -> None:
        self.bus = bus
        self.identity = NodeIdentity(domain_id=domain_id, session_id=bus.session_id(),
                                     name=name, namespace=namespace)
        self.tokens: list[str] = []
        self._declared: list[Token] = []
        self._next_id = self.identity.node_id + 1
        self._add(self.identity.node_token())

    def _add(self, token: str) -> None:
        self._declared.append(self.bus.declare_token(token))
        self.tokens.append(token)

    def declare(self, kind: EntityKind, topic: str, ros_type: str, qos: QoS) -> str:
        token = self.identity.entity_token(self._next_id, kind, topic, ros_type, qos)
        self._next_id += 1
        self._add(token)
        return token

    def publisher(self, topic: str, ros_type: str, qos: QoS = DEFAULT_QOS) -> Ros2Publisher:
        return Ros2Publisher(self, topic, ros_type, qos)

    def subscribe(self, topic: str, ros_type: str, qos: QoS = DEFAULT_QOS,
                  depth: int = 2) -> Subscription:
        """Samples of ``topic`` (raw CDR), newest ``depth`` kept."""
        self.declare("MS", topic, ros_type, qos)
        return self.bus.subscribe(topic_key(self.identity.domain_id, topic, ros_type), depth)

    def close(self) -> None:
        """Withdraw every token (the node leaves the ROS graph)."""
        for token in reversed(self._declared):
            token.undeclare()
        self._declared.clear()
