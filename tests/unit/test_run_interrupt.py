"""A run stopped by Ctrl-C (or by its batch) is an interruption, never a failure of the
run, and a service killed by a signal is said to be so."""

from __future__ import annotations

import asyncio
import math
import subprocess
import sys
import threading
import time
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from zenav import run
from zenav.launch import Stack, ended
from zenav.schemas.codec import encode
from zenav.schemas.messages import RunResult


def test_how_a_process_ended_names_the_signal_that_killed_it() -> None:
    assert ended(0) == "exited with status 0"
    assert ended(2) == "exited with status 2"
    assert ended(-9) == "was killed by signal 9 (SIGKILL)"
    assert ended(-2) == "was killed by signal 2 (SIGINT)"
    assert ended(-200) == "was killed by signal 200"


def test_a_killed_service_is_reported_as_killed(tmp_path: Path) -> None:
    stack = Stack(out_dir=tmp_path, params={}, base_port=20000)
    proc = subprocess.Popen([sys.executable, "-c", "import os, signal\n"
                             "os.kill(os.getpid(), signal.SIGKILL)"])
    proc.wait(timeout=30)
    stack.processes["planner"] = proc
    assert stack.failure() == "service planner was killed by signal 9 (SIGKILL)"


class FakeBus:
    """The little of ZenohBus that _collect uses before every service is up."""

    closed = False

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        pass

    def watch_liveliness(self, key: str, callback: Any) -> None:
        pass

    def close(self) -> None:
        FakeBus.closed = True


class FakeStack:
    robot_id = "robot0"
    services = ("simulator", "planner")
    out_dir = Path("/nonexistent")

    def __init__(self, failure: str | None) -> None:
        self._failure = failure

    def failure(self) -> str | None:
        return self._failure

    def transport(self, driver: bool = False) -> None:
        return None


@pytest.fixture
def fake_bus(monkeypatch: pytest.MonkeyPatch) -> None:
    FakeBus.closed = False
    monkeypatch.setattr(run, "ZenohBus", FakeBus)


def collect(stack: FakeStack, stop: threading.Event | None) -> Any:
    return asyncio.run(run._collect(stack, 30.0, stop=stop))  # type: ignore[arg-type]


@pytest.mark.usefixtures("fake_bus")
def test_a_service_stopped_by_the_same_ctrl_c_is_an_interruption_not_a_failure() -> None:
    stack = FakeStack("service simulator was killed by signal 2 (SIGINT): KeyboardInterrupt")
    with pytest.raises(run.RunError, match="killed by signal 2"):
        collect(stack, None)
    stop = threading.Event()
    stop.set()
    with pytest.raises(KeyboardInterrupt):
        collect(stack, stop)
    assert FakeBus.closed


@pytest.mark.usefixtures("fake_bus")
def test_a_run_waiting_on_its_services_ends_when_its_batch_stops_it() -> None:
    stop = threading.Event()
    timer = threading.Timer(0.3, stop.set)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            collect(FakeStack(None), stop)  # without stop: 30 s of waiting
    finally:
        timer.cancel()
    assert FakeBus.closed


class AnsweredBus(FakeBus):
    """A bus on which every service is up and the simulator's result is in, and whose
    event history query hangs as one to a planner being stopped does (up to 5 s)."""

    asked = threading.Event()

    def watch_liveliness(self, key: str, callback: Any) -> None:
        for service in FakeStack.services:
            callback(f"{key[:-1]}{service}", True)

    def subscribe(self, key: str, depth: int = 1) -> Any:
        result = RunResult(stamp=9.0, seq=0, scenario="s", outcome="reached", time=9.0,
                           path_length=1.0, min_clearance=math.inf,
                           trajectory=np.zeros((1, 5)))

        class Sub:
            async def get(self) -> tuple[str, bytes]:
                return key, encode(result)

            def pending(self) -> bool:
                return False

        return Sub()

    def latest(self, key: str) -> Any:
        return SimpleNamespace(take=lambda: None)

    def declare_token(self, key: str) -> Any:
        return SimpleNamespace(undeclare=lambda: None)

    async def query(self, selector: str, timeout: float = 2.0) -> list[tuple[str, bytes]]:
        AnsweredBus.asked.set()
        await asyncio.sleep(timeout)
        return []


def test_a_run_waiting_for_the_planners_event_history_ends_when_stopped(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(run, "ZenohBus", AnsweredBus)
    AnsweredBus.asked.clear()
    stop = threading.Event()

    def stop_once_asked() -> None:
        if AnsweredBus.asked.wait(30):
            stop.set()

    threading.Thread(target=stop_once_asked).start()
    began = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        collect(FakeStack(None), stop)  # without stop: the query's 5 s
    assert AnsweredBus.asked.is_set()
    assert time.monotonic() - began < 4.0
