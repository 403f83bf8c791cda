"""A goal closer to a wall than the robot's radius, but within ``goal_tolerance`` of where
its centre can stand, is reached: the planner stops beside the goal on the free side
(``Planner.settle_goal``) instead of driving at the goal until the local layer turns
away from the wall. The scenario loader refuses only a goal no centre can come within
the tolerance of. Through the six services on the in-memory bus."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
import yaml

from zenav.run import run_scenario
from zenav.sim import SCENARIO_DIR
from zenav.sim.contact import clearance
from zenav.sim.scenario import ScenarioError, load_scenario, parse_scenario
from zenav.sim.world import World

SCENE = SCENARIO_DIR / "nav-goal-beside-wall.yaml"
WALL_FACE_Y = 4.5  # the wall's lower face in that scene


@pytest.mark.parametrize("gap", [0.1, 0.15, 0.2])
def test_a_goal_beside_a_wall_is_reached_without_contact(gap: float, tmp_path: Path) -> None:
    data = yaml.safe_load(SCENE.read_text())
    data["robot"]["goal"] = [7.0, WALL_FACE_Y - gap]
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(data))
    record = run_scenario(path, tmp_path / "out", engine="inprocess", picture=False)
    assert record["outcome"] == "reached", (record["outcome"], record["time"])
    assert record["time"] < 40.0  # the way is 6.3 m at 0.3 m/s: no wandering at the wall
    scenario = load_scenario(path)
    world = World.from_scenario(scenario)
    assert min(clearance((row[1], row[2]), scenario.robot.radius, world.snapshot(row[0]))
               for row in record["trajectory"]) > 0.0
    end = record["path"][-1]
    assert math.dist(end, scenario.robot.goal) < scenario.robot.goal_tolerance
    assert end[1] + scenario.robot.radius <= WALL_FACE_Y + 1e-9  # it stops clear of the wall


def test_only_a_goal_no_centre_can_come_within_the_tolerance_of_is_refused() -> None:
    data = yaml.safe_load(SCENE.read_text())
    data["robot"]["goal"] = [7.0, WALL_FACE_Y - 0.1]
    data["robot"]["goal_tolerance"] = 0.1  # 0.1 + 0.1 = the radius: no room at all
    with pytest.raises(ScenarioError, match=r"robot.goal: unreachable: static obstacles\[0\]"):
        parse_scenario(data, "scene.yaml")
    data["robot"]["goal_tolerance"] = 0.11
    assert parse_scenario(data, "scene.yaml").robot.goal == (7.0, WALL_FACE_Y - 0.1)
