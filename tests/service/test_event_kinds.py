"""Every event that names an obstacle names its type too (the spec: each event carries
"the obstacle it was about, the obstacle type (new | static | dynamic)"). A decision
that keeps to a Morphin detour after its obstacle stopped threatening used to name the
obstacle with a type of null. Runs through the six services on the in-memory bus."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
import yaml

from zenav.run import run_scenario
from zenav.sim.generate import random_scenario
from zenav.sim.scenario import dump_scenario

SPEC_EXAMPLE: dict[str, Any] = {
    # The scenario format's own example: a box on the line and a head-on disc.
    "name": "head-on",
    "world": {"size": [10.0, 10.0], "cell": 0.5},
    "robot": {"start": [2.0, 5.0], "heading_deg": 0.0, "goal": [8.0, 5.0],
              "goal_tolerance": 0.25, "speed": 0.1, "max_speed": 0.2, "radius": 0.2},
    "laser": {"fov_deg": 180, "resolution_deg": 0.5, "max_range": 8.0, "rate_hz": 10,
              "noise_std": 0.0},
    "obstacles": [{"shape": "box", "center": [5.0, 5.0], "size": [0.5, 0.5]},
                  {"shape": "disc", "center": [9.0, 5.0], "radius": 0.2,
                   "velocity": [-0.5, 0.0], "appear": 0.0, "vanish": 40.0}],
    "duration": 300, "seed": 0,
}


def _spec_example(tmp: Path) -> Path:
    path = tmp / "head-on.yaml"
    path.write_text(yaml.safe_dump(SPEC_EXAMPLE))
    return path


def _crowd_world(tmp: Path) -> Path:
    # Five walkers converging on the robot's way, seen all round: detours that outlast
    # their threat.
    path = dump_scenario(random_scenario("crowd", 93013), tmp / "crowd-93013.yaml")
    data = yaml.safe_load(path.read_text())
    data["laser"]["fov_deg"] = 360.0
    path.write_text(yaml.safe_dump(data))
    return path


@pytest.mark.parametrize("world", [_spec_example, _crowd_world], ids=["spec", "crowd"])
def test_an_event_about_an_obstacle_names_its_type(world: Any, tmp_path: Path) -> None:
    record = run_scenario(world(tmp_path), tmp_path / "out", engine="inprocess",
                          picture=False)
    about = [e for e in record["events"] if e["obstacle"] is not None]
    assert len(about) >= 3, record["events"]
    assert all(e["kind"] in ("new", "static", "dynamic") for e in about), \
        [e for e in about if e["kind"] not in ("new", "static", "dynamic")]
    plain = [e for e in record["events"] if e["obstacle"] is None]
    assert all(e["kind"] is None for e in plain)
