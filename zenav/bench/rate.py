"""``zenav bench perf``, rate: the real-time simulator with the laser rate raised; the
highest rate at which no service drops an input (the ``status/<service>`` counters) and
every scan gets its base command."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from zenav.bench.common import fmt, percentile, verdict
from zenav.bench.live import live_stack
from zenav.sim import SCENARIO_DIR
from zenav.sim.scenario import MAX_TICKS

TARGET_RATE_HZ = 200.0


@dataclass
class RateRow:
    rate_hz: float
    scans_hz: float  # scans seen per wall second
    answered: float  # share of scans with their base command
    drops: dict[str, int]
    latency_p99_ms: float

    @property
    def keeps_up(self) -> bool:
        return (not any(self.drops.values()) and self.answered >= 0.99
                and self.scans_hz >= 0.95 * self.rate_hz)


SETTLE_S = 2.0
"""s: the stack runs this long before the measurement (links settled, first status in)."""
SPARE_S = 20.0
"""s of simulated time beyond the measured ones: start-up, the last status period."""


def longest_run(rate: float) -> float:
    """The longest a run at ``rate`` Hz may last within the simulator's tick limit, s."""
    return MAX_TICKS / max(rate, 10.0)


def highest_rate(seconds: float) -> float:
    """The highest laser rate whose run still covers ``seconds`` measured, Hz."""
    return MAX_TICKS / (SETTLE_S + seconds + SPARE_S)


def rate_scenario(rate: float, scenario: Path = SCENARIO_DIR / "h-mixed.yaml"
                  ) -> dict[str, Any]:
    """``scenario`` with its laser at ``rate`` Hz, lasting as long as the tick limit
    allows (up to an hour; the run is stopped once measured). For rates up to
    ``highest_rate`` that covers the measurement."""
    data: dict[str, Any] = yaml.safe_load(scenario.read_text())
    data.setdefault("laser", {})["rate_hz"] = rate
    data["duration"] = math.floor(min(3600.0, longest_run(rate)))
    return data


def measure_rate(rate: float, seconds: float, work: Path,
                 scenario: Path = SCENARIO_DIR / "h-mixed.yaml") -> RateRow:
    data = rate_scenario(rate, scenario)
    copy = work / f"rate-{rate:g}.yaml"
    copy.parent.mkdir(parents=True, exist_ok=True)
    copy.write_text(yaml.safe_dump(data))
    with live_stack(copy, work / f"rate-{rate:g}", {}) as (_, listener):
        time.sleep(SETTLE_S)  # links settled, first status messages in
        before = listener.drops()
        listener.clear()
        started = time.perf_counter()
        time.sleep(seconds)
        elapsed = time.perf_counter() - started
        listener.settle()
        with listener.lock:
            scans, base = dict(listener.scans), dict(listener.base)
        time.sleep(1.2)  # one more status period
        after = listener.drops()
    # Scans in the last 0.2 s may still be on their way through the stack.
    horizon = max(scans.values(), default=0.0) - 0.2
    counted = [s for s, t in scans.items() if t <= horizon]
    answered = sum(1 for s in counted if s in base) / max(len(counted), 1)
    latency = [(base[s] - scans[s]) * 1e3 for s in counted if s in base]
    drops = {name: after.get(name, 0) - before.get(name, 0) for name in after}
    return RateRow(rate, len(scans) / elapsed, answered, drops, percentile(latency, 99))


def rate_table(rows: list[RateRow]) -> str:
    lines = ["| laser rate Hz | scans seen per s | scans answered | inputs dropped (service: n) "
             "| scan→base p99 ms | keeps up |", "|---|---|---|---|---|---|"]
    for r in rows:
        drops = ", ".join(f"{k}: {v}" for k, v in sorted(r.drops.items()) if v) or "none"
        lines.append(f"| {r.rate_hz:g} | {r.scans_hz:.1f} | {100 * r.answered:.1f} % | {drops} "
                     f"| {fmt(r.latency_p99_ms, 1)} | {'yes' if r.keeps_up else 'no'} |")
    best = max((r.rate_hz for r in rows if r.keeps_up), default=math.nan)
    lines.append("")
    lines.append(f"Target: ≥ {TARGET_RATE_HZ:g} Hz — highest rate tried with no drop and every "
                 f"scan answered: {fmt(best)} Hz ({verdict(best >= TARGET_RATE_HZ)}).")
    return "\n".join(lines)
