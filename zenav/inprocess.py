"""The pipeline's cores called directly, without the bus: for timing them.

:class:`Pipeline` holds the pure cores the services call (laser driver -> perception ->
tracking -> planner), set up with the same parameters as ``zenav run``,
and runs them on one scan at a time; ``zenav bench perf`` (its compute section) times it
stage by stage with a :class:`StageClock`. It runs no scenario: a whole run in one
process is the in-process engine's (:mod:`zenav.engine`, ``zenav run --engine
inprocess``), which runs the services themselves.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

from typing_extensions import override

from zenav.schemas.messages import LaserScan, Pose2D, RawLaserFrame, Track, TrackList
from zenav.services.laser_driver.params import Params as DriverParams
from zenav.services.laser_driver.scan import frame_to_scan
from zenav.services.perception.clustering import Clusters
from zenav.services.perception.params import PerceptionParams
from zenav.services.perception.perceive import Perceiver
from zenav.services.planner import safety
from zenav.services.planner.decide import Decision, Detour, Planner
from zenav.services.planner.node import obstacles_of, scan_data
from zenav.services.planner.params import Params as PlannerParams
from zenav.services.planner.prediction import Assessment, Obstacle
from zenav.services.tracking.node import nearest_tracks, track_messages
from zenav.services.tracking.params import TrackingParams
from zenav.services.tracking.tracker import Tracker

Pose = tuple[float, float, float]


class StageClock:
    """Time spent per stage label, added up until :meth:`reset`: wall time by default,
    or the thread's CPU time (``clock=time.thread_time``: what the stage costs, without
    the time other processes hold the core on a shared machine)."""

    def __init__(self, clock: Callable[[], float] = time.perf_counter) -> None:
        self.now = clock
        self.spent: dict[str, float] = {}
        self.calls: dict[str, int] = {}

    @contextmanager
    def stage(self, label: str) -> Iterator[None]:
        start = self.now()
        try:
            yield
        finally:
            self.spent[label] = self.spent.get(label, 0.0) + self.now() - start
            self.calls[label] = self.calls.get(label, 0) + 1

    def reset(self) -> None:
        self.spent.clear()
        self.calls.clear()


class TimedPlanner(Planner):
    """The paper's planner with its collision prediction (``prediction``: assessing the
    obstacles and choosing a safe speed) and Morphin (``morphin``: planning a detour)
    timed on a clock. It decides exactly as :class:`Planner` does."""

    def __init__(self, params: PlannerParams, clock: StageClock) -> None:
        super().__init__(params)
        self.clock = clock

    @override
    def _assess_all(self, *args: Any, **kwargs: Any) -> list[Assessment]:
        with self.clock.stage("prediction"):
            return super()._assess_all(*args, **kwargs)

    @override
    def speed_and_safety(self, *args: Any, **kwargs: Any) -> safety.Choice:
        with self.clock.stage("prediction"):
            return super().speed_and_safety(*args, **kwargs)

    @override
    def plan_detour(self, *args: Any, **kwargs: Any) -> Detour | None:
        with self.clock.stage("morphin"):
            return super().plan_detour(*args, **kwargs)


@dataclass
class Step:
    """What each stage made of one scan."""

    t: float
    scan: LaserScan
    clusters: Clusters
    tracks: list[Track]
    track_list: TrackList
    obstacles: list[Obstacle]
    decision: Decision


class Pipeline:
    """Laser driver, perception, tracking and planner as the services set them up from
    ``params`` (per service, as :func:`stack_params` gives them); each stage of
    :meth:`step` is timed on ``clock``, and with ``time_planner_parts`` the planner's
    prediction and Morphin too."""

    def __init__(self, params: dict[str, dict[str, Any]], clock: StageClock | None = None,
                 *, time_planner_parts: bool = False) -> None:
        self.clock = clock or StageClock()
        self.driver = DriverParams.model_validate(params["laser_driver"])
        self.perceiver = Perceiver(PerceptionParams.model_validate(params["perception"]))
        self.tracker = Tracker(TrackingParams.model_validate(params["tracking"]))
        self.planner_params = PlannerParams.model_validate(params["planner"])
        self.planner = (TimedPlanner(self.planner_params, self.clock) if time_planner_parts
                        else Planner(self.planner_params))

    def step(self, t: float, seq: int, ranges: Any, pose: Pose) -> Step:
        """One scan (the simulator's ranges at ``t``, the robot at ``pose``) through the
        laser driver, perception, tracking and the planner."""
        scan = frame_to_scan(RawLaserFrame(stamp=t, seq=seq, ranges=ranges), self.driver, seq)
        with self.clock.stage("perception"):
            clusters = self.perceiver.process(scan, pose)
        with self.clock.stage("tracking"):
            tracks = track_messages(nearest_tracks(self.tracker.update(t, pose, clusters),
                                                   pose[0], pose[1]))
        track_list = TrackList(stamp=t, seq=seq, pose=Pose2D(x=pose[0], y=pose[1],
                                                             heading=pose[2]), tracks=tracks)
        obstacles = obstacles_of(track_list)
        with self.clock.stage("planner"):
            decision = self.planner.step(pose, obstacles, t, scan_data(scan, pose))
        return Step(t, scan, clusters, tracks, track_list, obstacles, decision)
