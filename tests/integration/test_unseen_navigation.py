"""One freshly drawn scene of each navigation class (sim/unseen.py, seed 0: scenes the
planner was not tuned on), through `zenav run` in process: reached with no contact,
judged on the scenario's own geometry from run.json alone (and, for the classes with ORCA
walkers, on the walkers' paths the record carries)."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from tests.integration.test_navigation import ground_truth_clearance
from zenav.sim.contact import clearance
from zenav.sim.scenario import Scenario, dump_scenario, load_scenario, parse_scenario
from zenav.sim.unseen import CLASSES, WALKER_CLASSES, turn_point, turn_vector, unseen_scenario
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


def assert_reached_without_contact(scenario: Scenario, record: dict[str, Any]) -> None:
    assert record["outcome"] == "reached", \
        f"{scenario.name}: {record['outcome']} at {record['time']}"
    last = record["trajectory"][-1]
    assert math.dist(last[1:3], scenario.robot.goal) <= scenario.robot.goal_tolerance + 1e-6
    world = World.from_scenario(scenario)
    gap = min(clearance((row[1], row[2]), scenario.robot.radius, world.snapshot(row[0]))
              for row in record["trajectory"])
    assert gap > 0.0


@pytest.mark.parametrize("kind", CLASSES)
def test_unseen_scene_is_reached_without_contact(kind: str, tmp_path: Path) -> None:
    path = dump_scenario(unseen_scenario(kind, SEED), tmp_path / f"{kind}.yaml")
    scenario = load_scenario(path)
    record = zenav_run(path, tmp_path / "run")
    assert_reached_without_contact(scenario, record)


@pytest.mark.parametrize("kind", WALKER_CLASSES)
def test_scene_with_walkers_is_reached_without_contact(kind: str, tmp_path: Path) -> None:
    path = dump_scenario(unseen_scenario(kind, SEED), tmp_path / f"{kind}.yaml")
    record = zenav_run(path, tmp_path / "run")
    assert record["outcome"] == "reached", f"{kind}: {record['outcome']} at {record['time']}"
    assert record["agents"], "the record carries the walkers' paths"
    assert ground_truth_clearance(path, record) > 0.0


TURNS = ("quarter", "half", "mirror")
QUARTERS = {"quarter": 1, "half": 2, "mirror": 0}


def turned(scenario: Scenario, turn: str) -> Scenario:
    """``scenario`` turned a quarter (counter-clockwise) or half turn about its world's
    centre (``sim.unseen``'s turning), or mirrored across its middle line y = height / 2:
    the same scene in other coordinates (boxes stay axis-aligned)."""
    data = scenario.model_dump(mode="json", exclude_none=True)
    width, height = data["world"]["size"]
    quarter, mirror = QUARTERS[turn], turn == "mirror"

    def point(p: list[float]) -> list[float]:
        x, y = p
        return list(turn_point((x, height - y if mirror else y), quarter, width, height))

    def vector(v: list[float]) -> list[float]:
        x, y = v
        return list(turn_vector((x, -y if mirror else y), quarter))

    if quarter % 2:
        data["world"]["size"] = [height, width]
    robot = data["robot"]
    robot["heading_deg"] = (-1.0 if mirror else 1.0) * robot["heading_deg"] + 90.0 * quarter
    robot["start"], robot["goal"] = point(robot["start"]), point(robot["goal"])
    data["name"] = f"{data['name']}-{turn}"
    for obstacle in data.get("obstacles", []):
        obstacle["center"] = point(obstacle["center"])
        if "velocity" in obstacle:
            obstacle["velocity"] = vector(obstacle["velocity"])
        if "goals" in obstacle:
            obstacle["goals"] = [point(goal) for goal in obstacle["goals"]]
        if quarter % 2 and "size" in obstacle:
            obstacle["size"] = obstacle["size"][::-1]
    return parse_scenario(data, f"<{data['name']}>")


def test_turned_mirrors_a_point_and_turns_a_box() -> None:
    scene = parse_scenario({
        "name": "t", "world": {"size": [10.0, 6.0], "cell": 0.5},
        "robot": {"start": [1.0, 2.0], "heading_deg": 30.0, "goal": [9.0, 2.0],
                  "speed": 0.1, "radius": 0.2},
        "obstacles": [{"shape": "box", "center": [4.0, 1.0], "size": [0.5, 2.0]},
                      {"shape": "disc", "center": [6.0, 5.0], "radius": 0.2,
                       "velocity": [0.1, -0.2]}]}, "<t>")
    quarter, mirror = turned(scene, "quarter"), turned(scene, "mirror")
    assert quarter.world.size == (6.0, 10.0)
    assert tuple(quarter.robot.start) == (4.0, 1.0) and quarter.robot.heading_deg == 120.0
    assert quarter.obstacles[0].size == (2.0, 0.5)
    assert tuple(quarter.obstacles[1].velocity) == (0.2, 0.1)
    assert tuple(mirror.robot.goal) == (9.0, 4.0) and mirror.robot.heading_deg == -30.0
    assert tuple(mirror.obstacles[1].velocity) == (0.1, 0.2)


@pytest.mark.parametrize("kind", CLASSES)
def test_an_unseen_scene_in_other_coordinates_is_reached_too(kind: str, tmp_path: Path) -> None:
    """Nothing in the planner hangs on the world's axes or sides: the same unseen scene
    turned a quarter or a half turn, or mirrored (one of the three per class, in turn),
    is reached without contact as well."""
    turn = TURNS[CLASSES.index(kind) % len(TURNS)]
    scenario = turned(unseen_scenario(kind, SEED), turn)
    path = dump_scenario(scenario, tmp_path / f"{scenario.name}.yaml")
    record = zenav_run(path, tmp_path / "run")
    assert_reached_without_contact(load_scenario(path), record)
