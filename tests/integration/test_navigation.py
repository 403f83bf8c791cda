"""The navigation classes beyond the paper's eight cases, through `zenav run`: each
scenario in sim/scenarios/nav-*.yaml (but the walled-in goal, which no way reaches) is
reached with no contact, judged on the scenario's own geometry from run.json alone; the
run record carries the planner's last global path."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import pytest

from zenav.sim.contact import clearance
from zenav.sim.scenario import load_scenario
from zenav.sim.world import World

pytestmark = pytest.mark.integration

UNREACHABLE = {"nav-goal-walled-in"}  # ends in `unreachable`: tests/service/test_walled_in_run.py
SCENARIOS = sorted(p for p in (Path(__file__).resolve().parents[2] / "sim" / "scenarios")
                   .glob("nav-*.yaml") if p.stem not in UNREACHABLE)


def zenav_run(scenario: Path, out: Path) -> dict[str, Any]:
    done = subprocess.run([sys.executable, "-m", "zenav", "run", str(scenario), "--out", str(out),
                           "--log-level", "WARNING"],
                          capture_output=True, text=True, timeout=900, check=False)
    assert done.returncode == 0, done.stderr
    record: dict[str, Any] = json.loads((out / "run.json").read_text())
    return record


@pytest.fixture(scope="module")
def records(tmp_path_factory: pytest.TempPathFactory) -> dict[str, dict[str, Any]]:
    base = tmp_path_factory.mktemp("navigation")
    with ThreadPoolExecutor(2) as pool:
        return dict(pool.map(lambda p: (p.stem, zenav_run(p, base / p.stem)), SCENARIOS))


def ground_truth_clearance(path: Path, record: dict[str, Any]) -> float:
    """The least gap between the robot disc and every obstacle over the run: the fixed
    ones from the scenario, the ORCA agents from the record's own rows (the spec's
    ``agents``: by index in ``obstacles``, at the trajectory's ticks)."""
    scenario = load_scenario(path)
    world = World.from_scenario(scenario)
    trajectory = record["trajectory"]
    gaps = [clearance((row[1], row[2]), scenario.robot.radius, world.snapshot(row[0]))
            for row in trajectory]
    for index, rows in record.get("agents", {}).items():
        agent = scenario.obstacles[int(index)]
        assert agent.radius is not None, f"agent {index} is a disc"
        assert len(rows) == len(trajectory), f"agent {index}: one row per tick"
        for robot, (t, x, y) in zip(trajectory, rows, strict=True):
            assert t == pytest.approx(robot[0])
            gaps.append(math.dist(robot[1:3], (x, y)) - scenario.robot.radius - agent.radius)
    return min(gaps, default=math.inf)


def test_there_is_a_scenario_for_every_class():
    names = {p.stem for p in SCENARIOS}
    for needed in ("appear", "wall-gap", "dead-end", "corridor-follower", "corridor-head-on",
                   "corridor-sealed-head-on", "hairpin", "slalom", "room-door-behind",
                   "door-two-way", "two-rooms", "s-bend", "doorway-stopper", "start-at-wall",
                   "corridor-overtaker", "blind-overtaker", "posts", "mover-stops",
                   "facing-away", "goal-beside-wall", "door-in-long-wall"):
        assert any(needed in name for name in names), needed


@pytest.mark.parametrize("path", SCENARIOS, ids=[p.stem for p in SCENARIOS])
def test_class_scenario_is_reached_without_contact(path, records):
    record = records[path.stem]
    scenario = load_scenario(path)
    assert record["outcome"] == "reached", f"{path.stem}: {record['outcome']} at {record['time']}"
    last = record["trajectory"][-1]
    assert math.dist(last[1:3], scenario.robot.goal) <= scenario.robot.goal_tolerance + 1e-6
    assert ground_truth_clearance(path, record) > 0.0
    # The path ends at the goal, or beside it when the goal lies too close to a wall for
    # the robot disc (``settle_point``), within the tolerance.
    assert math.dist(record["path"][-1], scenario.robot.goal) < scenario.robot.goal_tolerance


def test_the_appearing_box_is_never_taken_for_a_mover(records):
    events = records["nav-appear-ahead"]["events"]
    assert all(e["kind"] != "dynamic" for e in events), events
    assert any(e["scenario"] == "b" and e["action"] == "morphin" for e in events)


def test_in_a_sealed_corridor_the_robot_gives_way(records):
    """No way round the head-on walker: the robot steps aside (a `give_way` event about
    it, typed dynamic) instead of a detour back along the corridor, and is not hit."""
    events = records["nav-corridor-sealed-head-on"]["events"]
    held = [e for e in events if e["action"] == "give_way"]
    assert held and all(e["kind"] == "dynamic" and e["scenario"] == "f" for e in held), events


def test_a_door_in_a_long_wall_is_gone_through_not_round(records):
    """The map's path through the door, not the paper's detour down the wall (which
    took the robot 2.4 m down it, to y = 0.64, before recovery planned through the door)."""
    trajectory = records["nav-door-in-long-wall"]["trajectory"]
    assert min(row[2] for row in trajectory) > 2.0, "went down along the wall"
