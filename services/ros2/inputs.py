"""Serving ROS 2 inputs inside a zenav service (thin: the bus and the node's counters)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from pydantic import ValidationError

from zenav.services.node import Node
from zenav.services.ros2.convert import ConversionError
from zenav.services.ros2.wire import WireError, deserialize
from zenav.services.transport import Subscription

MAX_BYTES = 512 * 1024
"""Largest ROS 2 payload accepted (a 3601-beam scan with intensities is ~29 KB)."""


async def serve_ros2(node: Node, sub: Subscription, ros_type: str,
                     handler: Callable[[str, Any], None]) -> None:
    """Decode each sample of ``sub`` as ``ros_type`` and hand it to ``handler``; a
    sample that does not decode or convert is counted and logged, never fatal."""
    while True:
        key, payload = await sub.get()
        if len(payload) > MAX_BYTES:
            node.reject(key, "too_large", f"{key}: {len(payload)} bytes > {MAX_BYTES}")
            continue
        try:
            handler(key, deserialize(payload, ros_type))
        except (WireError, ConversionError) as exc:
            node.reject(key, "bad_ros2", f"{key}: {exc}")
        except ValidationError as exc:
            first = exc.errors(include_url=False)[0]
            node.reject(key, "bad_ros2", f"{key}: {first['msg']}")
