"""``zenav bench perf``, memory: the resident set size of each service process (psutil),
taken during the latency run."""

from __future__ import annotations

from typing import TYPE_CHECKING

from zenav.bench.common import rss_mb
from zenav.launch import Stack

if TYPE_CHECKING:
    from zenav.bench.latency import LatencyResult


def service_memory(stack: Stack) -> dict[str, float]:
    """Resident memory of each service process still running, MiB."""
    return rss_mb({name: proc.pid for name, proc in stack.processes.items()
                   if proc.poll() is None})


def memory_table(r: LatencyResult) -> str:
    lines = ["| service | resident memory, MiB |", "|---|---|"]
    lines += [f"| {name} | {mb:.0f} |" for name, mb in r.rss_mb.items()]
    lines.append(f"| total | {sum(r.rss_mb.values()):.0f} |")
    return "\n".join(lines)
