"""The report's opening says how its runs were made and what the stack said of them."""

from __future__ import annotations

from zenav.paper import engine_lines


def test_the_stack() -> None:
    assert "six processes over Zenoh" in " ".join(engine_lines("stack", [], []))


def test_the_in_process_engine_and_its_check() -> None:
    agreed = " ".join(engine_lines("inprocess", ["paper/a/seed1", "zenav/e/seed2"], []))
    assert "in-process engine" in agreed
    assert "paper/a/seed1, zenav/e/seed2 agreed" in agreed
    parted = " ".join(engine_lines("inprocess", ["paper/a/seed1", "zenav/e/seed2"],
                                   ["zenav/e/seed2: trajectory row 10"]))
    assert "1 of 2 DISAGREED: zenav/e/seed2: trajectory row 10" in parted
    assert "None was re-made" in " ".join(engine_lines("inprocess", [], []))
