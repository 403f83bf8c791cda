"""A service and its warm spare (``--standby-lock``): one serves, the other waits on the
lock and takes over the moment the first ends, kill -9 included."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

HOLD = ("import logging, sys, time\nfrom pathlib import Path\n"
        "from zenav.services.runner import take_over\n"
        "logging.basicConfig(stream=sys.stdout, level='INFO', format='%(message)s')\n"
        "take_over(Path(sys.argv[1]), 'planner')\nprint('serving', flush=True)\ntime.sleep(120)")


def holder(lock: Path) -> subprocess.Popen[str]:
    return subprocess.Popen([sys.executable, "-c", HOLD, str(lock)], stdout=subprocess.PIPE,
                            stderr=subprocess.DEVNULL, text=True, stdin=subprocess.DEVNULL)


def test_the_spare_takes_over_when_the_serving_process_is_killed(tmp_path: Path) -> None:
    lock = tmp_path / "standby" / "planner.lock"
    first = holder(lock)
    second = None
    try:
        assert first.stdout is not None and first.stdout.readline() == "serving\n"
        assert lock.read_text() == f"{first.pid}\n"
        second = holder(lock)
        assert second.stdout is not None
        assert second.stdout.readline() == ("standby: another process serves planner; taking "
                                            "over when it ends\n")
        os.kill(first.pid, signal.SIGKILL)
        first.wait(timeout=30)
        assert second.stdout.readline() == "standby: taking over planner\n"
        assert second.stdout.readline() == "serving\n"
        assert lock.read_text() == f"{second.pid}\n"
    finally:
        for proc in (first, second):
            if proc is not None and proc.poll() is None:
                proc.kill()
                proc.wait()


def test_a_waiting_spare_ends_on_sigterm_and_the_server_goes_on(tmp_path: Path) -> None:
    lock = tmp_path / "planner.lock"
    first = holder(lock)
    second = None
    try:
        assert first.stdout is not None and first.stdout.readline() == "serving\n"
        second = holder(lock)
        assert second.stdout is not None
        assert second.stdout.readline().startswith("standby: another process serves planner")
        second.send_signal(signal.SIGTERM)
        assert second.wait(timeout=30) == -signal.SIGTERM
        assert second.stdout.read() == ""  # it never served
        assert first.poll() is None and lock.read_text() == f"{first.pid}\n"
    finally:
        for proc in (first, second):
            if proc is not None and proc.poll() is None:
                proc.kill()
                proc.wait()
