"""The accuracy benchmark runs, and the zenav profile meets the targets on a simple case."""

from __future__ import annotations

from types import ModuleType
from typing import Any

import pytest

from zenav.bench import tracking_accuracy


def load_bench() -> ModuleType:
    return tracking_accuracy


def test_smoothed_estimate_meets_the_targets_at_noise_0_01() -> None:
    bench: Any = load_bench()
    smoothed = [m for m in bench.methods() if m.name == "zenav"]
    rows = bench.evaluate(
        noises=(0.01,),
        motions=("moving",),
        movers=((0.76, 62.47),),
        seeds=1,
        duration=4.0,
        method_list=smoothed,
    )
    (row,) = rows
    assert row.acc_static >= bench.TARGET_ACCURACY
    assert row.acc_dynamic >= bench.TARGET_ACCURACY
    assert row.speed_p95 <= bench.TARGET_SPEED_REL
    assert row.heading_p95 <= bench.TARGET_HEADING_DEG


def test_main_prints_the_table(capsys: pytest.CaptureFixture[str]) -> None:
    bench: Any = load_bench()
    assert bench.main(["--seeds", "1", "--duration", "1.5", "--no-per-mover"]) == 0
    out = capsys.readouterr().out
    assert "zenav" in out and "paper" in out and ">=95%" in out
    assert out.count("moving") >= 6  # 3 noises x 2 profiles


def test_the_table_against_t(capsys: pytest.CaptureFixture[str]) -> None:
    bench: Any = load_bench()
    assert bench.main(["--seeds", "1", "--duration", "1.5", "--compare-periods", "0.1,1"]) == 0
    out = capsys.readouterr().out
    assert "T=0.1s" in out and "T=1s" in out
    assert out.count("moving") == 2  # noise 0.01 only, one row per T
    with pytest.raises(SystemExit):
        bench.main(["--compare-periods", "soon"])
