"""The benchmarks run end to end on a reduced set (the CI smoke test): a few worlds with
one planner through zenav run, and the compute section of bench perf."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

pytestmark = pytest.mark.integration


def zenav(*args: str, timeout: float = 600) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "zenav", *args], capture_output=True,
                          text=True, timeout=timeout, check=False)


def test_bench_nav_on_two_worlds_with_one_planner(tmp_path):
    done = zenav("bench", "nav", "--planners", "vfh", "--worlds", "1", "--seed", "3",
                 "--families", "static,crossing", "--jobs", "2", "--no-progress",
                 "--out", str(tmp_path))
    assert done.returncode == 0, done.stderr
    records = json.loads((tmp_path / "nav.json").read_text())
    assert sorted(r["scenario"] for r in records) == ["crossing-3", "static-3"]
    assert all(r["outcome"] in ("reached", "collision", "timeout") for r in records)
    table = (tmp_path / "nav.md").read_text()
    assert "| vfh | 2 |" in table and "| static |" in table and "| crossing |" in table
    assert (tmp_path / "nav.png").stat().st_size > 10_000
    assert sorted(p.name for p in (tmp_path / "worlds").iterdir()) == [
        "crossing-3.yaml", "static-3.yaml"]


def test_bench_perf_compute_section(tmp_path):
    done = zenav("bench", "perf", "--sections", "compute", "--scans", "20",
                 "--obstacles", "0,5", "--out", str(tmp_path))
    assert done.returncode == 0, done.stderr
    report = (tmp_path / "perf.md").read_text()
    for row in ("clustering (perception)", "tracking", "collision prediction", "Morphin",
                "**whole pipeline**", "VFH step", "DWA step", "APF step"):
        assert f"| {row}" in report
    assert "Target: whole pipeline ≤ 500 µs median with 5 obstacles — measured" in report


def test_bench_refuses_an_unknown_planner(tmp_path):
    done = zenav("bench", "nav", "--planners", "nope", "--out", str(tmp_path))
    assert done.returncode == 2
    assert "unknown planner nope" in done.stderr


def test_bench_perf_floor_section(tmp_path):
    done = zenav("bench", "perf", "--sections", "floor", "--floor-seconds", "2",
                 "--out", str(tmp_path), timeout=120)
    assert done.returncode == 0, done.stderr
    report = (tmp_path / "perf.md").read_text()
    chain = next(line for line in report.splitlines() if "the scan's four hops" in line)
    assert "20 scans |" in chain  # 2 s at 10 Hz, every one through the four relays
    median = float(chain.split("|")[2].split()[0])
    assert 0.0 < median < 100.0
    direct = next(line for line in report.splitlines() if "Zenoh's callback" in line)
    assert "10 scans |" in direct  # 1 s at 10 Hz without the loop
    ring = next(line for line in report.splitlines() if "the lockstep tick's six hops" in line)
    assert int(ring.split(",")[2].split()[0]) > 0  # ticks counted round the ring
