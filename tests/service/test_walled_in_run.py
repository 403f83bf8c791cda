"""A goal inside a closed ring of walls (``nav-goal-walled-in``), run through the six
services on the in-memory bus: the run record has the planner's ``unreachable`` event,
the robot stands still from then on, and the outcome set is unchanged (the run ends as a
timeout)."""

from __future__ import annotations

from pathlib import Path

from zenav.run import run_scenario
from zenav.sim import SCENARIO_DIR
from zenav.sim.scenario import load_scenario


def test_the_walled_in_goal_ends_in_unreachable_and_the_robot_stands_still(
        tmp_path: Path) -> None:
    path = SCENARIO_DIR / "nav-goal-walled-in.yaml"
    scenario = load_scenario(path)
    record = run_scenario(path, tmp_path, engine="inprocess", picture=False)
    assert record["outcome"] == "timeout"
    assert record["time"] == scenario.duration
    stamps = [e["t"] for e in record["events"] if e["action"] == "unreachable"]
    assert len(stamps) == 1, [(e["t"], e["action"]) for e in record["events"]]
    declared = stamps[0]
    assert declared < scenario.duration - 20.0  # with time to spare, not at the timeout
    # Nothing the planner does changes after it: unreachable is the last event ...
    assert record["events"][-1]["action"] == "unreachable"
    # ... and the robot stands still (the motor bridge's ramp brings it to rest within a
    # second of the stop).
    after = [row for row in record["trajectory"] if row[0] >= declared + 1.0]
    assert len(after) > 100
    x0, y0, h0 = after[0][1:4]
    for _t, x, y, heading, speed in after:
        assert speed == 0.0
        assert abs(x - x0) < 1e-9 and abs(y - y0) < 1e-9 and abs(heading - h0) < 1e-9
    # The record's path is empty: the planner publishes none for an unreachable goal.
    assert record["path"] == []
