"""``zenav monitor``: a live, read-only view of a running stack, from any host.

:class:`MonitorModel` is what the monitor knows, fed with (key, payload, receive time)
and liveliness changes; it has no I/O and is tested without a terminal. The screen
(:func:`render`, with ``rich``) and the JSON-lines output (``--jsonl``, for scripts and
tests) both read it.

What it tracks:

- the robot: pose and speed from odometry; speed in ground truth too when a simulator
  publishes it; the last base command and why (``command``, ``stale``, ``idle``);
- the obstacles: the latest track list, with type, speed and heading;
- the planner: the current scenario letter and action, the latest decision;
- each service's liveliness token, with restarts counted, and its status counters;
- the rate of every topic, and when a topic stops or starts flowing;
- scan-to-command latency: for a scan with stamp ``s``, the wall time between the
  monitor receiving that scan and receiving the velocity command stamped ``s``. Both
  receive times are taken in the same process (in Zenoh's callback), so no clock
  synchronisation is needed; the figure includes the monitor's own receive path for the
  command, which on one host is tens of microseconds.

Events (``drain_events``) are state changes with the wall time they happened:
``alive`` (a token appeared or went), ``flow`` (a topic stopped or started), ``base``
(the base command's reason changed, e.g. to ``stale``), ``motion`` (the robot started or
came to a standstill), ``planner`` (scenario or action changed), ``decision`` (a planner
event), ``result`` (the simulated run ended).
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import json
import math
import statistics
import sys
import time
from collections import Counter, OrderedDict, deque
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import IO, Any

from zenav.schemas import keys
from zenav.schemas.codec import DecodeError, decode
from zenav.schemas.keys import Keys, Topic
from zenav.schemas.messages import (
    BaseCommand,
    GroundTruth,
    LaserScan,
    Message,
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
            "rejected": dict(self.rejected),
        }


# --- the screen ---------------------------------------------------------------------------


def _ms(value: float | int | None) -> str:
    return "-" if value is None else f"{1000 * value:.1f} ms"


def render(model: MonitorModel, now: float) -> Any:
    """The monitor's screen for ``rich``."""
    from rich.console import Group
    from rich.table import Table
    from rich.text import Text

    snap = model.snapshot(now)
    header = Text(f"zenav monitor  robot {model.robot_id}  "
                  f"{time.strftime('%H:%M:%S', time.localtime(now))}", style="bold")

    robot = Table(title="robot", title_justify="left", expand=False)
    for column in ("source", "x", "y", "heading", "v", "command"):
        robot.add_column(column)
    base = snap["base"]
    command = "-" if base is None else f"{base['v']:.2f} m/s ({base['reason']})"
    if snap["robot"] is not None:
        r = snap["robot"]
        robot.add_row("odometry", f"{r['x']:.2f}", f"{r['y']:.2f}", f"{r['heading_deg']:.0f}°",
                      f"{r['v']:.3f}", command)
    if snap["truth"] is not None:
        t = snap["truth"]
        robot.add_row("ground truth", f"{t['x']:.2f}", f"{t['y']:.2f}", "", f"{t['v']:.3f}", "")
    if snap["robot"] is None and snap["truth"] is None:
        robot.add_row("(no odometry yet)", "", "", "", "", command)

    planner = snap["planner"]
    plan = Text("planner: " + ("-" if planner is None else
                               f"scenario {planner['scenario']}, action {planner['action']}, "
                               f"speed {planner['speed']:.2f} m/s"))
    if snap["result"] is not None:
        res = snap["result"]
        plan.append(f"   run: {res['outcome']} at t={res['time']:.1f} s",
                    style="green" if res["outcome"] == "reached" else "red")
    latency = snap["latency"]
    lat = Text(f"scan→command latency: last {_ms(latency['last'])}, median "
               f"{_ms(latency['median'])}, p95 {_ms(latency['p95'])}, max {_ms(latency['max'])}"
               f" ({latency['n']} samples)")

    services = Table(title="services", title_justify="left")
    for column in ("service", "alive", "for", "rejoins", "rx", "rejected", "dropped"):
        services.add_column(column)
    for name, s in snap["services"].items():
        alive = {True: Text("alive", style="green"), False: Text("gone", style="bold red"),
                 None: Text("never seen", style="yellow")}[s["alive"]]
        since = "-" if s["since"] is None else f"{now - s['since']:.0f} s"
        services.add_row(name, alive, since, str(s["rejoins"]),
                         *("-" if s[k] is None else str(s[k])
                           for k in ("received", "rejected", "dropped")))

    rates = Table(title="topics", title_justify="left")
    for column in ("topic", "Hz", "flowing"):
        rates.add_column(column)
    for name, hz in snap["rates"].items():
        if name.startswith("status/"):
            continue  # the services table shows them
        flowing = snap["flowing"][name]
        rates.add_row(name, f"{hz:.1f}", Text("yes" if flowing else "stopped",
                                              style="green" if flowing else "red"))

    obstacles = Table(title="obstacles (tracks)", title_justify="left")
    for column in ("id", "type", "x", "y", "speed", "heading"):
        obstacles.add_column(column)
    for o in snap["obstacles"]:
        obstacles.add_row(str(o["id"]), o["kind"], f"{o['x']:.2f}", f"{o['y']:.2f}",
                          f"{o['speed']:.2f}", f"{o['heading_deg']:.0f}°")

    events = Text("\n".join(
        f"{time.strftime('%H:%M:%S', time.localtime(e.wall))} {e.kind} "
        + " ".join(f"{k}={v}" for k, v in e.data.items()) for e in model.recent))
    middle = Table.grid(padding=(0, 2))
    middle.add_row(services, rates)
    bottom = Table.grid(padding=(0, 2))
    bottom.add_row(obstacles, Group(Text("recent events", style="bold"), events))
    return Group(header, robot, plan, lat, middle, bottom)


# --- the process --------------------------------------------------------------------------


async def monitor(transport: Any, robot_id: str, *, jsonl: bool, period: float,
                  duration: float | None, silence: float = 0.5,
                  out: IO[str] = sys.stdout) -> None:
    from zenav.services.transport import ZenohBus
    from zenav.tooling import StampedSubscriber, stop_on_signals

    model = MonitorModel(robot_id, silence_after=silence)
    loop = asyncio.get_running_loop()
    stop = asyncio.Event()
    stop_on_signals(stop)
    if duration is not None:
        loop.call_later(duration, stop.set)
    bus = ZenohBus(transport, loop)
    subscriber = StampedSubscriber(
        bus, model.keys.everything,
        lambda key, payload, ns: model.on_sample(key, payload, ns / 1e9))
    bus.watch_liveliness(model.keys.alive_any,
                         lambda key, alive: model.on_liveliness(key, alive, time.time()))
    try:
        if jsonl:
            while not stop.is_set():
                now = time.time()
                model.tick(now)
                for event in model.drain_events():
                    out.write(json.dumps(event.as_dict()) + "\n")
                out.write(json.dumps(model.snapshot(now)) + "\n")
                out.flush()
                await _wait(stop, period)
        else:
            from rich.live import Live

            with Live(render(model, time.time()), refresh_per_second=max(1, round(1 / period)),
                      screen=False) as live:
                while not stop.is_set():
                    now = time.time()
                    model.tick(now)
                    model.drain_events()  # shown in "recent events"
                    live.update(render(model, now))
                    await _wait(stop, period)
    finally:
        subscriber.close()
        bus.close()


async def _wait(stop: asyncio.Event, period: float) -> None:
    with contextlib.suppress(TimeoutError):
        await asyncio.wait_for(stop.wait(), timeout=period)


def main(args: argparse.Namespace) -> int:
    from zenav.tooling import tool_setup

    setup = tool_setup(args, "monitor")
    if setup is None:
        return 2
    robot_id, transport = setup
    with contextlib.suppress(KeyboardInterrupt):
        asyncio.run(monitor(transport, robot_id, jsonl=args.jsonl, period=args.period,
                            duration=args.duration, silence=args.silence))
    return 0
