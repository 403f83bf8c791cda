"""The paper's performance indicators, on a run record made by hand."""

from __future__ import annotations

import math
from typing import Any

import pytest

from zenav.paper import indicators
from zenav.sim.scenario import parse_scenario

SCENARIO = parse_scenario({
    "name": "hand", "world": {"size": [10.0, 10.0], "cell": 0.5},
    "robot": {"start": [0.0, 0.0], "goal": [4.0, 0.0], "speed": 0.1, "radius": 0.2},
}, "hand")


def test_indicators_by_hand():
    record = {
        "time": 3.0, "path_length": 4.5, "min_clearance": 0.3,
        "trajectory": [[0.0, 0.0, 0.0, 0.0, 0.0], [1.0, 1.0, 1.0, 0.0, 0.2],
                       [2.0, 2.0, 0.5, 0.0, 0.4], [3.0, 4.0, 0.0, 0.0, 0.0]],
    }
    got = indicators(record, SCENARIO)
    assert got["T"] == 3.0 and got["L"] == 4.5
    assert got["v_mean"] == pytest.approx(0.15)
    assert got["v_max"] == pytest.approx(0.4)
    assert got["off_max"] == pytest.approx(1.0)
    assert got["off_mean"] == pytest.approx(1.5 / 4)
    assert got["clearance"] == 0.3


def test_no_obstacle_means_infinite_clearance():
    record = {"time": 1.0, "path_length": 0.1, "min_clearance": None,
              "trajectory": [[0.0, 0.0, 0.0, 0.0, 0.0], [1.0, 0.1, 0.0, 0.0, 0.1]]}
    assert math.isinf(indicators(record, SCENARIO)["clearance"])


def _record(outcome: str, time: float, **extra: Any) -> dict[str, Any]:
    return {"outcome": outcome, "time": time, "events": [], "collided_with": None, **extra}


def test_table_3_side_by_side_shows_a_failed_run_and_why() -> None:
    """(a) at 60 s for both profiles; (f) for the paper profile collides once: its cell
    shows the outcome, its mean and ratio are '-', and the failure list says what it hit
    and the planner's last decision."""
    from zenav.paper import eight_table, failures

    stop = {"t": 20.0, "obstacle": 3, "kind": "static", "scenario": "b", "action": "stop",
            "detail": "speed 0.00 m/s"}
    records = {
        "zenav/a/seed1": _record("reached", 60.0), "paper/a/seed1": _record("reached", 60.0),
        "zenav/f/seed1": _record("reached", 66.0),
        "paper/f/seed1": _record("collision", 27.5, collided_with=0, events=[stop]),
    }
    rows = eight_table(records, (1,))
    a_row = next(r for r in rows if r.startswith("| (a)"))
    f_row = next(r for r in rows if r.startswith("| (f)"))
    assert [c.strip() for c in a_row.strip("|").split("|")][:7] == [
        "(a)", "60.00", "60.00", "1.000", "60.00", "60.00", "1.000"]
    cells = [c.strip() for c in f_row.strip("|").split("|")]
    assert cells[1:7] == ["66.00", "66.00", "1.100", "collision 27.50", "-", "-"]
    assert cells[7:] == ["76.12 77.20 76.45", "76.59", "1.237"]  # the paper's own
    (line,) = failures(records)
    assert line == ("- paper/f/seed1: collision with obstacle 0 at t = 27.50 s; last decision "
                    "at t = 20.0 s: (b) stop for obstacle 3 (static), speed 0.00 m/s")
