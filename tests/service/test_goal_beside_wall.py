"""A goal closer to a wall than the robot's radius, but within ``goal_tolerance`` of where
its centre can stand, is reached: the planner stops beside the goal on the free side
(``Planner.settle_goal``) instead of driving at the goal until the local layer turns
away from the wall. Approached head-on, as near as the motor bridge's stop zone lets a
creeping robot come (``final_approach_speed``). A goal with no room within its tolerance
for the robot and its zone ends in ``unreachable``. The scenario loader refuses only a
goal no centre can come within the tolerance of. Through the six services on the
in-memory bus."""

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


def head_on(tmp_path: Path, radius: float, gap: float) -> Path:
    """The same wall, the goal ``gap`` m below its face, the robot straight below."""
    data = yaml.safe_load(SCENE.read_text())
    data["robot"].update(start=[7.0, 1.5], heading_deg=90.0, goal=[7.0, WALL_FACE_Y - gap],
                         radius=radius)
    data["obstacles"] = data["obstacles"][:1]  # the wall alone
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


@pytest.mark.parametrize(("radius", "gap"), [(0.2, 0.05), (0.3, 0.15)])
def test_a_goal_just_short_of_a_wall_ahead_is_reached_at_a_creep(
        tmp_path: Path, radius: float, gap: float) -> None:
    # The stop zone at 0.05 m/s reaches 0.096 m beyond the front: the centre can come
    # within radius + 0.096 m of the face, within the 0.25 m tolerance of these goals.
    path = head_on(tmp_path, radius, gap)
    record = run_scenario(path, tmp_path / "out", engine="inprocess", picture=False)
    assert record["outcome"] == "reached", (record["outcome"], record["time"])
    assert record["time"] < 30.0  # 3 m at 0.3 m/s, and the creep: no detour round the wall
    assert all(e["action"] not in ("morphin", "replan", "spin") for e in record["events"])
    scenario = load_scenario(path)
    world = World.from_scenario(scenario)
    assert min(clearance((row[1], row[2]), scenario.robot.radius, world.snapshot(row[0]))
               for row in record["trajectory"]) > 0.05


def test_a_goal_with_no_room_for_the_robot_and_its_stop_zone_ends_in_unreachable(
        tmp_path: Path) -> None:
    # 0.1 + 0.25 < 0.3 + 0.096: no centre the zone lets come that near stands within the
    # tolerance (the loader accepts it: 0.1 + 0.25 > 0.3).
    path = head_on(tmp_path, 0.3, 0.1)
    record = run_scenario(path, tmp_path / "out", engine="inprocess", picture=False)
    assert record["outcome"] == "timeout"
    stamps = [e["t"] for e in record["events"] if e["action"] == "unreachable"]
    assert len(stamps) == 1 and stamps[0] < 60.0, [(e["t"], e["action"])
                                                   for e in record["events"]]
    assert record["events"][-1]["action"] == "unreachable"
    assert record["path"] == []
