"""Ctrl-C on ``zenav run`` and ``zenav paper`` (stack engine): status 130 within 3 s, no
traceback, and no service process left behind, whether the signal reaches the command
only (``kill -INT PID``) or its whole process group (a terminal's Ctrl-C). SIGTERM to the
command alone (``timeout``, a supervisor) ends it by that signal, its services stopped."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

from tests.integration.livestack import sigint_as_usual

REPO = Path(__file__).resolve().parents[2]
SCENARIO = REPO / "sim" / "scenarios" / "a-no-obstacle.yaml"


def long_run(folder: Path) -> Path:
    """Scenario (a) stretched to a 60 m crossing: ``zenav run`` runs it at some 15x real
    time, so the whole run (6 s of wall time for the 6 m original on a quiet machine) lasts
    far longer than the latest Ctrl-C sent here, however fast the machine."""
    data = yaml.safe_load(SCENARIO.read_text())
    data["world"]["size"] = [64.0, 6.0]
    data["robot"]["goal"] = [62.0, 3.0]
    data["duration"] = 900
    path = folder / "long-crossing.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def interrupt(argv: list[str], after: float, group: bool, cwd: Path,
              sig: signal.Signals = signal.SIGINT) -> tuple[int, float, str]:
    """Start ``zenav ARGV``, send ``sig`` after ``after`` s; (status, s to stop, stderr)."""
    with sigint_as_usual():
        proc = subprocess.Popen([sys.executable, "-m", "zenav", *argv], cwd=cwd,
                                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                                start_new_session=True)
    time.sleep(after)
    assert proc.poll() is None, f"zenav {argv[0]} ended before Ctrl-C was sent"
    sent = time.monotonic()
    if group:
        os.killpg(proc.pid, sig)
    else:
        proc.send_signal(sig)
    try:
        _, err = proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        _, err = proc.communicate()
    return proc.returncode, time.monotonic() - sent, err


def services_of(out: Path) -> list[str]:
    """Service processes still running with parameter files under ``out``."""
    found = subprocess.run(["pgrep", "-af", f"zenav service .*{out}"], capture_output=True,
                           text=True, check=False)
    return found.stdout.splitlines()


@pytest.mark.parametrize(("after", "group"), [(0.8, True), (1.5, True), (1.5, False),
                                              (4.0, False)])
def test_zenav_run_stops_on_ctrl_c_with_130(tmp_path: Path, after: float, group: bool) -> None:
    out = tmp_path / "out"
    code, took, err = interrupt(["run", str(long_run(tmp_path)), "--out", str(out)], after,
                                group, tmp_path)
    assert code == 130, err
    assert "Traceback" not in err and "exited with status" not in err, err
    assert took < 3.0
    time.sleep(0.5)
    assert services_of(out) == []


def test_zenav_run_stops_its_services_on_sigterm(tmp_path: Path) -> None:
    out = tmp_path / "out"
    code, took, err = interrupt(["run", str(long_run(tmp_path)), "--out", str(out)], 4.0,
                                False, tmp_path, signal.SIGTERM)
    assert code == -signal.SIGTERM, err
    assert "Traceback" not in err, err
    assert took < 3.0
    time.sleep(0.5)
    assert services_of(out) == []


def test_zenav_paper_stops_its_runs_on_ctrl_c(tmp_path: Path) -> None:
    out = tmp_path / "paper"
    code, took, err = interrupt(["paper", "--out", str(out)], 6.0, False, tmp_path)
    assert code == 130, err
    assert "Traceback" not in err, err
    assert took < 3.0
    time.sleep(0.5)
    assert services_of(out) == []
