"""bench crowd end to end on a tiny set: two CrowdNav cases, one planner, through the stack.
The runs' records carry the agents' paths at the trajectory's ticks."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

pytestmark = pytest.mark.integration


def test_bench_crowd_on_two_cases_with_one_planner(tmp_path):
    done = subprocess.run(
        [sys.executable, "-m", "zenav", "bench", "crowd", "--cases", "2", "--planners", "orca",
         "--settings", "circle-invisible-360", "--jobs", "2", "--no-progress", "--engine", "stack",
         "--out", str(tmp_path)], capture_output=True, text=True, timeout=600, check=False)
    assert done.returncode == 0, done.stderr
    report = (tmp_path / "crowd.md").read_text()
    assert "## circle crossing, invisible humans, laser 360°" in report
    assert "| orca | 2 |" in report
    assert (tmp_path / "crowd.png").stat().st_size > 10_000
    summary = json.loads((tmp_path / "crowd.json").read_text())
    runs = summary["runs"]["circle-invisible-360"]
    assert sorted(r["scenario"] for r in runs) == ["circle-crossing-invisible-360-0",
                                                   "circle-crossing-invisible-360-1"]
    for case in (0, 1):
        record = json.loads((tmp_path / "runs" / "circle-invisible-360" / "orca" / str(case)
                             / "run.json").read_text())
        assert record["outcome"] in ("reached", "collision", "timeout")
        assert sorted(record["agents"]) == ["0", "1", "2", "3", "4"]
        ticks = [row[0] for row in record["trajectory"]]
        assert all([row[0] for row in rows] == ticks for rows in record["agents"].values())
