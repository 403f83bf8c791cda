"""``zenav bench perf``, latency: a real stack over Zenoh in real time; a tool process
takes the wall time (in Zenoh's callback, one clock) at which it receives the scan stamped
*s* (the laser driver's publish) and the base command stamped *s* (the motor bridge's
publish right after it received the velocity command): the interval is the laser
driver's publish to the motor bridge's publish, both seen one hop away. The same tool
hears every message in between (obstacle chain, track list, velocity command), so the
interval splits into one row per service: from its input's publish to its output's
publish, i.e. one hop plus that service's receive, decode, compute, encode and put. The
memory benchmark measures the same run."""

from __future__ import annotations

import math
import statistics
import time
from dataclasses import dataclass, field
from pathlib import Path

from zenav.bench.common import fmt, percentile, verdict
from zenav.bench.live import live_stack
from zenav.bench.memory import service_memory
from zenav.sim import SCENARIO_DIR

TARGET_LATENCY_MEDIAN_MS = 2.0
TARGET_LATENCY_P99_MS = 5.0


STAGES = ("laser_driver", "perception", "tracking", "planner", "motor_bridge")
"""The services along the scan's path, each answering the topic the one before it
publishes (the laser driver answers the simulator's raw frame)."""


@dataclass
class LatencyResult:
    samples: int
    scan_to_base_ms: list[float]
    scan_to_cmd_ms: list[float]
    rss_mb: dict[str, float]
    stages_ms: dict[str, list[float]] = field(default_factory=dict)
    """Per service of :data:`STAGES`: its input's publish to its output's publish, ms,
    for the scans that got their base command."""


def stage_intervals(path: list[dict[float, float]]) -> dict[str, list[float]]:
    """From the receive times by stamp of each topic of the path (raw frame, scan,
    obstacles, tracks, velocity command, base command), each service's interval in ms,
    over the stamps that reached the base command."""
    answered = [s for s in path[0] if s in path[-1]]
    return {name: [(after[s] - before[s]) * 1e3 for s in answered
                   if s in before and s in after]
            for name, before, after in zip(STAGES, path[:-1], path[1:], strict=True)}


def measure_latency(seconds: float, work: Path,
                    scenario: Path = SCENARIO_DIR / "h-mixed.yaml") -> LatencyResult:
    with live_stack(scenario, work / "latency", {}, hops=True) as (stack, listener):
        time.sleep(1.0)  # let the links settle
        listener.clear()
        time.sleep(seconds)
        rss = service_memory(stack)
        listener.settle()
        with listener.lock:
            path = [dict(into) for _, into in listener.path()]
    _, scans, _, _, commands, base = path
    to_base = [(base[s] - t) * 1e3 for s, t in scans.items() if s in base]
    to_cmd = [(commands[s] - t) * 1e3 for s, t in scans.items() if s in commands]
    return LatencyResult(len(to_base), to_base, to_cmd, rss, stage_intervals(path))


def latency_table(r: LatencyResult) -> str:
    med = statistics.median(r.scan_to_base_ms) if r.scan_to_base_ms else math.nan
    p99 = percentile(r.scan_to_base_ms, 99)
    cmd_med = statistics.median(r.scan_to_cmd_ms) if r.scan_to_cmd_ms else math.nan
    lines = [
        "| interval (wall clock, one receiving process) | samples | median ms | p99 ms | "
        "max ms | target |",
        "|---|---|---|---|---|---|",
        f"| scan → base command (laser driver's publish → motor bridge's publish) | "
        f"{r.samples} | {fmt(med, 2)} | {fmt(p99, 2)} | "
        f"{fmt(max(r.scan_to_base_ms) if r.scan_to_base_ms else math.nan, 2)} | median ≤ "
        f"{TARGET_LATENCY_MEDIAN_MS:g} ms ({verdict(med <= TARGET_LATENCY_MEDIAN_MS)}), "
        f"p99 ≤ {TARGET_LATENCY_P99_MS:g} ms ({verdict(p99 <= TARGET_LATENCY_P99_MS)}) |",
        f"| scan → velocity command (… → planner's publish) | {len(r.scan_to_cmd_ms)} | "
        f"{fmt(cmd_med, 2)} | {fmt(percentile(r.scan_to_cmd_ms, 99), 2)} | "
        f"{fmt(max(r.scan_to_cmd_ms) if r.scan_to_cmd_ms else math.nan, 2)} | |",
    ]
    if r.stages_ms:
        lines += ["", "Hop by hop: each service's input publish → its output publish (one hop "
                  "plus receive, decode, compute, encode, put); the laser driver's row is "
                  "before the interval above.", "",
                  "| service (input → output) | samples | median ms | p99 ms | max ms |",
                  "|---|---|---|---|---|"]
        names = dict(zip(STAGES, ("raw frame → scan", "scan → obstacle chain",
                                  "obstacle chain → track list", "track list → velocity command",
                                  "velocity command → base command"), strict=True))
        for name, values in r.stages_ms.items():
            lines.append(f"| {name} ({names[name]}) | {len(values)} | "
                         f"{fmt(statistics.median(values) if values else math.nan, 2)} | "
                         f"{fmt(percentile(values, 99), 2)} | "
                         f"{fmt(max(values) if values else math.nan, 2)} |")
    return "\n".join(lines)
