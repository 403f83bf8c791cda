"""The whole pipeline in one process, without the bus: for debugging and benchmarks.

It calls the same pure cores the services call, in the same order and with the same
parameters as ``zenav run`` (simulator -> laser driver -> perception -> tracking ->
planner -> motor bridge), so a lockstep run here follows the same trajectory as one
through the processes. The acceptance path is still ``zenav run``: this module skips
the transport, the codec and the processes.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from zenav.run import apply_override, stack_params
from zenav.schemas.messages import Pose2D, RawLaserFrame, Track, TrackList
from zenav.services.laser_driver.node import Params as DriverParams
from zenav.services.laser_driver.node import frame_to_scan
from zenav.services.motor_bridge.node import CommandFilter
from zenav.services.motor_bridge.node import Params as BridgeParams
from zenav.services.perception.clustering import Clusters
from zenav.services.perception.params import PerceptionParams
from zenav.services.perception.perceive import Perceiver
from zenav.services.planner.decide import Decision, Planner
from zenav.services.planner.node import EventLog, EventRow, obstacles_of
from zenav.services.planner.params import Params as PlannerParams
from zenav.services.tracking.node import track_message
from zenav.services.tracking.params import TrackingParams
from zenav.services.tracking.tracker import Tracker
from zenav.sim.node import Params as SimParams
from zenav.sim.node import Simulation
from zenav.sim.scenario import load_scenario

StageTimes = dict[str, list[float]]


@dataclass
class Cycle:
    """What each stage produced for one scan."""

    t: float
    clusters: Clusters
    tracks: list[Track]
    decision: Decision
    events: list[EventRow]


@dataclass
class InProcessRun:
    simulation: Simulation
    cycles: list[Cycle] = field(default_factory=list)
    stage_seconds: StageTimes = field(default_factory=dict)
    zone_stops: int = 0


def run_inprocess(
    scenario_path: Path,
    overrides: list[str] | None = None,
    on_cycle: Callable[[Cycle], None] | None = None,
) -> InProcessRun:
    scenario = load_scenario(scenario_path)
    params: dict[str, dict[str, Any]] = stack_params(scenario, scenario_path, "paper")
    for text in overrides or []:
        apply_override(params, text)
    sim = Simulation(scenario, SimParams.model_validate(params["simulator"]))
    driver = DriverParams.model_validate(params["laser_driver"])
    perceiver = Perceiver(PerceptionParams.model_validate(params["perception"]))
    tracker = Tracker(TrackingParams.model_validate(params["tracking"]))
    planner = Planner(PlannerParams.model_validate(params["planner"]))
    bridge = CommandFilter(BridgeParams.model_validate(params["motor_bridge"]))
    log = EventLog(planner.p.horizon)
    run = InProcessRun(sim)
    times: StageTimes = {k: [] for k in ("perception", "tracking", "planner")}
    run.stage_seconds = times
    v = omega = 0.0
    seq = 0
    while sim.outcome is None:
        if sim.scan_due():
            t = sim.t
            frame = RawLaserFrame(stamp=t, seq=seq, ranges=sim.scan())
            scan = frame_to_scan(frame, driver, seq)
            seq += 1
            s = sim.state
            pose = (s.x, s.y, s.heading)
            t0 = time.perf_counter()
            clusters = perceiver.process(scan, pose)
            t1 = time.perf_counter()
            tracks = [track_message(tr) for tr in tracker.update(t, pose, clusters)]
            t2 = time.perf_counter()
            track_list = TrackList(stamp=t, seq=seq, pose=Pose2D(x=pose[0], y=pose[1],
                                                                 heading=pose[2]), tracks=tracks)
            decision = planner.step(pose, obstacles_of(track_list), t)
            t3 = time.perf_counter()
            times["perception"].append(t1 - t0)
            times["tracking"].append(t2 - t1)
            times["planner"].append(t3 - t2)
            v, omega, reason = bridge.apply(t, decision.v, decision.omega, scan)
            run.zone_stops += reason == "stop_zone"
            cycle = Cycle(t, clusters, tracks, decision, log.events(decision))
            run.cycles.append(cycle)
            if on_cycle is not None:
                on_cycle(cycle)
        sim.step(v, omega)
    return run
