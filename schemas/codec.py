"""The wire format: one msgpack map per message, validated on the way in.

A payload is a msgpack map holding the message's fields plus two envelope entries,
``"_v"`` (the schema version) and ``"_t"`` (the message type name). Arrays are raw
bytes inside the map. Decoding never raises anything but :class:`DecodeError`, whose
``kind`` lets a service count rejections per cause and whose text names the key and
the reason.
"""

from __future__ import annotations

import math
from typing import Any, TypeVar

import msgpack
from pydantic import ValidationError

from zenav.schemas.messages import Message

SCHEMA_VERSION = 1
"""Bumped whenever a message changes incompatibly."""

DEFAULT_MAX_BYTES = 64 * 1024
"""Largest payload accepted unless a key says otherwise (a 361-beam scan is ~1.6 KB)."""

M = TypeVar("M", bound=Message)


class DecodeError(ValueError):
    """A payload that cannot be turned into the expected message.

    ``kind`` is one of ``size``, ``msgpack``, ``envelope``, ``version``, ``type`` and
    ``invalid``.
    """

    def __init__(self, key: str, kind: str, reason: str) -> None:
        super().__init__(f"{key}: {kind}: {reason}")
        self.key = key
        self.kind = kind
        self.reason = reason


def encode(message: Message) -> bytes:
    """Pack a message with its envelope."""
    fields: dict[str, Any] = message.model_dump(mode="python")
    fields["_v"] = SCHEMA_VERSION
    fields["_t"] = message.TYPE
    packed: bytes = msgpack.packb(fields, use_bin_type=True)
    return packed


def decode(
    payload: bytes, message_type: type[M], key: str = "?", max_bytes: int = DEFAULT_MAX_BYTES
) -> M:
    """Unpack and validate ``payload`` as ``message_type``, or raise :class:`DecodeError`."""
    if len(payload) > max_bytes:
        raise DecodeError(key, "size", f"payload of {len(payload)} B exceeds {max_bytes} B")
    try:
        fields = msgpack.unpackb(payload, raw=False, strict_map_key=True)
    except (ValueError, msgpack.ExtraData, msgpack.FormatError, msgpack.StackError) as exc:
        raise DecodeError(key, "msgpack", f"not a msgpack payload ({exc})") from None
    except (TypeError, RecursionError, OverflowError, MemoryError) as exc:
        # e.g. an array used as a map key, or nesting deeper than the stack
        raise DecodeError(key, "msgpack", f"unusable msgpack ({type(exc).__name__})") from None
    if not isinstance(fields, dict):
        raise DecodeError(key, "envelope", f"expected a map, got {type(fields).__name__}")
    version = fields.pop("_v", None)
    type_name = fields.pop("_t", None)
    if version is None or type_name is None:
        raise DecodeError(key, "envelope", "missing '_v' or '_t' envelope field")
    if version != SCHEMA_VERSION:
        raise DecodeError(
            key, "version", f"schema version {version!r}, this build speaks {SCHEMA_VERSION}"
        )
    if type_name != message_type.TYPE:
        raise DecodeError(key, "type", f"got a {type_name!r}, expected {message_type.TYPE!r}")
    try:
        return message_type.model_validate(fields)
    except ValidationError as exc:
        raise DecodeError(key, "invalid", _summarise(exc)) from None
    except Exception as exc:  # a validator failing in a way pydantic does not wrap
        raise DecodeError(key, "invalid", f"{type(exc).__name__}: {exc}"[:300]) from None


def peek_stamp(payload: bytes) -> tuple[float | None, int | None]:
    """The envelope's ``stamp`` (s) and ``seq`` without validating the rest: for tools that
    file messages by time (recorders), never for acting on a message. None where a field
    is missing, malformed, or the payload is not one of zenav's messages."""
    try:
        fields = msgpack.unpackb(payload, raw=False, strict_map_key=True)
    except Exception:  # any unpacking failure means "no stamp", by contract
        return None, None
    if not isinstance(fields, dict):
        return None, None
    stamp, seq = fields.get("stamp"), fields.get("seq")
    peeked: float | None = None
    if isinstance(stamp, (int, float)) and not isinstance(stamp, bool):
        value = float(stamp)
        peeked = value if math.isfinite(value) and value >= 0 else None
    good_seq = isinstance(seq, int) and not isinstance(seq, bool) and seq >= 0
    return peeked, (seq if good_seq else None)


def _summarise(exc: ValidationError) -> str:
    parts = []
    for error in exc.errors(include_url=False, include_input=False)[:3]:
        where = ".".join(str(p) for p in error["loc"]) or "message"
        parts.append(f"{where}: {error['msg']}")
    more = exc.error_count() - len(parts)
    if more > 0:
        parts.append(f"(+{more} more)")
    return "; ".join(parts)
