"""A run stopped by Ctrl-C (or by its batch) is an interruption, never a failure of the
run, and a service killed by a signal is said to be so."""

from __future__ import annotations

import asyncio
import subprocess
import sys
import threading
from pathlib import Path
from typing import Any

import pytest

from zenav import run
from zenav.launch import Stack, ended


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
