"""The baseline planners as the ``planner`` service (``zenav run --planner
vfh|dwa|apf|orca``, ``zenav service planner --planner ...``): the same inputs and outputs
as the paper's planner. Algorithms: ``vfh.py``, ``dwa.py``, ``apf.py``, ``orca.py``;
parameters: ``params.py``.

It answers each track list with one velocity command stamped with the tracks' stamp
(lockstep depends on it) and answers a repeated stamp by repeating its command. A
baseline decides on the tracks, the scan of their stamp and the robot's velocity from
the odometry of that instant (the newest at or before the stamp), the :class:`Instant`.
An instant is complete once its scan is in and an odometry message at or after its
stamp has come (so no later one can change which is the newest before it): in lockstep
that is the odometry of the same tick; on a robot, the next odometry message. As in the
paper planner's service (both join with :class:`~zenav.services.node.StampJoin`), a
decision waits for the tracks and their instant, whichever comes first, so that a
loaded machine does not change the result: a track list whose instant is not complete
within ``scan_wait`` wall seconds (or that a newer track list overtakes) is decided on
the scan of its stamp, else the newest before it, with the newest odometry at or before
that scan. Tracks give the robot pose
at scan time and the movers. The planner state says ``a`` (no paper scenario) and the
action: ``keep`` when moving, ``stop`` when standing, ``goal`` at the goal; an event is
published when the action changes.
"""

from __future__ import annotations

from dataclasses import dataclass
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
from zenav.services.node import Node, StampGate, StampJoin, latest_at
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


@dataclass(frozen=True)
class Instant:
    """The scan of a stamp and the odometry of that instant (None: none yet)."""

    stamp: float
    scan: LaserScan
    odometry: Odometry | None


class BaselineService:
    def __init__(self, node: Node, params: MissionParams, policy: Policy) -> None:
        self.node = node
        self.params = params
        self.policy = policy
        self.commands = node.publisher(keys.CMD_VEL, VelocityCommand, urgent=True)
        self.events = node.publisher(keys.EVENTS, PlannerEvent, reliable=True)
        self.state = node.publisher(keys.PLANNER_STATE, PlannerState)
        self.gate = StampGate(node, keys.TRACKS)
        # A track list and the instant of its stamp, joined (the latest few kept).
        self.join = StampJoin[TrackList, Instant](self.decide, params.scan_wait, KEPT)
        self.scans: dict[float, LaserScan] = {}
        """Scans whose instant is not complete yet: no odometry at or after them so far."""
        self.odometry: dict[float, Odometry] = {}
        self.last_action: Action | None = None
        self.last_command = (0.0, 0.0)
        node.subscribe(keys.SCAN, LaserScan, self.on_scan, depth=4)
        node.subscribe(keys.ODOM, Odometry, self.on_odometry, depth=8)
        node.subscribe(keys.TRACKS, TrackList, self.on_tracks, depth=2)

    def on_scan(self, scan: LaserScan) -> None:
        self.scans[scan.stamp] = scan
        while len(self.scans) > KEPT:
            del self.scans[min(self.scans)]
        self._complete()

    def on_odometry(self, odometry: Odometry) -> None:
        self.odometry[odometry.stamp] = odometry
        while len(self.odometry) > KEPT:
            del self.odometry[min(self.odometry)]
        self._complete()

    def _complete(self) -> None:
        """Hand the join every instant now complete: its scan in, and an odometry message
        at or after its stamp."""
        newest = max(self.odometry, default=None)
        if newest is None:
            return
        for stamp in sorted(s for s in self.scans if s <= newest):
            self.join.companion(self._instant(stamp, self.scans.pop(stamp)))

    def _instant(self, stamp: float, scan: LaserScan) -> Instant:
        at = latest_at(self.odometry, stamp)
        return Instant(stamp, scan, None if at is None else self.odometry[at])

    def _fallback(self, stamp: float) -> Instant | None:
        """A track list decided without its complete instant: the scan of its stamp, else
        the newest before it, complete or not, with the newest odometry at or before it."""
        scans = {s: i.scan for s, i in self.join.companions.items()} | self.scans
        at = latest_at(scans, stamp)
        return None if at is None else self._instant(at, scans[at])

    def cycle(self, tracks: TrackList, instant: Instant) -> Cycle:
        p = self.params
        scan, odometry = instant.scan, instant.odometry
        velocity = self.last_command if odometry is None else (odometry.v, odometry.omega)
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

    def decide(self, tracks: TrackList, instant: Instant | None) -> None:
        """The command for ``tracks``, on the instant of its stamp, else what is in."""
        if instant is None:  # not complete in time
            instant = self._fallback(tracks.stamp)
        v = omega = 0.0
        action: Action = "stop"
        detail = "no scan yet"
        if instant is not None:
            cycle = self.cycle(tracks, instant)
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
