"""The in-process engine's loop clock: it stands still while there is work and jumps
when there is none, so no timeout in a lockstep run depends on this machine's speed."""

from __future__ import annotations

import asyncio
import time
from pathlib import Path
from typing import Any

import pytest

from zenav.engine import IdleClockLoop, first_difference, read_back
from zenav.launch import write_params
from zenav.services.config import SERVICE_ORDER, load_params
from zenav.services.mission import stack_params
from zenav.services.runner import service_params
from zenav.sim import SCENARIO_DIR
from zenav.sim.scenario import load_scenario


async def _slow_answer(timeout: float) -> bool:
    """True when an answer that takes 0.3 s of wall time arrives within ``timeout``."""
    answered = asyncio.Event()

    async def work() -> None:
        await asyncio.sleep(0)
        time.sleep(0.3)  # a slow step of the pipeline (this machine is loaded)
        for _ in range(3):  # the next services' turns
            await asyncio.sleep(0)
        answered.set()

    task = asyncio.create_task(work())
    try:
        await asyncio.wait_for(answered.wait(), timeout)
        return True
    except TimeoutError:
        return False
    finally:
        await task


def test_a_slow_step_is_no_timeout_on_the_idle_clock() -> None:
    with asyncio.Runner(loop_factory=IdleClockLoop) as runner:
        assert runner.run(_slow_answer(0.1))


def test_the_same_slow_step_times_out_on_the_wall_clock() -> None:
    assert not asyncio.run(_slow_answer(0.1))  # what the engine's loop must avoid


def test_an_idle_loop_jumps_to_its_next_timer() -> None:
    async def sleep_an_hour() -> float:
        loop = asyncio.get_running_loop()
        before = loop.time()
        await asyncio.sleep(3600)
        return loop.time() - before

    started = time.monotonic()
    with asyncio.Runner(loop_factory=IdleClockLoop) as runner:
        assert runner.run(sleep_an_hour()) == pytest.approx(3600)
    assert time.monotonic() - started < 5


def test_a_timeout_fires_when_nothing_can_answer() -> None:
    async def never() -> bool:
        try:
            await asyncio.wait_for(asyncio.Event().wait(), 30.0)
        except TimeoutError:
            return True
        return False

    with asyncio.Runner(loop_factory=IdleClockLoop) as runner:
        assert runner.run(never())


@pytest.mark.parametrize("service", SERVICE_ORDER)
def test_parameters_are_read_back_as_a_service_process_reads_them(service: str,
                                                                  tmp_path: Path) -> None:
    path = SCENARIO_DIR / "h-mixed.yaml"
    params = stack_params(load_scenario(path), path, "paper")
    as_process = load_params(service_params(service),
                             [write_params(tmp_path, service, params[service])], [])
    assert read_back(service, params[service]) == as_process


def test_first_difference_names_the_row_the_event_or_the_field() -> None:
    rows = [[0.0, 1.0, 2.0, 0.0, 0.0], [0.1, 1.1, 2.0, 0.0, 0.1]]
    record: dict[str, Any] = {"trajectory": rows, "events": [{"t": 0.0, "action": "keep"}],
                              "outcome": "reached", "wall_time": 1.0}
    assert first_difference(record, {**record, "wall_time": 5.0, "engine": "inprocess"}) is None
    moved = {**record, "trajectory": [rows[0], [0.1, 1.1, 2.0, 0.0, 0.2]]}
    assert first_difference(record, moved) == ("trajectory row 1: stack [0.1, 1.1, 2.0, 0.0, "
                                               "0.1] vs in-process [0.1, 1.1, 2.0, 0.0, 0.2]")
    other_event = {**record, "events": [{"t": 0.0, "action": "stop"}]}
    where = first_difference(record, other_event)
    assert where is not None and where.startswith("event 0: ")
    assert first_difference(record, {**record, "outcome": "timeout"}) == (
        "outcome: stack 'reached' vs in-process 'timeout'")
