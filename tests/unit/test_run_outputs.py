"""A run into a folder that holds an earlier run's outputs replaces them all: no folder
mixes two runs' record, recording, parameter files and logs."""

from __future__ import annotations

import json
from pathlib import Path

from zenav.cli import main as zenav_main

REPO = Path(__file__).resolve().parents[2]
SCENARIO = REPO / "sim" / "scenarios" / "a-no-obstacle.yaml"


def test_a_second_run_into_the_same_folder_leaves_nothing_of_the_first(tmp_path: Path) -> None:
    out = tmp_path / "out"
    stale = [out / "run.mcap", out / "params" / "simulator.yaml", out / "logs" / "planner.log",
             out / "run.json"]
    for path in stale:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text("from an earlier run\n")
    mine = out / "notes.txt"
    mine.write_text("the user's own\n")
    assert zenav_main(["run", str(SCENARIO), "--engine", "inprocess", "--out", str(out)]) == 0
    assert not any(path.exists() for path in stale[:3])
    assert json.loads((out / "run.json").read_text())["outcome"] == "reached"
    assert (out / "logs" / "engine.log").exists()
    assert mine.read_text() == "the user's own\n"
