"""Planner service: tracks in (they carry the robot pose at scan time), one velocity
command per scan out, plus an event for every decision that changes what the robot does
and the planner's state for monitors."""

from __future__ import annotations

from collections import deque

from zenav.schemas import keys
from zenav.schemas.messages import (
    Action,
    ObstacleKind,
    PlannerEvent,
    PlannerState,
    ScenarioLetter,
    TrackList,
    VelocityCommand,
)
from zenav.services.node import Node, StampGate
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


class Service:
    def __init__(self, node: Node, params: Params) -> None:
        self.node = node
        self.planner = Planner(params)
        self.log = EventLog(params.horizon)
        self.commands = node.publisher(keys.CMD_VEL, VelocityCommand, urgent=True)
        self.events = node.publisher(keys.EVENTS, PlannerEvent, reliable=True)
        # Every event so far, for whoever asks (a run that joined late, a monitor).
        self.history: deque[bytes] = deque(maxlen=EVENTS_KEPT)
        node.bus.declare_queryable(node.keys.of(keys.EVENT_HISTORY), lambda: list(self.history))
        self.state = node.publisher(keys.PLANNER_STATE, PlannerState)
        self.gate = StampGate(node, keys.TRACKS)
        node.subscribe(keys.TRACKS, TrackList, self.on_tracks, depth=2)

    def on_tracks(self, tracks: TrackList) -> None:
        if not self.gate.admit(tracks.stamp, self.commands):
            return
        pose = tracks.pose
        decision = self.planner.step((pose.x, pose.y, pose.heading), obstacles_of(tracks),
                                     tracks.stamp)
        for letter, action, obstacle, kind, detail in self.log.events(decision):
            self.history.append(self.events.publish(PlannerEvent(
                stamp=tracks.stamp, seq=self.events.next_seq(), obstacle=obstacle,
                kind=kind, scenario=letter, action=action, detail=detail)))
        self.commands.publish(VelocityCommand(stamp=tracks.stamp, seq=self.commands.next_seq(),
                                              v=decision.v, omega=decision.omega))
        self.state.publish(PlannerState(
            stamp=tracks.stamp, seq=self.state.next_seq(), scenario=decision.scenario,
            action=decision.action, target=decision.target, speed=decision.speed))


if __name__ == "__main__":
    from zenav.services.runner import main

    raise SystemExit(main("planner"))
