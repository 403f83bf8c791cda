"""The latency bench's hop-by-hop split: each service's interval from the receive times
the bench's listener files by stamp."""

from __future__ import annotations

import pytest

from zenav.bench.latency import STAGES, LatencyResult, latency_table, stage_intervals


def _path(times: dict[float, list[float]]) -> list[dict[float, float]]:
    """Receive times by stamp for the six topics of the scan's path."""
    return [{s: row[i] for s, row in times.items() if i < len(row)} for i in range(6)]


def test_each_service_gets_its_input_to_output_interval():
    path = _path({0.1: [10.000, 10.001, 10.003, 10.004, 10.010, 10.011],
                  0.2: [20.000, 20.002, 20.004, 20.006, 20.009, 20.010]})
    stages = stage_intervals(path)
    assert list(stages) == list(STAGES)
    assert stages["laser_driver"] == pytest.approx([1.0, 2.0])
    assert stages["perception"] == pytest.approx([2.0, 2.0])
    assert stages["tracking"] == pytest.approx([1.0, 2.0])
    assert stages["planner"] == pytest.approx([6.0, 3.0])
    assert stages["motor_bridge"] == pytest.approx([1.0, 1.0])


def test_scans_without_a_base_command_are_left_out():
    # 0.2 never reached the motor bridge's output: it counts in no row.
    path = _path({0.1: [1.0, 1.001, 1.002, 1.003, 1.004, 1.005],
                  0.2: [2.0, 2.001, 2.002, 2.003, 2.004]})
    assert all(len(values) == 1 for values in stage_intervals(path).values())


def test_the_table_has_one_row_per_service_and_the_target_verdict():
    stages = {name: [1.0, 2.0] for name in STAGES}
    text = latency_table(LatencyResult(2, [1.5, 1.8], [1.0, 1.2], {}, stages))
    assert "median ≤ 2 ms (met)" in text
    for name in STAGES:
        assert f"| {name} (" in text


def test_lockstep_table_splits_the_command_and_judges_both_targets():
    from zenav.bench.lockstep import LockstepRow, lockstep_table

    rows = [LockstepRow("a", "reached", 60.0, 1.0, 2.5, 1.2),
            LockstepRow("b", "reached", 40.0, 1.0, 2.5, 1.0)]
    text = lockstep_table(rows)
    # 100 simulated s in 2 s of loop (50x, met) and 5 s of command (20x, not met)
    assert "| **all** | | 100.0 | 2.2 | 2.0 | **50.0** | 5.0 | **20.0** |" in text
    assert "measured 50.0× (met)" in text
    assert "measured 20.0× (NOT met)" in text
