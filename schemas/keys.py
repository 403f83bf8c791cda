"""Every Zenoh key expression zenav uses, and the message type each one carries.

Keys are ``zenav/<robot_id>/<topic>``; the robot id comes from configuration, so several
robots (or several simulated runs) can share one Zenoh network without hearing each
other.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from zenav.schemas.messages import (
    BaseCommand,
    GlobalPath,
    GroundTruth,
    LaserScan,
    Message,
    ObstacleChain,
    OccupancyMap,
    Odometry,
    PlannerEvent,
    PlannerState,
    RawLaserFrame,
    RunResult,
    ServiceStatus,
    TrackList,
    VelocityCommand,
)

ROOT = "zenav"
_ROBOT_ID = re.compile(r"^[A-Za-z0-9_-]{1,64}$")
_SERVICE = re.compile(r"^[a-z0-9_]{1,64}$")


@dataclass(frozen=True)
class Topic:
    """One data stream: its key suffix, message type and largest accepted payload."""

    name: str
    message: type[Message]
    max_bytes: int = 64 * 1024


# Largest payloads, with room to spare: a 3601-beam scan (0.1 deg over 360 deg) is ~14.5 KB;
# odometry and commands are ~100 B; 400 obstacles or tracks are ~120 KB.
RAW_LASER = Topic("device/laser", RawLaserFrame, max_bytes=32 * 1024)
BASE_CMD = Topic("device/base_cmd", BaseCommand, max_bytes=1024)
SCAN = Topic("scan", LaserScan, max_bytes=32 * 1024)
ODOM = Topic("odom", Odometry, max_bytes=1024)
OBSTACLES = Topic("obstacles", ObstacleChain, max_bytes=256 * 1024)
TRACKS = Topic("tracks", TrackList, max_bytes=256 * 1024)
CMD_VEL = Topic("cmd_vel", VelocityCommand, max_bytes=1024)
EVENTS = Topic("planner/events", PlannerEvent)
EVENT_HISTORY = Topic("planner/history", PlannerEvent)  # queryable: every event so far
PLANNER_STATE = Topic("planner/state", PlannerState)
PATH = Topic("planner/path", GlobalPath, max_bytes=256 * 1024)
MAP = Topic("planner/map", OccupancyMap, max_bytes=8 * 1024 * 1024)  # 2000 x 2000 cells
TRUTH = Topic("sim/truth", GroundTruth, max_bytes=256 * 1024)
RESULT = Topic("sim/result", RunResult, max_bytes=16 * 1024 * 1024)
STATUS = Topic("status", ServiceStatus)  # zenav/<robot>/status/<service>

TOPICS: tuple[Topic, ...] = (
    RAW_LASER,
    BASE_CMD,
    SCAN,
    ODOM,
    OBSTACLES,
    TRACKS,
    CMD_VEL,
    EVENTS,
    PLANNER_STATE,
    PATH,
    MAP,
    TRUTH,
    RESULT,
)


def check_robot_id(robot_id: str) -> str:
    if not _ROBOT_ID.match(robot_id):
        raise ValueError(
            f"robot id {robot_id!r} must be 1-64 letters, digits, '_' or '-' "
            "(it becomes part of every key)"
        )
    return robot_id


@dataclass(frozen=True)
class Keys:
    """The key expressions of one robot."""

    robot_id: str

    def __post_init__(self) -> None:
        check_robot_id(self.robot_id)

    @property
    def prefix(self) -> str:
        return f"{ROOT}/{self.robot_id}"

    def of(self, topic: Topic) -> str:
        return f"{self.prefix}/{topic.name}"

    def alive(self, service: str) -> str:
        """Liveliness token of one service."""
        if not _SERVICE.match(service):
            raise ValueError(f"service name {service!r} must match {_SERVICE.pattern}")
        return f"{self.prefix}/alive/{service}"

    @property
    def alive_any(self) -> str:
        return f"{self.prefix}/alive/*"

    def status(self, service: str) -> str:
        return f"{self.prefix}/{STATUS.name}/{service}"

    @property
    def status_any(self) -> str:
        return f"{self.prefix}/{STATUS.name}/*"

    @property
    def everything(self) -> str:
        return f"{self.prefix}/**"
