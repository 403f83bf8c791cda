"""``zenav bench nav --fov``: the same worlds, each seen by a laser of the field of view
asked for, everything else of the world unchanged."""

from __future__ import annotations

from pathlib import Path

from zenav.bench.nav import write_worlds
from zenav.sim.scenario import load_scenario


def test_fov_changes_only_the_laser(tmp_path: Path) -> None:
    own = write_worlds(["crossing", "crowd"], 2, 7, tmp_path / "own")
    wide = write_worlds(["crossing", "crowd"], 2, 7, tmp_path / "wide", fov_deg=360.0)
    assert [p.name for p in own] == [p.name for p in wide]
    for a, b in zip(own, wide, strict=True):
        before, after = load_scenario(a), load_scenario(b)
        assert before.laser.fov_deg == 180.0
        assert after.laser.fov_deg == 360.0
        assert after.laser.beam_count == 721
        assert after.model_dump(exclude={"laser"}) == before.model_dump(exclude={"laser"})
        assert (after.laser.model_dump(exclude={"fov_deg"})
                == before.laser.model_dump(exclude={"fov_deg"}))
