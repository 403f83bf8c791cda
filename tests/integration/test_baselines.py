"""The baseline planners as the planner service of a real stack: zenav run --planner."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
import yaml

pytestmark = pytest.mark.integration

SCENARIOS = Path(__file__).resolve().parents[2] / "sim" / "scenarios"


def run(scenario: str, planner: str, out: Path) -> dict[str, Any]:
    done = subprocess.run([sys.executable, "-m", "zenav", "run", str(SCENARIOS / scenario),
                           "--out", str(out), "--planner", planner],
                          capture_output=True, text=True, timeout=300, check=False)
    assert done.returncode == 0, done.stderr
    record: dict[str, Any] = json.loads((out / "run.json").read_text())
    assert record["planner"] == planner
    return record


@pytest.mark.parametrize("planner", ["vfh", "dwa", "apf", "orca"])
def test_reaches_the_goal_with_no_obstacle(planner, tmp_path):
    record = run("a-no-obstacle.yaml", planner, tmp_path)
    goal = yaml.safe_load((SCENARIOS / "a-no-obstacle.yaml").read_text())["robot"]["goal"]
    assert record["outcome"] == "reached"
    assert math.dist(record["trajectory"][-1][1:3], goal) <= 0.25
    assert "unclean_exits" not in record


@pytest.mark.parametrize("planner", ["vfh", "dwa"])
def test_drives_round_the_static_box(planner, tmp_path):
    record = run("b-static-obstacle.yaml", planner, tmp_path)
    assert record["outcome"] == "reached"
    assert record["min_clearance"] > 0
    assert max(abs(row[2] - 3.0) for row in record["trajectory"]) > 0.3  # went round


def test_apf_is_trapped_by_a_box_square_on_its_way(tmp_path):
    # The potential field's local minimum: the box stands on the line to the goal, the
    # push cancels the pull, and the robot stays in front of it until the time is up.
    record = run("b-static-obstacle.yaml", "apf", tmp_path)
    assert record["outcome"] == "timeout"
    assert record["min_clearance"] > 0
    last = record["trajectory"][-1]
    assert 3.5 < last[1] < 4.75 - 0.2 and abs(last[2] - 3.0) < 0.3
