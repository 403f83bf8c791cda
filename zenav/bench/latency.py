"""``zenav bench perf``, latency: a real stack over Zenoh in real time; a tool process
takes the wall time (in Zenoh's callback, one clock) at which it receives the scan stamped
*s* (the laser driver's publish) and the base command stamped *s* (the motor bridge's
publish right after it received the velocity command): the interval is the laser
driver's publish to the motor bridge's publish, both seen one hop away. The memory
benchmark measures the same run."""

from __future__ import annotations

import math
import statistics
import time
from dataclasses import dataclass
from pathlib import Path

from zenav.bench.common import fmt, percentile, verdict
from zenav.bench.live import live_stack
from zenav.bench.memory import service_memory
from zenav.sim import SCENARIO_DIR

TARGET_LATENCY_MEDIAN_MS = 2.0
TARGET_LATENCY_P99_MS = 5.0


@dataclass
class LatencyResult:
    samples: int
    scan_to_base_ms: list[float]
    scan_to_cmd_ms: list[float]
    rss_mb: dict[str, float]


def measure_latency(seconds: float, work: Path,
                    scenario: Path = SCENARIO_DIR / "h-mixed.yaml") -> LatencyResult:
    with live_stack(scenario, work / "latency", {}) as (stack, listener):
        time.sleep(1.0)  # let the links settle
        with listener.lock:
            listener.scans.clear()
            listener.commands.clear()
            listener.base.clear()
        time.sleep(seconds)
        rss = service_memory(stack)
        with listener.lock:
            scans, commands, base = dict(listener.scans), dict(listener.commands), dict(
                listener.base)
    to_base = [(base[s] - t) * 1e3 for s, t in scans.items() if s in base]
    to_cmd = [(commands[s] - t) * 1e3 for s, t in scans.items() if s in commands]
    return LatencyResult(len(to_base), to_base, to_cmd, rss)


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
    return "\n".join(lines)
