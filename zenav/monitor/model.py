"""What the monitor knows: :class:`MonitorModel`, fed with samples and liveliness
changes, with no I/O (see :mod:`zenav.monitor`)."""

from __future__ import annotations

import math
import statistics
from collections import Counter, OrderedDict, deque
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import numpy.typing as npt

from zenav.schemas import keys
from zenav.schemas.codec import DecodeError, decode
from zenav.schemas.keys import Keys, Topic
from zenav.schemas.messages import (
    BaseCommand,
    GlobalPath,
    GroundTruth,
    LaserScan,
    Message,
    OccupancyMap,
    Odometry,
    PlannerEvent,
    PlannerState,
    RunResult,
    ServiceStatus,
    TrackList,
    VelocityCommand,
)
from zenav.services.config import SERVICE_ORDER

TOPICS: dict[str, Topic] = {t.name: t for t in keys.TOPICS}

STOPPED_BELOW = 1e-3
"""m/s: a robot slower than this is at a standstill."""


@dataclass
class Event:
    wall: float
    kind: str
    data: dict[str, Any]

    def as_dict(self) -> dict[str, Any]:
        return {"event": self.kind, "wall": round(self.wall, 6), **self.data}


class RateMeter:
    """Messages per second over a sliding window, and the typical gap between them."""

    def __init__(self, window: float = 2.0) -> None:
        self.window = window
        self.times: deque[float] = deque()
        self.gaps: deque[float] = deque(maxlen=20)

    def add(self, now: float) -> None:
        if self.times:
            self.gaps.append(now - self.times[-1])
        self.times.append(now)
        self._trim(now)

    def _trim(self, now: float) -> None:
        while self.times and self.times[0] < now - self.window:
            self.times.popleft()

    def rate(self, now: float) -> float:
        self._trim(now)
        return len(self.times) / self.window

    def typical_gap(self) -> float | None:
        return statistics.median(self.gaps) if len(self.gaps) >= 3 else None


class LatencyMeter:
    """Scan-to-command latency: wall time from a scan's receipt to the receipt of the
    command with the same stamp."""

    def __init__(self, pending: int = 256, keep: int = 200) -> None:
        self._scans: OrderedDict[float, float] = OrderedDict()
        self._pending = pending
        self.samples: deque[float] = deque(maxlen=keep)

    def scan(self, stamp: float, now: float) -> None:
        if stamp in self._scans:
            return  # a retransmission: the first receipt counts
        self._scans[stamp] = now
        while len(self._scans) > self._pending:
            self._scans.popitem(last=False)

    def command(self, stamp: float, now: float) -> float | None:
        received = self._scans.pop(stamp, None)
        if received is None:
            return None
        latency = now - received
        self.samples.append(latency)
        return latency

    def stats(self) -> dict[str, float | int | None]:
        if not self.samples:
            return {"n": 0, "last": None, "median": None, "p95": None, "max": None}
        ordered = sorted(self.samples)
        p95 = ordered[min(len(ordered) - 1, math.ceil(0.95 * len(ordered)) - 1)]
        return {"n": len(ordered), "last": self.samples[-1],
                "median": statistics.median(ordered), "p95": p95, "max": ordered[-1]}


@dataclass
class ServiceState:
    alive: bool | None = None  # None: never seen
    since: float | None = None
    rejoins: int = 0
    status: ServiceStatus | None = None


@dataclass
class TopicState:
    meter: RateMeter
    last: float | None = None
    flowing: bool = False
    count: int = 0


def path_length(points: npt.NDArray[np.float64]) -> float:
    """m along the vertices (0 for fewer than two)."""
    if len(points) < 2:
        return 0.0
    return float(np.hypot(*np.diff(points, axis=0).T).sum())


def along_path(points: npt.NDArray[np.float64], x: float, y: float) -> tuple[float, float]:
    """(m still to go along the path from the point of it nearest (x, y), m from (x, y) to
    that point). The path needs two vertices or more."""
    a, b = points[:-1], points[1:]
    d = b - a
    seg = np.hypot(d[:, 0], d[:, 1])
    q = np.array([x, y])
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.where(seg > 0, ((q - a) * d).sum(axis=1) / np.maximum(seg, 1e-12) ** 2, 0.0)
    t = np.clip(t, 0.0, 1.0)
    nearest = a + t[:, None] * d
    gaps = np.hypot(*(nearest - q).T)
    k = int(np.argmin(gaps))
    to_go = float(seg[k] * (1.0 - t[k]) + seg[k + 1:].sum())
    return to_go, float(gaps[k])


@dataclass(frozen=True)
class PathState:
    """The planner's newest global path as the monitor heard it. The planner sends an
    unchanged path again every ``path_period``: a repeat refreshes ``message`` and
    ``received`` but is not another plan."""

    message: GlobalPath  # the newest message of this plan (a repeat or the first send)
    received: float  # wall time it was heard
    length: float  # m
    plans: int  # distinct paths heard since the monitor started

    @property
    def found(self) -> bool:
        return len(self.message.points) >= 2


@dataclass(frozen=True)
class MapState:
    """The planner's newest occupancy map, with its cell counts (taken once, on receipt:
    the grid can be millions of cells)."""

    message: OccupancyMap
    received: float  # wall time
    known: int  # cells free or occupied
    occupied: int

    @classmethod
    def of(cls, message: OccupancyMap, received: float) -> MapState:
        cells = message.cells
        return cls(message, received, known=int(np.count_nonzero(cells >= 0)),
                   occupied=int(np.count_nonzero(cells > 50)))

    @property
    def cells(self) -> int:
        return self.message.width * self.message.height


@dataclass
class MonitorModel:
    """Everything the monitor shows, from the messages and tokens it has seen."""

    robot_id: str
    expected: Sequence[str] = SERVICE_ORDER
    rate_window: float = 2.0
    silence_after: float = 0.5
    services: dict[str, ServiceState] = field(default_factory=dict)
    topics: dict[str, TopicState] = field(default_factory=dict)
    latency: LatencyMeter = field(default_factory=LatencyMeter)
    rejected: Counter[str] = field(default_factory=Counter)
    odom: Odometry | None = None
    truth: GroundTruth | None = None
    tracks: TrackList | None = None
    planner: PlannerState | None = None
    decision: PlannerEvent | None = None
    base: BaseCommand | None = None
    command: VelocityCommand | None = None
    result: dict[str, Any] | None = None
    path: PathState | None = None
    map: MapState | None = None
    moving: dict[str, bool] = field(default_factory=dict)
    recent: deque[Event] = field(default_factory=lambda: deque(maxlen=8))
    _events: list[Event] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.keys = Keys(self.robot_id)
        self._prefix = self.keys.prefix + "/"
        for name in self.expected:
            self.services.setdefault(name, ServiceState())

    # -- input ---------------------------------------------------------------------------

    def emit(self, at: float, what: str, **data: Any) -> None:
        event = Event(at, what, data)
        self._events.append(event)
        self.recent.append(event)

    def drain_events(self) -> list[Event]:
        events, self._events = self._events, []
        return events

    def on_liveliness(self, key: str, alive: bool, now: float) -> None:
        service = key.rsplit("/", 1)[-1]
        state = self.services.setdefault(service, ServiceState())
        if state.alive == alive:
            return
        if alive and state.alive is False:
            state.rejoins += 1
        state.alive, state.since = alive, now
        self.emit(now, "alive", service=service, alive=alive)

    def on_sample(self, key: str, payload: bytes, now: float) -> None:
        if not key.startswith(self._prefix):
            return
        name = key[len(self._prefix):]
        self._count(name, now)
        if name.startswith(keys.STATUS.name + "/"):
            status = self._decode(payload, keys.STATUS, key, ServiceStatus)
            if status is not None:
                self.services.setdefault(status.service, ServiceState()).status = status
            return
        topic = TOPICS.get(name)
        if topic is None:
            return
        message = self._decode(payload, topic, key, topic.message)
        if message is not None:
            self._apply(message, now)

    def _decode(self, payload: bytes, topic: Topic, key: str,
                message_type: type[Any]) -> Any:
        try:
            return decode(payload, message_type, key, topic.max_bytes)
        except DecodeError as exc:
            self.rejected[exc.kind] += 1
            return None

    def _silence_limit(self, topic: TopicState) -> float:
        gap = topic.meter.typical_gap()
        return max(self.silence_after, 4 * gap if gap is not None else 2.0)

    def _count(self, name: str, now: float) -> None:
        topic = self.topics.get(name)
        if topic is None:
            topic = self.topics[name] = TopicState(RateMeter(self.rate_window))
        elif topic.flowing and topic.last is not None and \
                now - topic.last > self._silence_limit(topic):
            # A gap that ended before tick() noticed it: report it all the same.
            topic.flowing = False
            self.emit(topic.last, "flow", topic=name, flowing=False, noticed=round(now, 6))
        topic.meter.add(now)
        topic.last = now
        topic.count += 1
        if not topic.flowing:
            topic.flowing = True
            self.emit(now, "flow", topic=name, flowing=True)

    def _motion(self, source: str, v: float, x: float, y: float, now: float) -> None:
        moving = abs(v) >= STOPPED_BELOW
        if self.moving.get(source) != moving:
            self.moving[source] = moving
            self.emit(now, "motion", source=source, moving=moving, v=round(v, 4),
                      x=round(x, 3), y=round(y, 3))

    def _apply(self, message: Message, now: float) -> None:
        if isinstance(message, Odometry):
            self.odom = message
            self._motion("odom", message.v, message.pose.x, message.pose.y, now)
        elif isinstance(message, GroundTruth):
            self.truth = message
            self._motion("truth", message.v, message.pose.x, message.pose.y, now)
        elif isinstance(message, LaserScan):
            self.latency.scan(message.stamp, now)
        elif isinstance(message, VelocityCommand):
            self.command = message
            self.latency.command(message.stamp, now)
        elif isinstance(message, BaseCommand):
            if self.base is None or self.base.reason != message.reason:
                self.emit(now, "base", reason=message.reason, stamp=message.stamp,
                          v=round(message.v, 4))
            self.base = message
        elif isinstance(message, TrackList):
            self.tracks = message
        elif isinstance(message, PlannerState):
            if self.planner is None or (self.planner.scenario, self.planner.action) != (
                    message.scenario, message.action):
                self.emit(now, "planner", scenario=message.scenario, action=message.action,
                          stamp=message.stamp)
            self.planner = message
        elif isinstance(message, PlannerEvent):
            self.decision = message
            self.emit(now, "decision", scenario=message.scenario, action=message.action,
                      obstacle=message.obstacle, kind=message.kind, stamp=message.stamp)
        elif isinstance(message, GlobalPath):
            if self.path is not None and message.repeats(self.path.message):
                self.path = replace(self.path, message=message, received=now)
                return
            plans = 1 if self.path is None else self.path.plans + 1
            self.path = PathState(message, now, path_length(message.points), plans)
            self.emit(now, "path", reason=message.reason, waypoints=len(message.points),
                      length=round(self.path.length, 3), stamp=message.planned_at)
        elif isinstance(message, OccupancyMap):
            self.map = MapState.of(message, now)
        elif isinstance(message, RunResult):
            result = {"outcome": message.outcome, "time": message.time,
                      "path_length": round(message.path_length, 4),
                      "min_clearance": None if math.isinf(message.min_clearance)
                      else round(message.min_clearance, 4),
                      "collided_with": message.collided_with}
            if self.result != result:
                self.result = result
                self.emit(now, "result", **result)

    def tick(self, now: float) -> None:
        """Notice topics that stopped flowing (no message for 4 typical gaps, at least
        ``silence_after`` s)."""
        for name, topic in self.topics.items():
            if not topic.flowing or topic.last is None:
                continue
            if now - topic.last > self._silence_limit(topic):
                topic.flowing = False
                self.emit(topic.last, "flow", topic=name, flowing=False, noticed=round(now, 6))

    # -- output --------------------------------------------------------------------------

    def snapshot(self, now: float) -> dict[str, Any]:
        robot = None
        if self.odom is not None:
            p = self.odom.pose
            robot = {"stamp": self.odom.stamp, "x": round(p.x, 4), "y": round(p.y, 4),
                     "heading_deg": round(math.degrees(p.heading), 2),
                     "v": round(self.odom.v, 4), "omega": round(self.odom.omega, 4)}
        truth = None
        if self.truth is not None:
            p = self.truth.pose
            truth = {"stamp": self.truth.stamp, "x": round(p.x, 4), "y": round(p.y, 4),
                     "v": round(self.truth.v, 4)}
        obstacles = [
            {"id": t.id, "kind": t.kind, "x": round(t.x, 3), "y": round(t.y, 3),
             "speed": round(t.speed, 3), "heading_deg": round(math.degrees(t.heading), 1),
             "visible": t.visible}
            for t in (self.tracks.tracks if self.tracks is not None else [])
        ]
        return {
            "event": "snapshot",
            "wall": round(now, 6),
            "robot_id": self.robot_id,
            "robot": robot,
            "truth": truth,
            "base": None if self.base is None else {
                "stamp": self.base.stamp, "v": round(self.base.v, 4),
                "omega": round(self.base.omega, 4), "reason": self.base.reason},
            "planner": None if self.planner is None else {
                "stamp": self.planner.stamp, "scenario": self.planner.scenario,
                "action": self.planner.action, "speed": round(self.planner.speed, 4)},
            "obstacles": obstacles,
            "services": {
                name: {"alive": s.alive, "since": s.since, "rejoins": s.rejoins,
                       "received": sum(s.status.received.values()) if s.status else None,
                       "rejected": sum(s.status.rejected.values()) if s.status else None,
                       "dropped": sum(s.status.dropped.values()) if s.status else None}
                for name, s in sorted(self.services.items())
            },
            "rates": {name: round(t.meter.rate(now), 2) for name, t in sorted(self.topics.items())},
            "flowing": {name: t.flowing for name, t in sorted(self.topics.items())},
            "latency": {k: (round(v, 6) if isinstance(v, float) else v)
                        for k, v in self.latency.stats().items()},
            "result": self.result,
            "path": self._path_snapshot(now),
            "map": self._map_snapshot(now),
            "rejected": dict(self.rejected),
        }

    def robot_xy(self) -> tuple[float, float] | None:
        """Where the robot is: odometry (the planner's frame), else ground truth."""
        source = self.odom if self.odom is not None else self.truth
        return None if source is None else (source.pose.x, source.pose.y)

    def _path_snapshot(self, now: float) -> dict[str, Any] | None:
        if self.path is None:
            return None
        path = self.path
        points = path.message.points
        to_go = off_path = None
        robot = self.robot_xy()
        if robot is not None and path.found:
            along, off = along_path(points, *robot)
            to_go, off_path = round(along, 3), round(off, 3)
        return {"stamp": path.message.planned_at, "sent": path.message.stamp,
                "seq": path.message.seq, "reason": path.message.reason,
                "waypoints": len(points),
                "length": round(path.length, 3), "found": path.found,
                "goal": [round(float(v), 3) for v in points[-1]] if path.found else None,
                "age": round(now - path.received, 3), "plans": path.plans,
                "to_go": to_go, "off_path": off_path,
                "points": [[round(float(x), 3), round(float(y), 3)] for x, y in points]}

    def _map_snapshot(self, now: float) -> dict[str, Any] | None:
        if self.map is None:
            return None
        m = self.map
        grid = m.message
        return {"stamp": grid.stamp, "seq": grid.seq, "width": grid.width,
                "height": grid.height, "resolution": grid.resolution,
                "origin": [round(grid.origin[0], 4), round(grid.origin[1], 4)],
                "size": [round(grid.width * grid.resolution, 3),
                         round(grid.height * grid.resolution, 3)],
                "known_fraction": round(m.known / m.cells, 4),
                "occupied_fraction": round(m.occupied / m.cells, 4),
                "occupied_cells": m.occupied, "age": round(now - m.received, 3)}
