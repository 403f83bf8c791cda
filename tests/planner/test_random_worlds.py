"""Generalisation: seeded random worlds the planner was not tuned on.

Each world runs through the same cores as the stack, in one process (zenav.inprocess:
same code, same order, no transport), so many fit in a test. The movers of these
families come from ahead or across, where the 180-degree laser sees them; the crowd
family also has movers coming from behind, which no forward scanner can see, and is
measured by the navigation benchmark instead.
"""

from __future__ import annotations

import pytest

from zenav.inprocess import run_inprocess
from zenav.sim.generate import random_scenario
from zenav.sim.scenario import dump_scenario

FAMILIES = ("static", "crossing", "head-on", "overtaking")
SEEDS = (101, 102, 103)


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("family", FAMILIES)
def test_random_world_is_crossed_without_contact(family, seed, tmp_path):
    scenario = random_scenario(family, seed, noise_std=0.01)
    path = dump_scenario(scenario, tmp_path / f"{family}-{seed}.yaml")
    run = run_inprocess(path)
    sim = run.simulation
    assert sim.outcome == "reached", f"{family}-{seed}: {sim.outcome} at t={sim.t:.1f}"
    assert sim.min_clearance > 0.0
