"""A finer grid than the paper's 0.5 m does not shrink the sliding window: the window is
8 cells but never less than the paper's 4 m (``services.mission.window_radius``). With
8 cells alone, 0.1 m cells left a 0.8 m window, and a head-on mover came within reach of
the robot before it was in view. Through the six services on the in-memory bus."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from tests.service.variants import run_variant


@pytest.mark.parametrize("scene", ["f-head-on", "nav-corridor-blind-overtaker"])
def test_a_fine_grid_keeps_the_movers_in_view_in_time(scene: str, tmp_path: Path) -> None:
    def finer(data: dict[str, Any]) -> None:
        data["world"]["cell"] = 0.1

    record, gap = run_variant(scene, finer, tmp_path)
    assert record["outcome"] == "reached", (record["outcome"], record["time"])
    assert gap > 0.0
