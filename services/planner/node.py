"""Planner service: tracks in (they carry the robot pose at scan time) and the scan of
the same stamp (for the map and the stop zone), one velocity command per scan out, plus
an event for every decision that changes what the robot does, the planner's state for
monitors, the global path (when it is planned again or no way is found, and again every
``path_period`` while it stays the same, for subscribers that join late) and the map once a
second.

Joining the two halves of a stamp: a decision is made once both the track list and the
scan of one stamp are in, whichever came first, so the result does not depend on their
arrival order. A track list whose scan has not come within ``scan_wait`` wall seconds
(or is overtaken by a newer track list) is decided on without a map update or a stop
zone check; the motor bridge's own stop zone still holds. The join is
:class:`~zenav.services.node.StampJoin`'s, shared with the baselines' service.
"""

from __future__ import annotations

from collections import deque

import numpy as np
import numpy.typing as npt

from zenav.schemas import keys
from zenav.schemas.messages import (
    Action,
    GlobalPath,
    LaserScan,
    ObstacleKind,
    OccupancyMap,
    PlannerEvent,
    PlannerState,
    ScenarioLetter,
    TrackList,
    VelocityCommand,
)
from zenav.services.node import Node, StampGate, StampJoin
from zenav.services.planner.costmap import ScanData
from zenav.services.planner.decide import Decision, Planner
from zenav.services.planner.params import Params
from zenav.services.planner.prediction import Obstacle


def obstacles_of(tracks: TrackList) -> list[Obstacle]:
    return [
        Obstacle(id=t.id, kind=t.kind, position=(t.x, t.y),
                 velocity=(t.vx, t.vy) if t.kind == "dynamic" else (0.0, 0.0),
                 radius=t.radius, cells=t.cells)
        for t in tracks.tracks
    ]


def scan_data(scan: LaserScan, pose: tuple[float, float, float]) -> ScanData:
    """The scan as the planner's map reads it, with the pose it was taken from."""
    return ScanData(pose, scan.ranges.astype(np.float64), scan.angle_min, scan.angle_increment,
                    scan.range_max, scan.range_min)


EventRow = tuple[ScenarioLetter, Action, int | None, ObstacleKind | None, str]

EVENTS_KEPT = 10_000
"""Events the planner keeps for queries: far more than a run makes, still bounded."""

RESUME_AFTER = 3
"""Cycles without any threat before a return to plain driving is reported."""


class EventLog:
    """Decides which decisions are events: every change of scenario, action or obstacle
    (a return to plain driving once it has lasted ``RESUME_AFTER`` cycles, so a threat
    that flickers off for one scan is not reported twice), and every crosser judged
    harmless ((c) or (d)) once, when the crossing is within the planner's horizon."""

    def __init__(self, horizon: float) -> None:
        self.horizon = horizon
        self.last: tuple[str, str, int | None] | None = None
        self.calm = 0  # cycles in a row with nothing to answer
        self.seen_crossers: set[int] = set()

    def events(self, decision: Decision) -> list[EventRow]:
        found: list[EventRow] = []
        for note in decision.notes:
            soon = min(note.robot_time, note.obstacle_time) <= self.horizon
            if note.letter in "cd" and soon and note.obstacle.id not in self.seen_crossers:
                self.seen_crossers.add(note.obstacle.id)
                found.append((note.letter, "keep", note.obstacle.id, note.obstacle.kind,
                              f"meets the path {note.obstacle_time:.1f} s from now, "
                              f"robot in {note.robot_time:.1f} s"))
        current = (decision.scenario, decision.action, decision.obstacle)
        plain = decision.scenario == "a" and decision.action == "keep"
        self.calm = self.calm + 1 if plain else 0
        if current == self.last or (plain and self.last is not None and 0 < self.calm
                                    < RESUME_AFTER):
            return found
        action: Action = decision.action
        if plain and self.last is not None:
            action = "resume"
        self.last = current
        if decision.obstacle is not None:
            self.seen_crossers.add(decision.obstacle)  # answered: not reported as (c)/(d)
        found.append((decision.scenario, action, decision.obstacle, decision.kind,
                      f"speed {decision.speed:.2f} m/s toward "
                      f"({decision.target[0]:.2f}, {decision.target[1]:.2f})"))
        return found


PathKey = tuple[str, int, str]
"""What a published global path stands for: ("path", plan number, "") or ("none", 0, why)."""

NO_PATH = np.empty((0, 2))


def current_path(planner: Planner) -> tuple[PathKey, npt.NDArray[np.float64], str] | None:
    """The global path the planner goes by, as it is published: what it stands for, its
    vertices and its reason. None before the planner has one; no vertices while the map
    shows no way to the goal (the planner then keeps driving its old path, in recovery,
    but that path is known to be blocked), and for good once the goal is unreachable."""
    plan = planner.plan
    if plan is not None and not plan.found:
        why = plan.reason
        if planner.recovery.unreachable:
            why = f"goal unreachable: {why}"
        return ("none", 0, why[:100]), NO_PATH, why[:100]
    if planner.path is None:
        return None
    reason = plan.reason if plan is not None else "start"
    return ("path", planner.plan_count, ""), planner.path, reason[:100]


SCANS_KEPT = 8
"""Scans kept while their track lists are on the way."""


class Service:
    def __init__(self, node: Node, params: Params) -> None:
        self.node = node
        self.params = params
        self.planner = Planner(params)
        self.log = EventLog(params.horizon)
        self.commands = node.publisher(keys.CMD_VEL, VelocityCommand, urgent=True)
        self.events = node.publisher(keys.EVENTS, PlannerEvent, reliable=True)
        # Every event so far, for whoever asks (a run that joined late, a monitor).
        self.history: deque[bytes] = deque(maxlen=EVENTS_KEPT)
        node.bus.declare_queryable(node.keys.of(keys.EVENT_HISTORY), lambda: list(self.history))
        self.state = node.publisher(keys.PLANNER_STATE, PlannerState)
        self.paths = node.publisher(keys.PATH, GlobalPath, reliable=True)
        self.maps = node.publisher(keys.MAP, OccupancyMap)
        self.gate = StampGate(node, keys.TRACKS)
        # A track list and the scan of its stamp, joined (the latest few scans kept).
        self.join = StampJoin[TrackList, LaserScan](self.decide, params.scan_wait, SCANS_KEPT)
        self.path_sent: PathKey | None = None  # what the last path published stood for
        self.path_last: GlobalPath | None = None  # and that message, for its repeats
        self.map_sent = -1.0  # stamp of the last map published
        node.subscribe(keys.TRACKS, TrackList, self.on_tracks, depth=2)
        node.subscribe(keys.SCAN, LaserScan, self.on_scan, depth=2)

    def on_scan(self, scan: LaserScan) -> None:
        self.join.companion(scan)

    def on_tracks(self, tracks: TrackList) -> None:
        if not self.gate.admit(tracks.stamp, self.commands):
            return
        self.join.arrive(tracks)

    def decide(self, tracks: TrackList, scan: LaserScan | None) -> None:
        pose = tracks.pose
        xyh = (pose.x, pose.y, pose.heading)
        decision = self.planner.step(xyh, obstacles_of(tracks), tracks.stamp,
                                     None if scan is None else scan_data(scan, xyh))
        for letter, action, obstacle, kind, detail in self.log.events(decision):
            self.history.append(self.events.publish(PlannerEvent(
                stamp=tracks.stamp, seq=self.events.next_seq(), obstacle=obstacle,
                kind=kind, scenario=letter, action=action, detail=detail)))
        # The path before the command: the command leads, through the motor bridge and the
        # simulator, to the run's result, and a path sent after it could reach the run's
        # recorder behind the result of a run that ends on this tick.
        self.publish_path(tracks.stamp)
        self.commands.publish(VelocityCommand(stamp=tracks.stamp, seq=self.commands.next_seq(),
                                              v=decision.v, omega=decision.omega))
        self.state.publish(PlannerState(
            stamp=tracks.stamp, seq=self.state.next_seq(), scenario=decision.scenario,
            action=decision.action, target=decision.target, speed=decision.speed))
        self.publish_map(tracks.stamp)

    def publish_map(self, stamp: float) -> None:
        costmap = self.planner.costmap
        if costmap is not None and stamp - self.map_sent >= self.params.map_period:
            self.map_sent = stamp
            values = costmap.values()
            nx, ny = values.shape
            self.maps.publish(OccupancyMap(
                stamp=stamp, seq=self.maps.next_seq(),
                origin=(float(costmap.origin[0]), float(costmap.origin[1])),
                resolution=costmap.resolution, width=nx, height=ny,
                cells=np.ascontiguousarray(values.T).ravel()))

    def publish_path(self, stamp: float) -> None:
        """A new global path (or the news that there is none) at once; the same again,
        a new message stamped now, once ``path_period`` has passed since the last send."""
        current = current_path(self.planner)
        if current is None:
            return
        key, points, reason = current
        last = self.path_last
        if key != self.path_sent or last is None:
            self.path_sent = key
            self.path_last = GlobalPath(stamp=stamp, seq=self.paths.next_seq(), points=points,
                                        reason=reason, planned=stamp)
        elif last.stamp <= stamp < last.stamp + self.params.path_period - 1e-9:
            return  # sent within the period (a clock that went back sends at once)
        else:
            self.path_last = last.model_copy(update={"stamp": stamp,
                                                     "seq": self.paths.next_seq()})
        self.paths.publish(self.path_last)


if __name__ == "__main__":
    from zenav.services.runner import main

    raise SystemExit(main("planner"))
