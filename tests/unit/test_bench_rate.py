"""The sustained-rate section of ``zenav bench perf``: its runs fit the simulator's limits."""

from __future__ import annotations

import pytest

from zenav.bench.rate import SETTLE_S, highest_rate, rate_scenario
from zenav.sim.scenario import MAX_TICKS, limit_problems, parse_scenario


@pytest.mark.parametrize("rate", [10, 50, 100, 200, 300, 400, 600, highest_rate(6.0)])
def test_every_default_rate_gives_a_scenario_the_simulator_takes(rate: float) -> None:
    """The default rates (and the highest the default 6 s allow) give a scenario within
    every limit, at that rate, long enough to settle and be measured for 6 s. (100 Hz
    and more once asked for 360,000 ticks and the section ended in a traceback.)"""
    scenario = parse_scenario(rate_scenario(rate), "rate")
    assert limit_problems(scenario) == []
    assert scenario.laser.rate_hz == rate
    assert scenario.duration >= SETTLE_S + 6.0 + 10.0
    assert scenario.duration * max(rate, 10.0) <= MAX_TICKS


def test_a_slow_rate_runs_for_an_hour_at_most() -> None:
    assert parse_scenario(rate_scenario(10), "rate").duration == 3600
