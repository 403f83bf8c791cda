"""The floor section's arithmetic: which scans count, what a ring's ticks come to, and
what the table says is left for the services."""

from __future__ import annotations

import math

import pytest

from zenav.bench.floor import RingResult, chain_intervals, floor_table, main


def test_each_scan_counts_from_its_receive_to_its_base_commands():
    scans = {0: 10.0, 1: 10.1, 2: 10.2}
    commands = {0: 10.0015, 1: 10.102, 2: 10.2025}
    assert chain_intervals(scans, commands, settle=0.0) == pytest.approx([1.5, 2.0, 2.5])


def test_scans_before_the_links_settled_and_scans_without_a_command_are_left_out():
    # The first scan through (seq 3) starts the settling; seq 4 comes 0.5 s after it, seq
    # 14 1.1 s after; seq 15 lost its command; 0-2 never got through (links not up yet).
    scans = {i: 10.0 + 0.1 * i for i in range(16)}
    commands = {i: t + 0.002 for i, t in scans.items() if 3 <= i <= 14}
    kept = chain_intervals(scans, commands, settle=1.0)
    assert kept == pytest.approx([2.0] * 2)  # seqs 13 and 14 only


def test_no_scan_through_the_chain_gives_no_interval():
    assert chain_intervals({0: 1.0, 1: 1.1}, {}) == []


def test_a_ring_of_ticks_in_real_time_at_ten_hertz():
    ring = RingResult(ticks=1000, wall=2.0)  # 500 ticks/s: 2 ms each, 50 s simulated in 1 s
    assert ring.per_tick_ms == pytest.approx(2.0)
    assert ring.real_time == pytest.approx(50.0)
    assert math.isnan(RingResult(0, 1.0).per_tick_ms)


def test_the_table_says_what_each_target_leaves_for_the_services():
    text = floor_table([1.0, 1.5, 2.0], [0.7], RingResult(1000, 4.0), 2.0, 50.0)
    assert "| 1.50 ms median |" in text
    assert "| 0.70 ms median |" in text
    assert "The asyncio loop's hand-off, as the services take their inputs: 0.20 ms a hop." in text
    assert "4.00 ms a tick: 25.0× real time at 10 Hz" in text
    assert "within the latency target: 0.50 ms of 2 ms (median)" in text
    # 50x is 2 ms a tick at 10 Hz, already spent twice over by the hops alone
    assert "at 50×, 2.00 ms a tick: nothing, the hops alone take more." in text
    assert "at 20×, 5.00 ms a tick: 1.00 ms." in floor_table([1.0], [1.0],
                                                            RingResult(1000, 4.0), 2.0, 20.0)


def test_a_relay_with_a_role_not_in_its_mode_refuses_to_start(capsys):
    assert main(["simulator", "chain", "7000", "1"]) == 2
    assert "no role 'simulator'" in capsys.readouterr().err
