"""The paper's performance indicators, on a run record made by hand."""

from __future__ import annotations

import math

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
