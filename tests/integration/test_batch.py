"""The batch runner's in-process sweeps: worker processes, the stack re-making a sample
of the runs, and Ctrl-C stopping every worker at once."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import psutil
import pytest

from tests.integration.livestack import sigint_as_usual
from zenav.batch import Job, run_batch, sample
from zenav.sim import SCENARIO_DIR

pytestmark = pytest.mark.integration


def test_an_inprocess_sweep_is_verified_by_the_stack(tmp_path: Path) -> None:
    paths = [SCENARIO_DIR / "c-crosser-passes-first.yaml",
             SCENARIO_DIR / "d-crosser-arrives-after.yaml"]
    jobs = [Job(p.stem, p, tmp_path / p.stem) for p in paths]
    seen: list[str] = []
    records = run_batch(jobs, 2, lambda job, record: seen.append(job.key), engine="inprocess",
                        verify=1, picture=False, log_level="WARNING", echo=seen.append)
    assert sorted(records) == sorted(job.key for job in jobs)
    assert all(r["outcome"] == "reached" and r["engine"] == "inprocess"
               for r in records.values())
    assert records.verified == [sample(jobs, 1)[0].key]
    assert records.disagreements == []
    assert any(line.startswith("verified: 1 runs") for line in seen)
    assert (tmp_path / records.verified[0] / "stack-check" / "run.json").exists()


def test_ctrl_c_stops_the_workers_within_a_second(tmp_path: Path) -> None:
    command = [sys.executable, "-m", "zenav", "bench", "nav", "--planners", "paper",
               "--worlds", "40", "--families", "static", "--jobs", "2", "--verify", "0",
               "--no-progress", "--out", str(tmp_path)]
    with sigint_as_usual():
        proc = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    parent = psutil.Process(proc.pid)
    deadline = time.monotonic() + 120
    while len(parent.children(recursive=True)) < 3:  # the forkserver and two workers
        assert proc.poll() is None, proc.stderr.read() if proc.stderr else ""
        assert time.monotonic() < deadline, "the workers did not start"
        time.sleep(0.2)
    family = parent.children(recursive=True)
    time.sleep(2.0)  # the workers are in their runs (40 worlds: a minute of work)
    assert proc.poll() is None, "the benchmark ended before Ctrl-C was sent"
    sent = time.monotonic()
    proc.send_signal(signal.SIGINT)

    def running() -> list[psutil.Process]:
        alive = []
        for child in family:
            try:
                if child.status() != psutil.STATUS_ZOMBIE:
                    alive.append(child)
            except psutil.NoSuchProcess:
                pass
        return alive

    while running() and time.monotonic() - sent < 10:
        time.sleep(0.05)
    stopped = time.monotonic() - sent
    proc.wait(timeout=30)
    exited = time.monotonic() - sent
    print(f"zenav-measure ctrl-c: workers gone after {stopped:.2f} s, the command after "
          f"{exited:.2f} s")
    assert not running(), f"still running {stopped:.1f} s after Ctrl-C: {running()}"
    assert stopped < 2.0  # within a second on a quiet machine; this one is shared
    assert proc.returncode != 0
