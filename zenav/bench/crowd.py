"""``zenav bench crowd``: CrowdNav's test protocol, every planner, every setting.

Settings are {circle, square} crossing x {invisible, visible} humans x {180°, 360°}
laser (:mod:`zenav.sim.crowdnav` writes the cases as scenario files: case k is CrowdNav's
test case k). Each (setting, case, planner) is one run through an *engine*: ``stack``
(``zenav run``'s path through :mod:`zenav.batch`, six processes over Zenoh) or any engine
registered in :data:`ENGINES` (``inprocess``, the default, plugs in here),
``--jobs`` at a time; a run whose ``run.json`` is already in ``--out`` is not repeated.

Columns are CrowdNav's: success, collision and timeout rates, the mean time to goal of
the successes, and the discomfort frequency: the fraction of all time steps (simulator
ticks, over every run of the row) in which the robot's disc was within 0.2 m of a
human's (surface to surface), computed from the run record's trajectory and agents rows.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path
from typing import Any

import numpy as np

from zenav import argtypes
from zenav.batch import (
    DEFAULT_VERIFY,
    Job,
    Records,
    add_verify_argument,
    run_batch,
    verified_note,
    verify_count,
)
from zenav.bench.common import machine, words
from zenav.bench.nav import NO_WAY_OUT, UNWARNED, collision_kind
from zenav.sim.crowdnav import (
    DISCOMFORT,
    HUMAN_RADIUS,
    ROBOT_RADIUS,
    Layout,
    check_cases,
    crowdnav_scenario,
)
from zenav.sim.scenario import dump_scenario, load_scenario

__all__ = ["ENGINES", "SETTINGS", "Setting", "discomfort_steps", "run_crowd", "summarise"]

Record = dict[str, Any]
OnDone = Callable[[Job, Record], None]
Engine = Callable[[Sequence[Job], int, OnDone, bool, int], Records]
"""(jobs, runs at a time, called as each run ends, reuse, verify) -> the records by job
key. A run that fails gives a record with outcome ``error``; with ``reuse``, a
``run.json`` already in a run's directory is its record; ``verify``: how many in-process
runs are made again through the stack and compared (the stack engine has none to check)."""


@dataclass(frozen=True)
class Setting:
    layout: Layout  # circle | square
    visible: bool
    fov_deg: int  # 180 | 360

    @property
    def name(self) -> str:
        return f"{self.layout}-{'visible' if self.visible else 'invisible'}-{self.fov_deg}"

    @property
    def title(self) -> str:
        return (f"{self.layout} crossing, {'visible' if self.visible else 'invisible'} humans, "
                f"laser {self.fov_deg}°")


SETTINGS: dict[str, Setting] = {
    s.name: s for s in (Setting(layout, visible, fov)
                        for layout in ("circle", "square") for visible in (False, True)
                        for fov in (180, 360))
}
PLANNERS = ("paper", "vfh", "dwa", "apf", "orca")


def stack_engine(jobs: Sequence[Job], parallel: int, on_done: OnDone,
                 reuse: bool = False, verify: int = 0) -> Records:
    """Every job through ``zenav run``'s path (the whole service stack, lockstep);
    ``verify`` is unused (these runs are the stack's)."""
    return run_batch(jobs, parallel, on_done, log_level="WARNING", reuse=reuse,
                     keep_going=True)


def inprocess_engine(jobs: Sequence[Job], parallel: int, on_done: OnDone,
                     reuse: bool = False, verify: int = DEFAULT_VERIFY) -> Records:
    """Every job with the in-process engine (``zenav run --engine inprocess``) in worker
    processes; a seeded sample of ``verify`` jobs is then re-made through the stack and
    compared tick by tick (:func:`zenav.batch.run_batch`)."""
    return run_batch(jobs, parallel, on_done, log_level="WARNING", reuse=reuse,
                     keep_going=True, engine="inprocess", picture=False, verify=verify)


ENGINES: dict[str, Engine] = {"stack": stack_engine, "inprocess": inprocess_engine}
"""Engines by name."""


def discomfort_steps(record: Record, robot_radius: float = ROBOT_RADIUS,
                     human_radius: float = HUMAN_RADIUS,
                     distance: float = DISCOMFORT) -> tuple[int, int]:
    """(ticks with the robot within ``distance`` m of a human, surface to surface; ticks)."""
    trajectory = np.asarray(record["trajectory"], dtype=np.float64).reshape(-1, 5)
    agents = record.get("agents") or {}
    if not agents or not len(trajectory):
        return 0, len(trajectory)
    paths = np.stack([np.asarray(rows, dtype=np.float64).reshape(-1, 3)
                      for rows in agents.values()])  # (humans, ticks, 3)
    if paths.shape[1] != len(trajectory):
        raise ValueError(f"{record.get('scenario')}: agents rows ({paths.shape[1]}) are not "
                         f"at the trajectory's ticks ({len(trajectory)})")
    gaps = np.hypot(paths[:, :, 1] - trajectory[None, :, 1],
                    paths[:, :, 2] - trajectory[None, :, 2]) - robot_radius - human_radius
    return int((gaps.min(axis=0) < distance).sum()), len(trajectory)


@dataclass
class Row:
    planner: str
    runs: int
    errors: int
    success: float
    collision: float
    timeout: float
    time_to_goal: float  # mean over the successes, s
    discomfort: float  # fraction of ticks
    collisions: int = 0
    unwarned: int = 0  # collisions no scan could have warned of (``nav.no_warning``)
    no_way_out: int = 0  # the others that left no way out once seen (``escape.no_escape``)

    def cells(self) -> list[str]:
        def rate(x: float) -> str:
            return "—" if math.isnan(x) else f"{x:.2f}"

        errors = f" (+{self.errors} failed)" if self.errors else ""
        time_text = "—" if math.isnan(self.time_to_goal) else f"{self.time_to_goal:.2f}"
        return [self.planner, f"{self.runs}{errors}", rate(self.success), rate(self.collision),
                rate(self.timeout), time_text, rate(self.discomfort)]


def summarise(records: Sequence[Record], planners: Sequence[str]) -> list[Row]:
    """One row per planner over ``records`` (one setting)."""
    rows = []
    for planner in planners:
        mine = [r for r in records if r.get("planner") == planner]
        valid = [r for r in mine if r["outcome"] != "error"]
        n = len(valid)
        counts = {o: sum(r["outcome"] == o for r in valid)
                  for o in ("reached", "collision", "timeout")}
        times = [r["time"] for r in valid if r["outcome"] == "reached"]
        close = total = 0
        for r in valid:
            c, t = discomfort_steps(r)
            close, total = close + c, total + t
        rows.append(Row(planner=planner, runs=n, errors=len(mine) - n,
                        success=counts["reached"] / n if n else math.nan,
                        collision=counts["collision"] / n if n else math.nan,
                        timeout=counts["timeout"] / n if n else math.nan,
                        time_to_goal=statistics.fmean(times) if times else math.nan,
                        discomfort=close / total if total else math.nan,
                        collisions=counts["collision"],
                        unwarned=sum(r.get("hit") == UNWARNED for r in valid),
                        no_way_out=sum(r.get("hit") == NO_WAY_OUT for r in valid)))
    return rows


def collisions_line(rows: Sequence[Row], visible: bool) -> str:
    """One line under a setting's table: each planner's collisions, those no scan could
    have warned of, and (humans blind to the robot) those that left no way out."""
    parts = []
    for r in rows:
        if not r.collisions:
            continue
        part = f"{r.planner} {r.collisions} ({r.unwarned} never in view before the contact"
        parts.append(part + ("" if visible else f", {r.no_way_out} with no way out once "
                             "seen") + ")")
    if not parts:
        return "No collisions."
    why = ("" if not visible else " Humans who see the robot walk as it moves, so whether "
           "it had a way out is not judged here.")
    return ("Collisions: " + "; ".join(parts) + ". Never in view: the human's centre was "
            "never within the laser's field and range (occlusion aside); no way out: "
            "standing, or any heading at the robot's top speed, in open space with the "
            "human's path known, touched it (`zenav.bench.escape`)." + why)


HEADER = ("| planner | runs | success | collision | timeout | time to goal s | discomfort |\n"
          "|---|---|---|---|---|---|---|")


def table(rows: Sequence[Row]) -> str:
    return "\n".join([HEADER, *("| " + " | ".join(r.cells()) + " |" for r in rows)])


def plot(results: dict[str, list[Row]], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(results)
    planners = [r.planner for r in next(iter(results.values()))] if results else []
    fig, ax = plt.subplots(figsize=(max(6.0, 1.3 * len(names) + 2), 4.5))
    width = 0.8 / max(len(planners), 1)
    for i, planner in enumerate(planners):
        values = [next(r.success for r in results[s] if r.planner == planner) for s in names]
        ax.bar([k + i * width for k in range(len(names))],
               [0.0 if math.isnan(v) else v for v in values], width=width, label=planner)
    ax.set_xticks([k + width * (len(planners) - 1) / 2 for k in range(len(names))])
    ax.set_xticklabels(names, rotation=20, ha="right", fontsize=8)
    ax.set_ylim(0, 1.05)
    ax.set_ylabel("success rate")
    ax.set_title("CrowdNav protocol: success per setting and planner")
    ax.legend(loc="lower right", fontsize="small")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write_cases(settings: Sequence[str], cases: int, seed: int,
                directory: Path) -> dict[str, list[tuple[int, Path]]]:
    """The scenario files, per setting: case numbers seed .. seed + cases - 1."""
    written: dict[str, list[tuple[int, Path]]] = {}
    for name in settings:
        s = SETTINGS[name]
        folder = directory / name
        folder.mkdir(parents=True, exist_ok=True)
        written[name] = []
        for case in range(seed, seed + cases):
            scenario = crowdnav_scenario(s.layout, case, visible=s.visible,
                                         fov_deg=float(s.fov_deg))
            path = folder / f"{case}.yaml"
            written[name].append((case, dump_scenario(scenario, path)))
    return written


def check(planners: Sequence[str], settings: Sequence[str], cases: int, engine: str,
          jobs: int) -> None:
    """Refuse bad arguments with one line naming the problem (ValueError)."""
    from zenav.services.runner import PLANNERS as KNOWN

    unknown = [p for p in planners if p not in KNOWN]
    if unknown or not planners:
        raise ValueError(f"unknown planner {', '.join(unknown) or '(none given)'}; choose "
                         f"from {', '.join(KNOWN)}")
    bad = [s for s in settings if s not in SETTINGS]
    if bad or not settings:
        raise ValueError(f"unknown setting {', '.join(bad) or '(none given)'}; choose from "
                         f"{', '.join(SETTINGS)}")
    if engine not in ENGINES:
        raise ValueError(f"unknown engine {engine!r}; choose from {', '.join(ENGINES)}")
    if cases < 1:
        raise ValueError(f"--cases must be >= 1 (got {cases})")
    if jobs < 1:
        raise ValueError(f"--jobs must be >= 1 (got {jobs})")


def run_crowd(planners: Sequence[str], out: Path, *, cases: int = 500, seed: int = 0,
              settings: Sequence[str] = tuple(SETTINGS), jobs: int = 2, engine: str = "inprocess",
              progress: bool = True, reuse: bool = False, verify: int = DEFAULT_VERIFY,
              echo: Callable[[str], None] = print) -> str:
    """Write the cases, run them, print and write ``crowd.md``, ``crowd.png``, ``crowd.json``.
    ``reuse``: a run whose ``run.json`` is already under ``out`` is not run again (its
    wall time is then not the sweep's). ``verify``: in-process runs made again through
    the stack and compared tick by tick; the report says whether they agree."""
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    check(planners, settings, cases, engine, jobs)
    out.mkdir(parents=True, exist_ok=True)
    written = write_cases(settings, cases, seed, out / "cases")
    job_list = [Job(f"{name}/{p}/{case}", path, out / "runs" / name / p / str(case), planner=p)
                for name in settings for case, path in written[name] for p in planners]
    records: dict[str, list[Record]] = {name: [] for name in settings}
    reached = 0
    started = time.monotonic()
    with Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                  TimeElapsedColumn(), TextColumn("left"), TimeRemainingColumn(),
                  disable=not progress) as bar:
        task = bar.add_task("zenav bench crowd", total=len(job_list))

        def done(job: Job, record: Record) -> None:
            nonlocal reached
            record.setdefault("scenario", job.name)
            record["planner"] = job.planner
            if record["outcome"] == "collision":
                record["hit"] = collision_kind(load_scenario(job.scenario), record)
            records[job.key.split("/", 1)[0]].append(record)
            reached += record["outcome"] == "reached"
            finished = sum(len(v) for v in records.values())
            bar.update(task, advance=1, description=f"{finished} done, {reached} reached")

        batch = ENGINES[engine](job_list, jobs, done, reuse, verify)
    wall = time.monotonic() - started
    for name in settings:
        for r in records[name]:
            if r["outcome"] == "error":
                echo(f"run failed: {name} {r['planner']} {r.get('scenario')}: {r.get('error')}")
    results = {name: summarise(records[name], planners) for name in settings}
    command = (f"zenav bench crowd --cases {cases} --planners {','.join(planners)} "
               f"--seed {seed} --jobs {jobs} --engine {engine}"
               + ("" if tuple(settings) == tuple(SETTINGS) else
                  f" --settings {','.join(settings)}") + (" --reuse" if reuse else "")
               + ("" if engine == "stack" or verify == DEFAULT_VERIFY else f" --verify {verify}"))
    parts = [f"# zenav bench crowd\n\n`{command}`\n\n"
             f"{datetime.now().astimezone():%Y-%m-%d %H:%M %Z}, {machine()}; "
             f"{len(job_list)} runs ({cases} cases x {len(planners)} planners x "
             f"{len(settings)} settings, CrowdNav test cases {seed}..{seed + cases - 1}), "
             f"engine {engine}{verified_note(batch)}, {jobs} at a time, "
             f"wall time {wall / 60:.1f} min\n\n"
             "Success, collision and timeout are fractions of the runs; time to goal is "
             "the mean over the successes; discomfort is the fraction of simulator ticks "
             "with the robot within 0.2 m of a human (surface to surface).\n"]
    for name in settings:
        parts.append(f"\n## {SETTINGS[name].title}\n\n{table(results[name])}\n\n"
                     f"{collisions_line(results[name], SETTINGS[name].visible)}\n")
    report = "".join(parts)
    (out / "crowd.md").write_text(report)
    (out / "crowd.json").write_text(json.dumps(
        {"command": command, "wall_s": round(wall, 1), "verified": batch.verified,
         "disagreements": batch.disagreements,
         "settings": {n: [{k: (None if isinstance(v, float) and math.isnan(v) else v)
                           for k, v in vars(r).items()} for r in rows]
                      for n, rows in results.items()},
         "runs": {n: [{k: v for k, v in r.items() if k not in ("trajectory", "agents")}
                      for r in records[n]] for n in settings}}, indent=1))
    plot(results, out / "crowd.png")
    echo(report)
    echo(f"wrote {out / 'crowd.md'}, {out / 'crowd.png'}, {out / 'crowd.json'}")
    return report


def _command(args: argparse.Namespace) -> int:
    try:
        check_cases(args.seed, args.cases)
        verify = verify_count(args.engine, args.verify)
        run_crowd(words(args.planners), args.out, cases=args.cases, seed=args.seed,
                  settings=words(args.settings), jobs=args.jobs, engine=args.engine,
                  progress=not args.no_progress, reuse=args.reuse, verify=verify)
    except ValueError as exc:
        print(f"zenav bench crowd: {exc}", file=sys.stderr)
        return 2
    return 0


def add_command(kinds: Any) -> None:
    """``zenav bench crowd`` (``kinds``: the subcommands of ``zenav bench``)."""
    crowd = kinds.add_parser("crowd", help="CrowdNav's protocol (circle and square crossing, "
                             "invisible and visible humans, 180° and 360° laser)")
    crowd.add_argument("--cases", type=int, default=500,
                       help="CrowdNav test cases per setting (default 500, CrowdNav's)")
    crowd.add_argument("--planners", default=",".join(PLANNERS),
                       help=f"comma-separated planner names (default {','.join(PLANNERS)})")
    crowd.add_argument("--settings", default=",".join(SETTINGS),
                       help="comma-separated settings LAYOUT-VISIBILITY-FOV (default all "
                       f"eight: {','.join(SETTINGS)})")
    crowd.add_argument("--seed", type=argtypes.non_negative_int, default=0,
                       help="first CrowdNav test case (default 0)")
    crowd.add_argument("--jobs", type=int, default=os.cpu_count() or 1,
                       help="runs at a time (default: the number of cores; with the stack "
                       "engine each run is six processes)")
    crowd.add_argument("--engine", choices=ENGINES, default="inprocess",
                       help=f"how each run is made: {', '.join(ENGINES)} (default "
                       "inprocess: the services in one process per run, --verify cases made "
                       "again through the stack and compared; stack: every run through "
                       "zenav run's six processes)")
    add_verify_argument(crowd)
    crowd.add_argument("--out", type=argtypes.path, default=Path("out/bench-crowd"),
                       help="directory for the cases, runs, crowd.md, crowd.png, crowd.json "
                       "(default out/bench-crowd)")
    crowd.add_argument("--reuse", action="store_true",
                       help="take a run.json already under --out as that run's record "
                       "(finish an interrupted sweep; by default every run is made again)")
    crowd.add_argument("--no-progress", action="store_true", help="no progress bar")
    crowd.set_defaults(func=_command)
