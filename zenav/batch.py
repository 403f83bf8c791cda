"""One batch runner: many scenario runs through ``zenav run``'s path, a few at a time.

Each job is :func:`zenav.run.run_scenario` (six service processes over Zenoh, lockstep on
the simulated clock) in a worker thread, with its ``run.json`` and ``run.png`` in the
job's own directory. ``zenav paper`` and ``zenav bench nav`` run their jobs here.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from zenav.run import run_scenario
from zenav.sim.scenario import load_scenario


@dataclass(frozen=True)
class Job:
    """One run: a scenario file, the planner, the directory for its record."""

    key: str  # how the batch names it, e.g. "a/seed1" or "paper/static-3"
    scenario: Path
    out: Path
    planner: str = "paper"
    profile: str = "zenav"  # the parameter profile (zenav.services.profiles)

    @property
    def name(self) -> str:
        return self.scenario.stem


def error_record(job: Job, error: str) -> dict[str, Any]:
    """The record of a run that failed: outcome ``error`` and the one-line reason."""
    return {"scenario": job.name, "planner": job.planner, "outcome": "error", "error": error}


def run_job(job: Job, *, log_level: str = "INFO", reuse: bool = False,
            keep_going: bool = False) -> dict[str, Any]:
    """One run; its record. ``reuse``: a ``run.json`` already in ``job.out`` is the record.
    ``keep_going``: a failed run gives an :func:`error_record` instead of raising."""
    record_path = job.out / "run.json"
    if reuse and record_path.exists():
        reused: dict[str, Any] = json.loads(record_path.read_text())
        return reused
    try:
        record = run_scenario(job.scenario, job.out, planner=job.planner, log_level=log_level,
                              picture=False, profile=job.profile)
    except Exception as exc:
        if not keep_going:
            raise
        return error_record(job, (str(exc).strip().splitlines() or [type(exc).__name__])[-1])
    from zenav.plot import plot_run  # matplotlib is slow to import; only here

    plot_run(load_scenario(job.scenario), record, job.out / "run.png")
    return record


def run_batch(jobs: Iterable[Job], parallel: int,
              on_done: Callable[[Job, dict[str, Any]], None] | None = None, *,
              log_level: str = "INFO", reuse: bool = False,
              keep_going: bool = False) -> dict[str, dict[str, Any]]:
    """Run every job, ``parallel`` at a time; the records by job key. ``on_done`` is
    called (in this thread) as each job ends; for the options see :func:`run_job`."""
    records: dict[str, dict[str, Any]] = {}
    with ThreadPoolExecutor(max(1, parallel)) as pool:
        futures = {pool.submit(run_job, job, log_level=log_level, reuse=reuse,
                               keep_going=keep_going): job for job in jobs}
        for future in as_completed(futures):
            job = futures[future]
            record = future.result()
            records[job.key] = record
            if on_done is not None:
                on_done(job, record)
    return records
