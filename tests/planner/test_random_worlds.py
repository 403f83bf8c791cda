"""Generalisation: seeded random worlds the planner was not tuned on.

Each world runs through the production in-process engine (``zenav run --engine
inprocess``: the six services on one in-memory bus, every message through the codec, the
same record as the stack), so many fit in a test: three seeds of every family. The
navigation benchmark (``zenav bench nav``) runs many more.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from zenav.run import run_scenario
from zenav.sim.generate import FAMILIES, random_scenario
from zenav.sim.scenario import dump_scenario

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


def test_crowd_movers_are_in_place_from_the_start_clear_of_the_robot() -> None:
    """No crowd mover comes out of nothing on the robot: all five exist at t = 0, on
    the circle round the path's middle, their discs at least 0.5 m from the robot's."""
    for seed in range(200):
        scenario = random_scenario("crowd", seed)
        start = np.asarray(scenario.robot.start)
        movers = scenario.obstacles
        assert len(movers) == 5
        for mover in movers:
            assert mover.appear == 0.0 and mover.velocity is not None
            assert mover.radius is not None  # a disc
            gap = float(np.hypot(*(np.asarray(mover.center) - start)))
            assert gap - mover.radius - scenario.robot.radius >= 0.5, (seed, gap)
