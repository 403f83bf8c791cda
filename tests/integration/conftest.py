"""Measured figures of the deployment tests (stop time after link loss, restart time after
kill -9, ...), printed in a section of pytest's summary so that they can be quoted."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

MEASURED: list[str] = []

HERE = Path(__file__).resolve().parent


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Everything in this folder is of the process tier, marked or not: a module that
    forgets ``pytestmark`` must not slip into the fast tier (``-m "not integration"``)."""
    for item in items:
        if HERE in Path(str(item.fspath)).resolve().parents:
            item.add_marker(pytest.mark.integration)


@pytest.fixture
def measure(request: pytest.FixtureRequest) -> Callable[[str, float, str], None]:
    """``measure(name, seconds, detail)``: note one figure for the summary."""
    test = request.node.name

    def note(name: str, seconds: float, detail: str = "") -> None:
        line = f"{name}: {seconds:.3f} s{f'  ({detail})' if detail else ''}  [{test}]"
        MEASURED.append(line)
        print(f"zenav-measure {line}")

    return note


def pytest_terminal_summary(terminalreporter: pytest.TerminalReporter) -> None:
    if MEASURED:
        terminalreporter.section("zenav measurements")
        for line in MEASURED:
            terminalreporter.write_line(line)


BUSY_LOOPS = 2
"""CPU burners a loaded-machine test runs beside the stack (one per core here)."""


@pytest.fixture
def busy_machine() -> Iterator[list[subprocess.Popen[bytes]]]:
    """Two busy-loop processes for the length of the test: recovery figures taken on a
    machine that has other work to do. Each ends by itself after 15 minutes, should the
    test's own teardown never run."""
    burners = [subprocess.Popen([sys.executable, "-c",
                                 "import time\nend = time.monotonic() + 900\n"
                                 "while time.monotonic() < end: pass"],
                                stdin=subprocess.DEVNULL)
               for _ in range(BUSY_LOOPS)]
    try:
        yield burners
    finally:
        for burner in burners:
            burner.kill()
            burner.wait(timeout=10)
