"""A scene of ``sim/scenarios/`` changed by hand, run through the six services on the
in-memory bus (``zenav run --engine inprocess``) and judged on ground truth."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import yaml

from zenav.run import run_scenario
from zenav.sim import SCENARIO_DIR
from zenav.sim.contact import clearance
from zenav.sim.scenario import load_scenario
from zenav.sim.world import World


def run_variant(scene: str, edit: Callable[[dict[str, Any]], None],
                tmp_path: Path) -> tuple[dict[str, Any], float]:
    """The run record of ``scene`` with ``edit`` applied to its file's data, and the least
    gap between the robot disc and any obstacle over the run, from the scenario itself."""
    data = yaml.safe_load((SCENARIO_DIR / f"{scene}.yaml").read_text())
    edit(data)
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(data))
    record = run_scenario(path, tmp_path / "out", engine="inprocess", picture=False)
    scenario = load_scenario(path)
    world = World.from_scenario(scenario)
    gap = min(clearance((row[1], row[2]), scenario.robot.radius, world.snapshot(row[0]))
              for row in record["trajectory"])
    return record, gap
