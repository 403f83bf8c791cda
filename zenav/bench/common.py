"""What the benchmarks share: the figures' formatting, the machine's description, the
services' memory."""

from __future__ import annotations

import contextlib
import math
from pathlib import Path

import numpy as np
import psutil


def words(text: str) -> list[str]:
    """The comma-separated words of an option."""
    return [w.strip() for w in text.split(",") if w.strip()]


def percentile(values: list[float], q: float) -> float:
    return float(np.percentile(np.asarray(values, dtype=np.float64), q)) if values else math.nan


def verdict(ok: bool) -> str:
    return "met" if ok else "NOT met"


def fmt(value: float, digits: int = 0) -> str:
    return "—" if math.isnan(value) else f"{value:.{digits}f}"


def cpu_model() -> str:
    """The CPU's model name (from /proc/cpuinfo)."""
    with contextlib.suppress(OSError):
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    return "unknown CPU"


def machine() -> str:
    """Cores, CPU and memory, for a report's heading."""
    return (f"{psutil.cpu_count()} cores, {cpu_model()}, "
            f"{psutil.virtual_memory().total / 2**30:.0f} GiB")


def rss_mb(pids: dict[str, int]) -> dict[str, float]:
    """Resident memory of each process still running, MiB."""
    out = {}
    for name, pid in pids.items():
        with contextlib.suppress(psutil.Error):
            out[name] = psutil.Process(pid).memory_info().rss / 2**20
    return out
