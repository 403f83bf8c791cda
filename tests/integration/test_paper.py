"""zenav paper on a reduced set: the report's figures come from the run records."""

from __future__ import annotations

import itertools
import json
import math
import subprocess
import sys

import pytest

pytestmark = pytest.mark.integration


def test_quick_report_numbers_equal_what_the_run_record_gives(tmp_path):
    done = subprocess.run([sys.executable, "-m", "zenav", "paper", "--quick", "--out",
                           str(tmp_path)], capture_output=True, text=True, timeout=300,
                          check=False)
    assert done.returncode == 0, done.stderr
    report = (tmp_path / "report.md").read_text()
    record = json.loads((tmp_path / "runs" / "a-seed1" / "run.json").read_text())
    assert record["outcome"] == "reached"
    # the eight-scenario table: run 1 of (a) is the run's time
    row = next(line for line in report.splitlines() if line.startswith("| (a)"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert float(cells[1]) == pytest.approx(record["time"], abs=0.005)
    assert float(cells[4]) == pytest.approx(record["time"], abs=0.005)  # mean of one run
    # the indicator table, recomputed here from the trajectory alone
    row = next(line for line in report.splitlines() if line.startswith("| a/seed1"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    traj = record["trajectory"]
    length = sum(math.dist(a[1:3], b[1:3]) for a, b in itertools.pairwise(traj))
    assert float(cells[2]) == pytest.approx(traj[-1][0], abs=0.005)
    assert float(cells[3]) == pytest.approx(length, abs=0.005)
    assert float(cells[5]) == pytest.approx(max(r[4] for r in traj), abs=0.0005)
    assert int(cells[9]) == len(record["events"])
