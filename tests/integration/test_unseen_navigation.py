"""One freshly drawn scene of each navigation class (sim/unseen.py, seed 0: scenes the
planner was not tuned on), through `zenav run` in process: reached with no contact,
judged on the scenario's own geometry from run.json alone."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from zenav.sim.contact import clearance
from zenav.sim.scenario import dump_scenario, load_scenario
from zenav.sim.unseen import CLASSES, unseen_scenario
from zenav.sim.world import World

pytestmark = pytest.mark.integration

SEED = 0


def zenav_run(scenario: Path, out: Path) -> dict[str, Any]:
    done = subprocess.run([sys.executable, "-m", "zenav", "run", str(scenario), "--out", str(out),
                           "--engine", "inprocess", "--log-level", "WARNING"],
                          capture_output=True, text=True, timeout=600, check=False)
    assert done.returncode == 0, done.stderr
    record: dict[str, Any] = json.loads((out / "run.json").read_text())
    return record


@pytest.mark.parametrize("kind", CLASSES)
def test_unseen_scene_is_reached_without_contact(kind: str, tmp_path: Path) -> None:
    path = dump_scenario(unseen_scenario(kind, SEED), tmp_path / f"{kind}.yaml")
    scenario = load_scenario(path)
    record = zenav_run(path, tmp_path / "run")
    assert record["outcome"] == "reached", \
        f"{scenario.name}: {record['outcome']} at {record['time']}"
    last = record["trajectory"][-1]
    assert math.dist(last[1:3], scenario.robot.goal) <= scenario.robot.goal_tolerance + 1e-6
    world = World.from_scenario(scenario)
    gap = min(clearance((row[1], row[2]), scenario.robot.radius, world.snapshot(row[0]))
              for row in record["trajectory"])
    assert gap > 0.0
