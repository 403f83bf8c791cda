"""A robot that starts within ``goal_tolerance`` of its goal has reached it at t = 0 (the
spec ends a run "when the robot centre is within goal_tolerance of the goal"): the record
has the one row of the start and no motion, through the six services on the in-memory
bus. Just outside the tolerance, the run goes on."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from zenav.run import run_scenario
from zenav.sim.params import Params
from zenav.sim.scenario import parse_scenario
from zenav.sim.simulation import Simulation


def near_goal(gap: float) -> dict[str, Any]:
    return {"name": "at-goal", "world": {"size": [6.0, 6.0], "cell": 0.5},
            "robot": {"start": [2.0, 2.0], "goal": [2.0 + gap, 2.0], "heading_deg": 0.0,
                      "speed": 0.5, "radius": 0.2, "goal_tolerance": 0.25},
            "laser": {"fov_deg": 180.0}, "obstacles": [], "duration": 10.0}


def test_a_run_that_starts_within_the_tolerance_is_reached_at_t0(tmp_path: Path) -> None:
    path = tmp_path / "at-goal.yaml"
    path.write_text(yaml.safe_dump(near_goal(0.25)))  # on the tolerance's edge: within
    record = run_scenario(path, tmp_path / "out", engine="inprocess", picture=False)
    assert (record["outcome"], record["time"], record["path_length"]) == ("reached", 0.0, 0.0)
    assert record["trajectory"] == [[0.0, 2.0, 2.0, 0.0, 0.0]]


def test_a_start_just_outside_the_tolerance_is_not_an_outcome() -> None:
    scenario = parse_scenario(near_goal(0.26), "at-goal.yaml")
    sim = Simulation(scenario, Params(scenario="at-goal.yaml"))
    assert sim.outcome is None
    sim.step(0.5, 0.0)  # the base ramps up from rest; 0.01 m is covered within a tick
    assert sim.outcome == "reached"
