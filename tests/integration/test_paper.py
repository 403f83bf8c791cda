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
                           str(tmp_path)], capture_output=True, text=True, timeout=600,
                          check=False)
    assert done.returncode == 0, done.stderr
    report = (tmp_path / "report.md").read_text()
    records = {profile: json.loads((tmp_path / "runs" / profile / "a-seed1" / "run.json")
                                   .read_text()) for profile in ("zenav", "paper")}
    assert records["paper"]["profile"] == "paper" and "profile" not in records["zenav"]
    # Table 3 side by side: (a)'s run and mean for zenav's defaults, then the paper profile
    row = next(line for line in report.splitlines() if line.startswith("| (a)"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    for first, profile in ((1, "zenav"), (4, "paper")):
        record = records[profile]
        assert record["outcome"] == "reached"
        assert float(cells[first]) == pytest.approx(record["time"], abs=0.005)
        assert float(cells[first + 1]) == pytest.approx(record["time"], abs=0.005)  # mean
        assert cells[first + 2] == "1.000"
    assert cells[-1] == "1.000" and cells[-2] == "61.92"  # the paper's own
    # the indicator table, recomputed here from the trajectory alone
    for profile, record in records.items():
        row = next(line for line in report.splitlines()
                   if line.startswith(f"| {profile}/a/seed1"))
        cells = [c.strip() for c in row.strip("|").split("|")]
        traj = record["trajectory"]
        length = sum(math.dist(a[1:3], b[1:3]) for a, b in itertools.pairwise(traj))
        assert float(cells[2]) == pytest.approx(traj[-1][0], abs=0.005)
        assert float(cells[3]) == pytest.approx(length, abs=0.005)
        assert float(cells[5]) == pytest.approx(max(r[4] for r in traj), abs=0.0005)
        assert int(cells[9]) == len(record["events"])
    # the typing accuracy of both profiles
    assert "## Typing accuracy of the two profiles" in report
    table = report.split("## Typing accuracy")[1].split("```")[1]
    assert " paper " in table and " zenav " in table
