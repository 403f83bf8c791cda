"""The paper's shipped scenarios through the real stack: reached, no contact on ground
truth, the paper's scenario letter and action in the events, and the same run twice.
The navigation classes beyond the paper (``nav-*.yaml``) are in test_navigation.py."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from zenav.sim.contact import clearance
from zenav.sim.scenario import load_scenario
from zenav.sim.world import World

pytestmark = pytest.mark.integration

SCENARIOS = sorted(p for p in (Path(__file__).resolve().parents[2] / "sim" / "scenarios")
                   .glob("*.yaml") if not p.stem.startswith("nav-"))

# What the paper says the robot does in each of its eight scenarios (Section 3.5).
EXPECTED: dict[str, tuple[str, set[str]]] = {
    "a-no-obstacle": ("a", {"keep"}),
    "b-static-obstacle": ("b", {"morphin"}),
    "c-crosser-passes-first": ("c", {"keep"}),
    "d-crosser-arrives-after": ("d", {"keep"}),
    "e-crosser-would-meet": ("e", {"stop", "slow", "speed_up"}),
    "f-head-on": ("f", {"morphin"}),
    "g-slower-ahead": ("g", {"slow", "stop"}),
    "h-mixed": ("h", {"stop", "slow", "speed_up", "morphin"}),
}


def zenav_run(scenario: Path, out: Path) -> dict[str, Any]:
    done = subprocess.run([sys.executable, "-m", "zenav", "run", str(scenario), "--out", str(out)],
                          capture_output=True, text=True, timeout=600, check=False)
    assert done.returncode == 0, done.stderr
    record: dict[str, Any] = json.loads((out / "run.json").read_text())
    return record


@pytest.fixture(scope="module")
def records(tmp_path_factory: pytest.TempPathFactory) -> dict[str, dict[str, Any]]:
    """All shipped scenarios, two runs at a time (each run is six processes)."""
    base = tmp_path_factory.mktemp("scenarios")
    with ThreadPoolExecutor(2) as pool:
        done = pool.map(lambda p: (p.stem, zenav_run(p, base / p.stem)), SCENARIOS)
        return dict(done)


def ground_truth_clearance(scenario_path: Path, trajectory: list[list[float]]) -> float:
    """Smallest gap between the robot disc and any obstacle over the recorded run,
    from the scenario's own geometry (not from anything the planner saw)."""
    scenario = load_scenario(scenario_path)
    world = World.from_scenario(scenario)
    gaps = [clearance((row[1], row[2]), scenario.robot.radius, world.snapshot(row[0]))
            for row in trajectory]
    return min(gaps, default=math.inf)


@pytest.mark.parametrize("path", SCENARIOS, ids=[p.stem for p in SCENARIOS])
def test_shipped_scenario_reaches_its_goal_without_touching_anything(path, records):
    record = records[path.stem]
    scenario = yaml.safe_load(path.read_text())
    assert record["outcome"] == "reached", f"{path.stem}: {record['outcome']} at {record['time']}"
    last = record["trajectory"][-1]
    goal = scenario["robot"]["goal"]
    assert math.dist(last[1:3], goal) <= scenario["robot"].get("goal_tolerance", 0.25) + 1e-6
    assert ground_truth_clearance(path, record["trajectory"]) > 0.0


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_paper_scenario_shows_its_letter_and_action(name, records):
    letter, actions = EXPECTED[name]
    found = {(e["scenario"], e["action"]) for e in records[name]["events"]}
    assert any(s == letter and a in actions for s, a in found), f"{name}: events {sorted(found)}"


def test_a_noisy_run_is_the_same_run_twice(tmp_path):
    data = yaml.safe_load((SCENARIOS[0].parent / "h-mixed.yaml").read_text())
    data["laser"] = {"noise_std": 0.02}
    data["seed"] = 7
    noisy = tmp_path / "noisy.yaml"
    noisy.write_text(yaml.safe_dump(data))
    with ThreadPoolExecutor(2) as pool:
        first, second = pool.map(lambda k: zenav_run(noisy, tmp_path / f"run{k}"), (1, 2))
    assert first["outcome"] == "reached"
    assert np.array_equal(np.array(first["trajectory"]), np.array(second["trajectory"]))
    assert first["events"] == second["events"]
