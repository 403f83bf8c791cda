"""A duration that is not a whole number of ticks: the last tick is cut short, so a
timeout comes at the duration exactly (the run record's rule), not at the next tick."""

from __future__ import annotations

import itertools
from typing import Any

import pytest

from zenav.sim.params import Params
from zenav.sim.scenario import parse_scenario
from zenav.sim.simulation import Simulation


def drive(duration: float) -> Simulation:
    spec: dict[str, Any] = {
        "name": "straight", "world": {"size": [10.0, 6.0], "cell": 0.5},
        "robot": {"start": [2.0, 3.0], "heading_deg": 0.0, "goal": [8.0, 3.0], "speed": 0.1,
                  "radius": 0.2},
        "duration": duration}
    scenario = parse_scenario(spec, "straight.yaml")
    sim = Simulation(scenario, Params(scenario="straight.yaml"))
    while sim.outcome is None:
        sim.step(0.1, 0.0)
    return sim


@pytest.mark.parametrize("duration", [3.05, 0.04, 2.99])
def test_a_timeout_comes_at_the_duration_exactly(duration: float) -> None:
    sim = drive(duration)
    times = [row[0] for row in sim.rows]
    assert sim.outcome == "timeout"
    assert sim.t == duration and times[-1] == duration
    gaps = [b - a for a, b in itertools.pairwise(times)]
    assert all(0.0 < g <= sim.dt + 1e-9 for g in gaps)


def test_the_cut_tick_drives_for_its_own_length() -> None:
    sim = drive(3.05)  # at its steady 0.1 m/s long before the end
    (t0, x0, _, _, v0), (t1, x1, *_) = sim.rows[-2], sim.rows[-1]
    assert v0 == pytest.approx(0.1)
    assert t1 - t0 == pytest.approx(0.05)
    assert x1 - x0 == pytest.approx(0.1 * 0.05, abs=1e-9)


def test_a_whole_number_of_ticks_is_as_before() -> None:
    sim = drive(3.0)
    times = [row[0] for row in sim.rows]
    assert sim.outcome == "timeout" and times[-1] == 3.0 and len(times) == 31
    assert sim.rows[-1][1] == pytest.approx(drive(3.05).rows[-2][1], abs=0.0)
