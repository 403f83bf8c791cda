"""The baseline planners as the ``planner`` service (``zenav run --planner
vfh|dwa|apf|orca``, ``zenav service planner --planner ...``): the same inputs and outputs
as the paper's planner. Algorithms: ``vfh.py``, ``dwa.py``, ``apf.py``, ``orca.py``;
parameters: ``params.py``.

It answers each track list with one velocity command stamped with the tracks' stamp
(lockstep depends on it) and answers a repeated stamp by repeating its command. The
scan that goes with a track list (same stamp; it usually arrives first, straight from
the laser driver) and the odometry of that instant are kept by stamp. As in the paper
planner's service (both join them with :class:`~zenav.services.node.StampJoin`), a
decision waits for both halves of a stamp, whichever comes first, so that a loaded
machine does not change the result: a track list whose scan has not
come within ``scan_wait`` wall seconds (or is overtaken by a newer track list) is
decided on the newest scan before it. Tracks give the robot pose
at scan time and the movers. The planner state says ``a`` (no paper scenario) and the
action: ``keep`` when moving, ``stop`` when standing, ``goal`` at the goal; an event is
published when the action changes.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from zenav.schemas import keys
from zenav.schemas.messages import (
    Action,
    LaserScan,
    Odometry,
    PlannerEvent,
    PlannerState,
    Track,
    TrackList,
    VelocityCommand,
)
from zenav.services.baselines.apf import APF
from zenav.services.baselines.common import Cycle, Obstacles, goal_reached
from zenav.services.baselines.dwa import DWA
from zenav.services.baselines.orca import ORCA
from zenav.services.baselines.params import APFParams, DWAParams, ORCAParams, VFHParams
from zenav.services.baselines.vfh import VFH
from zenav.services.node import Node, StampGate, StampJoin
from zenav.services.planner.params import MissionParams

KEPT = 8
"""Scans and odometry messages kept by stamp."""

STANDING = 0.005
"""Commanded speeds below this, m/s, count as a stop."""


class Command(Protocol):
    @property
    def v(self) -> float: ...

    @property
    def omega(self) -> float: ...


class Policy(Protocol):
    def step(self, cycle: Cycle) -> Command: ...


def _obstacles(tracks: list[Track]) -> Obstacles:
    return Obstacles(
        positions=np.array([[t.x, t.y] for t in tracks], dtype=np.float64).reshape(-1, 2),
        velocities=np.array([[t.vx, t.vy] for t in tracks], dtype=np.float64).reshape(-1, 2),
        radii=np.array([t.radius for t in tracks], dtype=np.float64),
    )


def movers_of(tracks: TrackList, moving_speed: float) -> tuple[Obstacles, Obstacles]:
    """The tracks that move, and the standing ones out of view (remembered)."""
    moving = [t for t in tracks.tracks if t.kind == "dynamic" and t.speed >= moving_speed]
    standing = [t for t in tracks.tracks if not t.visible and t not in moving]
    return _obstacles(moving), _obstacles(standing)


def latest_at(kept: dict[float, LaserScan] | dict[float, Odometry], stamp: float) -> float | None:
    """The stamp of the kept message for ``stamp``: the same, else the newest before it."""
    if stamp in kept:
        return stamp
    earlier = [s for s in kept if s <= stamp]
    return max(earlier) if earlier else None


class BaselineService:
    def __init__(self, node: Node, params: MissionParams, policy: Policy) -> None:
        self.node = node
        self.params = params
        self.policy = policy
        self.commands = node.publisher(keys.CMD_VEL, VelocityCommand, urgent=True)
        self.events = node.publisher(keys.EVENTS, PlannerEvent, reliable=True)
        self.state = node.publisher(keys.PLANNER_STATE, PlannerState)
        self.gate = StampGate(node, keys.TRACKS)
        # A track list and the scan of its stamp, joined (the latest few scans kept).
        self.join = StampJoin[TrackList, LaserScan](self.decide, params.scan_wait, KEPT)
        self.odometry: dict[float, Odometry] = {}
        self.last_action: Action | None = None
        self.last_command = (0.0, 0.0)
        node.subscribe(keys.SCAN, LaserScan, self.on_scan, depth=4)
        node.subscribe(keys.ODOM, Odometry, self.on_odometry, depth=8)
        node.subscribe(keys.TRACKS, TrackList, self.on_tracks, depth=2)

    def on_scan(self, scan: LaserScan) -> None:
        self.join.companion(scan)

    def on_odometry(self, odometry: Odometry) -> None:
        self.odometry[odometry.stamp] = odometry
        while len(self.odometry) > KEPT:
            del self.odometry[min(self.odometry)]

    def cycle(self, tracks: TrackList, scan: LaserScan) -> Cycle:
        p = self.params
        at = latest_at(self.odometry, tracks.stamp)
        velocity = self.last_command
        if at is not None:
            velocity = (self.odometry[at].v, self.odometry[at].omega)
        pose = tracks.pose
        movers, remembered = movers_of(tracks, p.moving_speed)
        return Cycle(ranges=scan.ranges.astype(np.float64), angles=scan.angles(),
                     range_max=scan.range_max, pose=(pose.x, pose.y, pose.heading),
                     velocity=velocity, goal=p.goal,
                     movers=movers, remembered=remembered, tracked=_obstacles(tracks.tracks))

    def on_tracks(self, tracks: TrackList) -> None:
        if not self.gate.admit(tracks.stamp, self.commands):
            return
        self.join.arrive(tracks)

    def decide(self, tracks: TrackList, scan: LaserScan | None) -> None:
        """The command for ``tracks``, on the scan of its stamp or else the newest before."""
        if scan is None:  # not come in time: the newest before it
            at = latest_at(self.join.companions, tracks.stamp)
            scan = None if at is None else self.join.companions[at]
        v = omega = 0.0
        action: Action = "stop"
        detail = "no scan yet"
        if scan is not None:
            cycle = self.cycle(tracks, scan)
            if goal_reached(cycle, self.params.goal_tolerance):
                action, detail = "goal", "at the goal"
            else:
                decision = self.policy.step(cycle)
                v, omega = decision.v, decision.omega
                action = "keep" if v >= STANDING else "stop"
                detail = f"v {v:.2f} m/s, omega {omega:.2f} rad/s"
        self.last_command = (v, omega)
        if action != self.last_action:
            self.last_action = action
            self.events.publish(PlannerEvent(
                stamp=tracks.stamp, seq=self.events.next_seq(), scenario="a", action=action,
                detail=detail))
        self.commands.publish(VelocityCommand(stamp=tracks.stamp, seq=self.commands.next_seq(),
                                              v=v, omega=omega))
        self.state.publish(PlannerState(
            stamp=tracks.stamp, seq=self.state.next_seq(), scenario="a", action=action,
            target=self.params.goal, speed=max(v, 0.0)))


class VFHService(BaselineService):
    def __init__(self, node: Node, params: VFHParams) -> None:
        super().__init__(node, params, VFH(params))


class DWAService(BaselineService):
    def __init__(self, node: Node, params: DWAParams) -> None:
        super().__init__(node, params, DWA(params))


class APFService(BaselineService):
    def __init__(self, node: Node, params: APFParams) -> None:
        super().__init__(node, params, APF(params))


class ORCAService(BaselineService):
    def __init__(self, node: Node, params: ORCAParams) -> None:
        super().__init__(node, params, ORCA(params))
