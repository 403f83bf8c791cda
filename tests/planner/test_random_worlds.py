"""Generalisation: seeded random worlds the planner was not tuned on.

Each world runs through the production in-process engine (``zenav run --engine
inprocess``: the six services on one in-memory bus, every message through the codec, the
same record as the stack), so many fit in a test. The movers of these families come
from ahead or across, where the 180-degree laser sees them; the crowd family also has
movers coming from behind, which no forward scanner can see, and is measured by the
navigation benchmark instead.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from zenav.run import run_scenario
from zenav.sim.generate import random_scenario
from zenav.sim.scenario import dump_scenario

FAMILIES = ("static", "crossing", "head-on", "overtaking")
SEEDS = (101, 102, 103)


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("family", FAMILIES)
def test_random_world_is_crossed_without_contact(family: str, seed: int,
                                                 tmp_path: Path) -> None:
    scenario = random_scenario(family, seed, noise_std=0.01)
    path = dump_scenario(scenario, tmp_path / f"{family}-{seed}.yaml")
    record = run_scenario(path, tmp_path / "run", engine="inprocess", picture=False)
    assert record["outcome"] == "reached", f"{family}-{seed}: {record['outcome']} at " \
        f"t={record['time']:.1f}"
    assert record["min_clearance"] is None or record["min_clearance"] > 0.0
