"""``nav-corridor-sealed-head-on`` made by another hand: a faster robot (0.5 m/s) and a
slower laser (5 Hz). In both, the robot stood at its spot aside, found the walker would
still walk into it, and took a new spot across the walker's line, behind it, timed at
the cruise speed; it backs there at the motor bridge's 0.1 m/s and was hit on the way.
Such a spot is now timed at the reverse limit (``give_way.spot_aside``'s ``backing``).
Through the six services on the in-memory bus, judged on ground truth."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from tests.service.variants import run_variant


@pytest.mark.parametrize(("section", "key", "value"),
                         [("robot", "speed", 0.5), ("laser", "rate_hz", 5)])
def test_the_sealed_corridor_is_passed_with_another_speed_or_scan_rate(
        section: str, key: str, value: Any, tmp_path: Path) -> None:
    def changed(data: dict[str, Any]) -> None:
        data.setdefault(section, {})[key] = value

    record, gap = run_variant("nav-corridor-sealed-head-on", changed, tmp_path)
    assert record["outcome"] == "reached", (record["outcome"], record["time"])
    assert gap > 0.0
    assert any(e["action"] == "give_way" for e in record["events"])
