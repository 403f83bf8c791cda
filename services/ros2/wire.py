"""The rmw_zenoh wire format, as pure functions (no bus).

What a ROS 2 node running rmw_zenoh_cpp puts on Zenoh, after the middleware's design
document (ros2/rmw_zenoh, ``docs/design.md``):

- data keys ``<domain_id>/<fully qualified topic, no leading slash>/<DDS type
  name>/<type hash>``, e.g. ``0/cmd_vel/geometry_msgs::msg::dds_::Twist_/RIHS01_9c45...``;
- payloads in CDR (little-endian, with the 4-byte encapsulation header);
- an attachment on every sample: sequence number (int64 LE), source timestamp (ns since
  the UNIX epoch, int64 LE), then the publisher's GID as a length-prefixed byte array
  (one length byte, 16, then 16 bytes);
- liveliness tokens under ``@ros2_lv/<domain_id>/`` for each node (``NN``), publisher
  (``MP``) and subscription (``MS``), which is how ``ros2 node list`` and ``ros2 topic
  list`` see a process. Names in tokens are "mangled": every ``/`` becomes ``%``.

Type hashes (REP 2011, ``RIHS01_<sha256>``) and CDR come from the ``rosbags`` typestore
for ROS 2 Jazzy, which carries the standard message definitions; nothing here is a
hard-coded hash.
"""

from __future__ import annotations

import re
import struct
from dataclasses import dataclass
from functools import cache
from typing import Any, Literal

import xxhash
from rosbags.typesys import Stores, get_typestore
from rosbags.typesys.store import Typestore

ADMIN_SPACE = "@ros2_lv"
GID_SIZE = 16
ATTACHMENT_SIZE = 8 + 8 + 1 + GID_SIZE

# The message types zenav reads or writes on a ROS 2 robot.
LASER_SCAN = "sensor_msgs/msg/LaserScan"
ODOMETRY = "nav_msgs/msg/Odometry"
TWIST = "geometry_msgs/msg/Twist"
TWIST_STAMPED = "geometry_msgs/msg/TwistStamped"
MARKER_ARRAY = "visualization_msgs/msg/MarkerArray"
PATH = "nav_msgs/msg/Path"
OCCUPANCY_GRID = "nav_msgs/msg/OccupancyGrid"
USED_TYPES = (LASER_SCAN, ODOMETRY, TWIST, TWIST_STAMPED, MARKER_ARRAY, PATH, OCCUPANCY_GRID)

EntityKind = Literal["NN", "MP", "MS", "SS", "SC"]

_TYPE_NAME = re.compile(r"^([A-Za-z][A-Za-z0-9_]*)/(msg|srv)/([A-Z][A-Za-z0-9]*)$")
_NAME_TOKEN = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


class WireError(ValueError):
    """Bytes or names that do not follow the rmw_zenoh wire format; the text says how."""


@cache
def typestore() -> Typestore:
    """The ROS 2 Jazzy message definitions (shared, built once)."""
    return get_typestore(Stores.ROS2_JAZZY)


def message_class(ros_type: str) -> Any:
    """The rosbags class of ``ros_type`` (e.g. ``geometry_msgs/msg/Twist``)."""
    try:
        return typestore().types[ros_type]
    except KeyError:
        raise WireError(f"unknown ROS 2 message type {ros_type!r}") from None


def dds_type_name(ros_type: str) -> str:
    """``geometry_msgs/msg/Twist`` -> ``geometry_msgs::msg::dds_::Twist_``."""
    match = _TYPE_NAME.match(ros_type)
    if match is None:
        raise WireError(f"{ros_type!r} is not a ROS 2 type name like pkg/msg/Name")
    package, kind, name = match.groups()
    return f"{package}::{kind}::dds_::{name}_"


def type_hash(ros_type: str) -> str:
    """The REP 2011 type hash, ``RIHS01_<64 hex>``, computed from the definition."""
    message_class(ros_type)  # a clear error for an unknown type
    return str(typestore().hash_rihs01(ros_type))


def check_name_part(name: str, what: str) -> str:
    """A node name, or one token of a topic name or namespace."""
    if not _NAME_TOKEN.match(name):
        raise WireError(f"{what} {name!r}: use letters, digits and '_', not starting with a digit")
    return name


def qualify(name: str, namespace: str = "/") -> str:
    """The fully qualified ROS name of topic ``name`` (relative names join ``namespace``)."""
    if not name or (name.endswith("/") and name != "/"):
        raise WireError(f"topic name {name!r} is empty or ends with '/'")
    if not namespace.startswith("/"):
        raise WireError(f"namespace {namespace!r} must start with '/'")
    full = name if name.startswith("/") else namespace.rstrip("/") + "/" + name
    for part in full.strip("/").split("/"):
        check_name_part(part, f"topic {full!r}: part")
    return full


def mangle(name: str) -> str:
    """A name as it appears inside a liveliness token: ``/`` -> ``%``."""
    return name.replace("/", "%")


def demangle(name: str) -> str:
    return name.replace("%", "/")


def topic_key(domain_id: int, topic: str, ros_type: str) -> str:
    """The data key of a fully qualified topic: ``<domain>/<topic>/<type>/<hash>``."""
    return f"{domain_id}/{topic.strip('/')}/{dds_type_name(ros_type)}/{type_hash(ros_type)}"


# --- QoS ------------------------------------------------------------------------------

_RELIABILITY = {"reliable": 1, "best_effort": 2}
_DURABILITY = {"transient_local": 1, "volatile": 2}
_HISTORY = {"keep_last": 1, "keep_all": 2}


@dataclass(frozen=True)
class QoS:
    """The QoS policies zenav sets; deadline, lifespan and liveliness stay at defaults."""

    reliability: Literal["reliable", "best_effort"] = "reliable"
    durability: Literal["volatile", "transient_local"] = "volatile"
    history: Literal["keep_last", "keep_all"] = "keep_last"
    depth: int = 10

    def to_keyexpr(self) -> str:
        """rmw_zenoh's compact QoS string: each policy that differs from rmw_zenoh's own
        default (reliable, volatile, keep last 42, infinite durations, automatic
        liveliness) is written as its rmw enum value, the others are left empty."""
        default = QoS(depth=42)
        rel = str(_RELIABILITY[self.reliability]) if self.reliability != default.reliability else ""
        dur = str(_DURABILITY[self.durability]) if self.durability != default.durability else ""
        his = str(_HISTORY[self.history]) if self.history != default.history else ""
        depth = str(self.depth) if self.depth != default.depth else ""
        return f"{rel}:{dur}:{his},{depth}:,:,:,,"


SENSOR_QOS = QoS(reliability="best_effort", depth=5)
"""ROS 2's sensor-data profile (what laser drivers publish with)."""
DEFAULT_QOS = QoS()
"""ROS 2's default profile: reliable, volatile, keep last 10."""


# --- attachment -----------------------------------------------------------------------


@dataclass(frozen=True)
class Attachment:
    """What rides with every sample: sequence number, source time and publisher GID."""

    sequence_number: int
    source_timestamp_ns: int
    gid: bytes

    def encode(self) -> bytes:
        if len(self.gid) != GID_SIZE:
            raise WireError(f"a GID has {GID_SIZE} bytes, got {len(self.gid)}")
        return (struct.pack("<qq", self.sequence_number, self.source_timestamp_ns)
                + bytes([GID_SIZE]) + self.gid)

    @classmethod
    def decode(cls, data: bytes) -> Attachment:
        if len(data) != ATTACHMENT_SIZE:
            raise WireError(f"attachment has {len(data)} bytes, rmw_zenoh sends {ATTACHMENT_SIZE}")
        if data[16] != GID_SIZE:
            raise WireError(f"attachment GID length byte is {data[16]}, expected {GID_SIZE}")
        sequence_number, source_timestamp_ns = struct.unpack_from("<qq", data)
        return cls(sequence_number, source_timestamp_ns, bytes(data[17:]))


def gid_of(token: str) -> bytes:
    """An entity's GID as rmw_zenoh derives it: XXH3-128 of its liveliness key, low
    64 bits then high 64 bits, each little-endian."""
    return xxhash.xxh3_128(token.encode()).intdigest().to_bytes(GID_SIZE, "little")


# --- liveliness tokens -----------------------------------------------------------------


@dataclass(frozen=True)
class NodeIdentity:
    """One ROS 2 node: where its tokens live and what ``ros2 node list`` shows."""

    domain_id: int
    session_id: str
    name: str
    namespace: str = "/"
    node_id: int = 0
    enclave: str = "/"

    def __post_init__(self) -> None:
        check_name_part(self.name, "node name")
        if self.namespace != "/":
            qualify("x", self.namespace)  # checks every part
        if not 0 <= self.domain_id <= 232:
            raise WireError(f"ROS domain id {self.domain_id} is outside 0..232")
        if not re.fullmatch(r"[0-9a-f]{1,32}", self.session_id):
            raise WireError(f"session id {self.session_id!r} is not a Zenoh id in hex")

    def _prefix(self, entity_id: int, kind: EntityKind) -> str:
        return (f"{ADMIN_SPACE}/{self.domain_id}/{self.session_id}/{self.node_id}/{entity_id}/"
                f"{kind}/{mangle(self.enclave)}/{mangle(self.namespace)}/{mangle(self.name)}")

    def node_token(self) -> str:
        return self._prefix(self.node_id, "NN")

    def entity_token(self, entity_id: int, kind: EntityKind, topic: str, ros_type: str,
                     qos: QoS) -> str:
        """The token of a publisher (``MP``) or subscription (``MS``) of this node."""
        return (f"{self._prefix(entity_id, kind)}/{mangle(topic)}/{dds_type_name(ros_type)}/"
                f"{type_hash(ros_type)}/{qos.to_keyexpr()}")


@dataclass(frozen=True)
class TokenInfo:
    """A liveliness token read back (what a graph view of the network lists)."""

    domain_id: int
    session_id: str
    node_id: str
    entity_id: str
    kind: str
    enclave: str
    namespace: str
    node_name: str
    topic: str | None = None
    dds_type: str | None = None
    type_hash: str | None = None
    qos: str | None = None


def parse_token(key: str) -> TokenInfo:
    """Read a ``@ros2_lv/...`` key; raises :class:`WireError` for anything else."""
    parts = key.split("/")
    if len(parts) not in (9, 13) or parts[0] != ADMIN_SPACE:
        raise WireError(f"{key!r} is not an rmw_zenoh liveliness token")
    if parts[5] not in ("NN", "MP", "MS", "SS", "SC"):
        raise WireError(f"{key!r}: unknown entity kind {parts[5]!r}")
    topic = parts[9:] if len(parts) == 13 else [None] * 4
    return TokenInfo(
        domain_id=int(parts[1]), session_id=parts[2], node_id=parts[3], entity_id=parts[4],
        kind=parts[5], enclave=demangle(parts[6]), namespace=demangle(parts[7]),
        node_name=demangle(parts[8]),
        topic=demangle(topic[0]) if topic[0] is not None else None,
        dds_type=topic[1], type_hash=topic[2], qos=topic[3],
    )


# --- CDR ------------------------------------------------------------------------------


def serialize(message: Any, ros_type: str) -> bytes:
    """CDR bytes of a rosbags message object (little-endian, as ROS 2 sends)."""
    return bytes(typestore().serialize_cdr(message, ros_type))


def deserialize(payload: bytes, ros_type: str) -> Any:
    """A rosbags message object from CDR bytes; raises :class:`WireError` if they do not
    hold a ``ros_type``."""
    message_class(ros_type)
    try:
        return typestore().deserialize_cdr(payload, ros_type)
    except Exception as exc:  # rosbags raises several kinds for truncated or bad data
        raise WireError(f"not a CDR {ros_type}: {type(exc).__name__}: {exc}") from None
