"""``zenav soak``, reduced for CI: 20 s of the real-time stack at 100 Hz scans.

The documented run is ``zenav soak --minutes 30 --rate-hz 100``."""

from __future__ import annotations

from pathlib import Path

import pytest

from zenav.bench.soak import run_soak, summary

pytestmark = pytest.mark.integration


def test_soak_reports_memory_drops_and_latency(tmp_path: Path) -> None:
    report = run_soak(tmp_path, minutes=20 / 60, rate_hz=100.0, warmup=6.0, window=6.0,
                      progress=False)
    print(summary(report))
    services = {"simulator", "laser_driver", "perception", "tracking", "planner",
                "motor_bridge"}
    assert set(report["rss_mb"]) == services  # every service alive to the end
    assert all(code == 0 for code in report["exit_codes"].values()), report["exit_codes"]
    for name, rss in report["rss_mb"].items():
        assert 10 < rss["start"] < 1000, (name, rss)
        assert rss["growth_pct"] < 10, (name, rss)  # 5 % is the bar over 30 minutes
    stages = report["stages"]
    assert set(stages) == services
    scans = sum(stages["laser_driver"]["received"].values())
    assert scans > 20 * 30, scans  # well above the paper's 10 Hz
    assert sum(stages["planner"]["received"].values()) > 0.5 * scans
    for when in ("start", "end"):
        latency = report["latency_s"][when]
        assert latency["n"] > 100, report["latency_s"]
        assert latency["p50"] < 0.05, report["latency_s"]
    assert (tmp_path / "soak.json").is_file()
