"""One batch runner: many scenario runs through ``zenav run``'s path, several at a time.

Each job is :func:`zenav.run.run_scenario` with its ``run.json`` (and ``run.png``) in the
job's own directory, on one of two engines:

- ``stack``: six service processes over Zenoh per run; jobs run in worker threads
  (each run is already its own processes).
- ``inprocess``: the same services in one process (:mod:`zenav.engine`); jobs run in a
  pool of worker processes (forkserver), one run at a time per worker, each run seeded
  from its scenario file only. A seeded sample of ``verify`` jobs is then run again
  through the stack and the two records compared tick by tick; any disagreement is
  printed loudly and kept in :attr:`Records.disagreements`.

``zenav paper``, ``zenav bench nav`` (and the crowd benchmark) run their jobs here. Ctrl-C
stops the worker processes at once (they ignore SIGINT and are killed).
"""

from __future__ import annotations

import dataclasses
import json
import multiprocessing
import os
import random
import signal
import sys
import threading
from collections.abc import Callable, Iterable
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from zenav.engine import ENGINES, first_difference
from zenav.run import run_scenario

DEFAULT_VERIFY = 3
"""In-process jobs re-run through the stack to show the two engines agree."""


def add_verify_argument(parser: Any) -> None:
    """``--verify K`` of the commands that run batches (``paper``, ``bench nav``,
    ``bench crowd``); read it with ``verify_count``."""
    parser.add_argument("--verify", type=int, default=None, metavar="K",
                        help="with --engine inprocess: K in-process runs re-made through the "
                        f"stack and compared tick by tick (default {DEFAULT_VERIFY})")


def verify_count(engine: str, verify: int | None) -> int:
    """How many runs to verify: ``--verify`` as given, or the default. ValueError (one
    line) for a negative count, or a count given with the stack engine, whose runs are
    all stack runs already (it used to be accepted there and do nothing)."""
    if verify is None:
        return DEFAULT_VERIFY
    if verify < 0:
        raise ValueError(f"--verify must be >= 0 (got {verify})")
    if engine != "inprocess":
        raise ValueError("--verify checks --engine inprocess against the stack; with "
                         "--engine stack every run is a stack run already")
    return verify


def default_jobs() -> int:
    """Runs at a time unless told: the cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, os.cpu_count() or 1)


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


class Records(dict[str, dict[str, Any]]):
    """The records by job key, and what the stack said of the sample re-run through it."""

    def __init__(self) -> None:
        super().__init__()
        self.verified: list[str] = []  # job keys re-run through the stack
        self.disagreements: list[str] = []  # "key: where the records part"


def verified_note(records: Records) -> str:
    """What the stack said of the in-process runs it re-made, for a report's header."""
    if not records.verified:
        return ""
    if records.disagreements:
        return (f"; {len(records.disagreements)} of {len(records.verified)} runs re-made "
                f"through the stack DISAGREE")
    return f"; {len(records.verified)} runs re-made through the stack agree tick by tick"


def error_record(job: Job, error: str) -> dict[str, Any]:
    """The record of a run that failed: outcome ``error`` and the one-line reason."""
    return {"scenario": job.name, "planner": job.planner, "outcome": "error", "error": error}


def run_job(job: Job, *, log_level: str = "INFO", reuse: bool = False,
            keep_going: bool = False, engine: str = "stack",
            picture: bool = True, stop: threading.Event | None = None) -> dict[str, Any]:
    """One run; its record. ``reuse``: a ``run.json`` already in ``job.out`` is the record.
    ``keep_going``: a failed run gives an :func:`error_record` instead of raising.
    ``picture``: draw ``run.png`` too. ``stop`` (stack): set, the run ends at once with
    KeyboardInterrupt, its processes stopped (see :func:`zenav.run.run_scenario`)."""
    record_path = job.out / "run.json"
    if reuse and record_path.exists():
        reused: dict[str, Any] = json.loads(record_path.read_text())
        return reused
    try:
        # run_scenario draws run.png itself: it has the planner's last map to draw.
        if stop is not None and stop.is_set():
            raise KeyboardInterrupt  # the batch is stopping: start no more runs
        record = run_scenario(job.scenario, job.out, planner=job.planner, log_level=log_level,
                              picture=picture, profile=job.profile, engine=engine,
                              stop=stop)
    except Exception as exc:
        if not keep_going:
            raise
        return error_record(job, (str(exc).strip().splitlines() or [type(exc).__name__])[-1])
    return record


def _worker_start() -> None:
    """A worker process leaves Ctrl-C to the parent, which terminates the pool."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def stop_workers(pool: ProcessPoolExecutor) -> None:
    """Kill the pool's worker processes now (they ignore SIGINT) and drop what is queued."""
    processes = list((getattr(pool, "_processes", None) or {}).values())
    for process in processes:
        process.kill()
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        process.join(timeout=1.0)


def _run_threads(jobs: list[Job], parallel: int, options: dict[str, Any],
                 done: Callable[[Job, dict[str, Any]], None]) -> None:
    """Stack jobs, each in a thread of its own (each run is its own processes). Ctrl-C
    (or a failed job) sets the runs' ``stop``: the runs under way end within a tenth of
    a second, their stacks torn down, and the queued ones never start."""
    stop = threading.Event()
    threads = ThreadPoolExecutor(max(1, parallel))
    try:
        futures = {threads.submit(run_job, job, stop=stop, **options): job for job in jobs}
        for future in as_completed(futures):
            done(futures[future], future.result())
    except BaseException:
        stop.set()
        threads.shutdown(wait=True, cancel_futures=True)
        raise
    threads.shutdown(wait=True)


def sample(jobs: list[Job], count: int, seed: int = 0) -> list[Job]:
    """``count`` of ``jobs`` chosen by ``seed`` (the same jobs for the same list)."""
    return random.Random(seed).sample(jobs, min(count, len(jobs)))


def verify_with_stack(jobs: list[Job], records: dict[str, dict[str, Any]], parallel: int,
                      *, log_level: str = "WARNING") -> tuple[list[str], list[str]]:
    """Run ``jobs`` again through the stack (records in ``OUT/stack-check``); the keys
    checked and, for each that disagrees with ``records``, where the records part."""
    checked: list[str] = []
    disagreements: list[str] = []
    candidates = [job for job in jobs if records.get(job.key, {}).get("outcome") != "error"]

    stop = threading.Event()  # Ctrl-C: the re-runs under way end, their stacks stopped

    def again(job: Job) -> tuple[Job, dict[str, Any]]:
        redo = dataclasses.replace(job, out=job.out / "stack-check")
        return job, run_job(redo, log_level=log_level, keep_going=True, picture=False,
                            stop=stop)

    pool = ThreadPoolExecutor(max(1, parallel))
    try:
        for job, stack in pool.map(again, candidates):
            checked.append(job.key)
            if stack["outcome"] == "error":
                disagreements.append(f"{job.key}: the stack run failed: {stack.get('error')}")
                continue
            where = first_difference(stack, records[job.key])
            if where is not None:
                disagreements.append(f"{job.key}: {where}")
    except BaseException:
        stop.set()
        pool.shutdown(wait=True, cancel_futures=True)
        raise
    pool.shutdown(wait=True)
    return checked, disagreements


def run_batch(jobs: Iterable[Job], parallel: int,
              on_done: Callable[[Job, dict[str, Any]], None] | None = None, *,
              log_level: str = "INFO", reuse: bool = False, keep_going: bool = False,
              engine: str = "stack", verify: int = DEFAULT_VERIFY, verify_seed: int = 0,
              picture: bool = True, echo: Callable[[str], None] | None = None) -> Records:
    """Run every job, ``parallel`` at a time; the records by job key. ``on_done`` is
    called (in this thread) as each job ends; for the options see :func:`run_job`.
    With ``engine="inprocess"``, ``verify`` jobs (chosen by ``verify_seed``) are re-run
    through the stack afterwards; disagreements go to ``echo`` (stderr by default)."""
    if engine not in ENGINES:
        raise ValueError(f"unknown engine {engine!r}; choose from {', '.join(ENGINES)}")
    job_list = list(jobs)
    records = Records()
    options: dict[str, Any] = {"log_level": log_level, "reuse": reuse,
                               "keep_going": keep_going, "engine": engine, "picture": picture}

    def done(job: Job, record: dict[str, Any]) -> None:
        records[job.key] = record
        if on_done is not None:
            on_done(job, record)

    if engine == "stack":
        _run_threads(job_list, parallel, options, done)
        return records
    context = multiprocessing.get_context("forkserver" if sys.platform != "win32" else "spawn")
    pool = ProcessPoolExecutor(max(1, parallel), mp_context=context, initializer=_worker_start)
    try:
        futures = {pool.submit(run_job, job, **options): job for job in job_list}
        for future in as_completed(futures):
            done(futures[future], future.result())
    except BaseException:
        stop_workers(pool)  # Ctrl-C or a failed job: no worker outlives the batch
        raise
    pool.shutdown(wait=True)
    if verify > 0:
        say = echo or (lambda text: print(text, file=sys.stderr))
        chosen = sample(job_list, verify, verify_seed)
        records.verified, records.disagreements = verify_with_stack(
            chosen, records, parallel, log_level="WARNING")
        if records.disagreements:
            say("!" * 72)
            say(f"ENGINES DISAGREE on {len(records.disagreements)} of "
                f"{len(records.verified)} runs re-made through the stack:")
            for line in records.disagreements:
                say(f"  {line}")
            say("!" * 72)
        else:
            say(f"verified: {len(records.verified)} runs re-made through the stack agree "
                f"tick by tick ({', '.join(records.verified)})")
    return records
