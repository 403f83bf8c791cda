"""The in-process engine against the stack: the same trajectory, row by row, and the same
events, on the eight paper scenarios, the paper's experiments, seeded random worlds and
CrowdNav cases with ORCA agents.

The stack (six processes over Zenoh) is the acceptance path; the in-process engine
(``zenav run --engine inprocess``, :mod:`zenav.engine`) is what sweeps use, so it must
be the same run, tick by tick, not merely a similar one.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import pytest

from zenav.engine import first_difference
from zenav.run import run_scenario
from zenav.sim import SCENARIO_DIR
from zenav.sim.crowdnav import Layout, crowdnav_scenario
from zenav.sim.generate import random_scenario
from zenav.sim.scenario import dump_scenario

pytestmark = pytest.mark.integration

PAPER = sorted(SCENARIO_DIR.glob("[a-h]-*.yaml"))
EXPERIMENTS = sorted(SCENARIO_DIR.glob("paper-*.yaml"))
RANDOM = (("static", 7), ("crossing", 8), ("head-on", 9), ("mixed", 10))
AGENT_WORLDS: tuple[tuple[Layout, int, bool, float], ...] = (
    ("circle", 3, False, 360.0), ("square", 5, True, 180.0))
"""Worlds with agents (ORCA walkers with goals of their own): CrowdNav test cases
(layout, case, humans see the robot, laser field of view), one of each layout and
setting kind."""


def _worlds(tmp: Path) -> list[Path]:
    paths = [*PAPER, *EXPERIMENTS]
    for family, seed in RANDOM:
        scenario = random_scenario(family, seed, noise_std=0.01)
        paths.append(dump_scenario(scenario, tmp / f"{family}-{seed}.yaml"))
    for layout, case, visible, fov in AGENT_WORLDS:
        crowd = crowdnav_scenario(layout, case, visible=visible, fov_deg=fov)
        assert any(o.behavior == "orca" for o in crowd.obstacles)
        paths.append(dump_scenario(crowd, tmp / f"{crowd.name}.yaml"))
    return paths


def test_the_engines_agree_tick_by_tick(tmp_path: Path) -> None:
    worlds = _worlds(tmp_path)

    def both(path: Path) -> tuple[str, dict[str, Any], dict[str, Any]]:
        stack = run_scenario(path, tmp_path / "stack" / path.stem, picture=False,
                             log_level="WARNING")
        inprocess = run_scenario(path, tmp_path / "inprocess" / path.stem, picture=False,
                                 engine="inprocess", log_level="WARNING")
        return path.stem, stack, inprocess

    with ThreadPoolExecutor(2) as pool:
        runs = list(pool.map(both, worlds))
    differences = []
    for name, stack, inprocess in runs:
        assert stack["trajectory"], name
        where = first_difference(stack, inprocess)
        if where is not None:
            differences.append(f"{name}: {where}")
    assert not differences, "the engines disagree:\n" + "\n".join(differences)
    assert len(runs) == len(PAPER) + len(EXPERIMENTS) + len(RANDOM) + len(AGENT_WORLDS)
