"""``zenav paper``: the paper's experiments through the real stack, as a report.

Every run goes through ``zenav run``'s path: six processes over Zenoh, or with
``--engine inprocess`` the same services in one process (lockstep on the simulated clock
either way). The report (``report.md``) puts the measured figures beside the
paper's and links the figures drawn from each run record; every number in it is
computed from a ``run.json`` by :func:`indicators`.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from zenav import argtypes
from zenav.batch import (
    DEFAULT_VERIFY,
    Job,
    add_verify_argument,
    default_jobs,
    run_batch,
    verify_count,
)
from zenav.engine import ENGINES
from zenav.services.mission import window_radius
from zenav.sim import SCENARIO_DIR
from zenav.sim.scenario import Scenario, load_scenario

PAPER_TIMES: dict[str, tuple[float, float, float, float]] = {
    "a": (61.77, 62.00, 61.98, 61.92),
    "b": (65.48, 64.37, 63.89, 64.58),
    "c": (62.68, 62.27, 61.57, 62.17),
    "d": (62.05, 62.24, 61.94, 62.07),
    "e": (64.53, 65.02, 64.97, 64.87),
    "f": (76.12, 77.20, 76.45, 76.59),
    "g": (75.61, 76.01, 75.92, 75.85),
    "h": (77.85, 78.56, 78.97, 78.46),
}
"""Table 3 of the paper: three approach times and their mean, s."""

EIGHT = {letter: f"{letter}-" for letter in PAPER_TIMES}
SIMULATIONS = ("paper-static", "paper-dynamic", "paper-mixed")
ROBUSTNESS = "paper-robustness"
NOISE_STD = 0.01
SEEDS = (1, 2, 3)
PROFILES = ("zenav", "paper")
"""The parameter profiles the report compares (``zenav.services.profiles``)."""
PROFILE_TITLES = {"zenav": "zenav (defaults)", "paper": "paper profile"}

def indicators(record: dict[str, Any], scenario: Scenario) -> dict[str, float]:
    """The paper's performance indicators for one run, from its run record alone.

    - T: time to the outcome, s; L: path length, m;
    - mean and maximum speed, m/s (mean over the trajectory rows);
    - tracking of the global path: max and mean distance of the trajectory from the
      start-goal segment, m;
    - the minimum clearance to any obstacle, m (inf when there was none).
    """
    traj = np.asarray(record["trajectory"], dtype=np.float64)
    start = np.asarray(scenario.robot.start, dtype=np.float64)
    goal = np.asarray(scenario.robot.goal, dtype=np.float64)
    axis = goal - start
    length2 = float(axis @ axis)
    points = traj[:, 1:3]
    s = np.clip(((points - start) @ axis) / length2, 0.0, 1.0) if length2 > 0 else 0.0
    nearest = start + np.outer(s, axis)
    off = np.hypot(*(points - nearest).T)
    clearance = record["min_clearance"]
    return {
        "T": float(record["time"]),
        "L": float(record["path_length"]),
        "v_mean": float(traj[:, 4].mean()),
        "v_max": float(traj[:, 4].max()),
        "off_max": float(off.max()),
        "off_mean": float(off.mean()),
        "clearance": math.inf if clearance is None else float(clearance),
    }


def noisy_copy(source: Path, target: Path, seed: int, noise_std: float = NOISE_STD) -> Path:
    """``source`` with range noise and its own seed (the paper repeated each run 3 times)."""
    data = yaml.safe_load(source.read_text())
    data["laser"] = {**(data.get("laser") or {}), "noise_std": noise_std}
    data["seed"] = seed
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_text(yaml.safe_dump(data, sort_keys=False))
    return target


def plan_jobs(out: Path, quick: bool = False,
              profiles: tuple[str, ...] = PROFILES) -> list[Job]:
    """The runs of the report, for each profile; ``quick``: scenario (a) once, for CI.

    Keys are ``PROFILE/LETTER/seedN`` and ``PROFILE/NAME``; each run's record lands in
    ``runs/PROFILE/...``."""
    jobs = []
    letters = ["a"] if quick else list(PAPER_TIMES)
    seeds = SEEDS[:1] if quick else SEEDS
    for profile in profiles:
        for letter in letters:
            source = next(SCENARIO_DIR.glob(f"{letter}-*.yaml"))
            for seed in seeds:
                scenario = noisy_copy(source, out / "scenarios" / f"{letter}-seed{seed}.yaml",
                                      seed)
                run_dir = out / "runs" / profile / f"{letter}-seed{seed}"
                jobs.append(Job(f"{profile}/{letter}/seed{seed}", scenario, run_dir,
                                profile=profile))
        if not quick:
            for name in (*SIMULATIONS, ROBUSTNESS):
                jobs.append(Job(f"{profile}/{name}", SCENARIO_DIR / f"{name}.yaml",
                                out / "runs" / profile / name, profile=profile))
    return jobs


# --- report --------------------------------------------------------------------------


def _fmt(value: float, digits: int = 2) -> str:
    return "-" if math.isinf(value) else f"{value:.{digits}f}"


def _run_cell(record: dict[str, Any]) -> str:
    """One run in the table: its time, with the outcome when it did not reach the goal."""
    if record.get("outcome") == "error":
        return "error"
    time = f"{record['time']:.2f}"
    return time if record["outcome"] == "reached" else f"{record['outcome']} {time}"


def profile_means(records: dict[str, dict[str, Any]], profile: str,
                  seeds: tuple[int, ...]) -> dict[str, float | None]:
    """Mean time per scenario letter over the runs that reached the goal; None when any
    run of the letter did not (its mean would hide the failure)."""
    means: dict[str, float | None] = {}
    for letter in PAPER_TIMES:
        runs = [records[k] for s in seeds if (k := f"{profile}/{letter}/seed{s}") in records]
        if not runs:
            continue
        reached = all(r.get("outcome") == "reached" for r in runs)
        means[letter] = statistics.fmean(r["time"] for r in runs) if reached else None
    return means


def eight_table(records: dict[str, dict[str, Any]], seeds: tuple[int, ...],
                profiles: tuple[str, ...] = PROFILES) -> list[str]:
    """Table 3 per profile side by side (runs, mean, ratio to (a)), then the paper's."""
    head = ["scenario"]
    for profile in profiles:
        title = PROFILE_TITLES.get(profile, profile)
        head += [f"{title}: runs (s)", "mean (s)", "ratio to (a)"]
    head += ["paper's runs (s)", "paper's mean", "paper's ratio"]
    rows = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    means = {profile: profile_means(records, profile, seeds) for profile in profiles}
    for letter, paper in PAPER_TIMES.items():
        if not any(letter in means[profile] for profile in profiles):
            continue
        cells = [f"({letter})"]
        for profile in profiles:
            runs = [records[k] for s in seeds if (k := f"{profile}/{letter}/seed{s}") in records]
            mean = means[profile].get(letter)
            base = means[profile].get("a")
            cells += [" ".join(_run_cell(r) for r in runs) or "-",
                      "-" if mean is None else f"{mean:.2f}",
                      "-" if mean is None or not base else f"{mean / base:.3f}"]
        cells += [f"{paper[0]:.2f} {paper[1]:.2f} {paper[2]:.2f}", f"{paper[3]:.2f}",
                  f"{paper[3] / PAPER_TIMES['a'][3]:.3f}"]
        rows.append("| " + " | ".join(cells) + " |")
    return rows


def failures(records: dict[str, dict[str, Any]]) -> list[str]:
    """One line per run that did not reach the goal: the outcome, what it hit, and the
    planner's last decision before it (why it failed, as far as the record says)."""
    lines = []
    for key in sorted(records):
        record = records[key]
        outcome = record.get("outcome")
        if outcome == "reached":
            continue
        if outcome == "error":
            lines.append(f"- {key}: the run failed: {record.get('error', '?')}")
            continue
        hit = record.get("collided_with")
        events = [e for e in record.get("events", []) if e["t"] <= record["time"]]
        last = events[-1] if events else None
        said = "no decision" if last is None else (
            f"last decision at t = {last['t']:.1f} s: ({last['scenario']}) {last['action']}"
            f" for obstacle {last['obstacle']} ({last['kind']}), {last['detail']}")
        what = f" with obstacle {hit}" if hit is not None else ""
        lines.append(f"- {key}: {outcome}{what} at t = {record['time']:.2f} s; {said}")
    return lines


def indicator_table(
    records: dict[str, dict[str, Any]], scenarios: dict[str, Scenario]
) -> list[str]:
    rows = ["| run | outcome | T (s) | L (m) | mean speed (m/s) | max speed (m/s) | "
            "max off path (m) | mean off path (m) | min clearance (m) | decisions |",
            "|---|---|---|---|---|---|---|---|---|---|"]
    for key in sorted(records):
        record = records[key]
        if record.get("outcome") == "error":
            rows.append(f"| {key} | error | - | - | - | - | - | - | - | - |")
            continue
        ind = indicators(record, scenarios[key])
        rows.append(f"| {key} | {record['outcome']} | {ind['T']:.2f} | {ind['L']:.2f} | "
                    f"{ind['v_mean']:.3f} | {ind['v_max']:.3f} | {ind['off_max']:.2f} | "
                    f"{ind['off_mean']:.2f} | {_fmt(ind['clearance'])} | "
                    f"{len(record['events'])} |")
    return rows


def decision_list(record: dict[str, Any]) -> list[str]:
    from zenav.plot import decision_points

    return [f"- t = {t:.1f} s at ({x:.2f}, {y:.2f}): {label}"
            for t, x, y, label in decision_points(record)]


def accuracy_lines(quick: bool) -> list[str]:
    """The typing accuracy of both profiles (``zenav bench accuracy``'s table at noise
    0.01 m, one seed), one table per mover of the mixed case (D1-D4); ``quick``: D1 for
    2 s."""
    from zenav.bench.tracking_accuracy import PAPER_MOVERS, evaluate, format_table, methods

    movers = PAPER_MOVERS[:1] if quick else PAPER_MOVERS
    duration = 2.0 if quick else 6.0
    lines = ["## Typing accuracy of the two profiles", "",
             "`zenav bench accuracy` on simulated scans of the mixed case's movers D1-D4, each "
             f"with three standing obstacles (noise {NOISE_STD} m, one seed, {duration:g} s "
             "per run, robot still or driving and turning): the share of frames each obstacle "
             "is typed right, and the mover's speed and heading errors once seen for 1 s. "
             "The full table, with more seeds and noise levels and the paper profile against "
             "T, is docs/tracking-accuracy.txt.", ""]
    for number, (speed, alpha) in enumerate(movers, start=1):
        rows = evaluate(noises=(NOISE_STD,), movers=((speed, alpha),), seeds=1,
                        duration=duration, method_list=methods())
        lines += [f"D{number}: {speed * 1000:.0f} mm/s at alpha_o {alpha:g} deg", "",
                  "```", format_table(rows), "```", ""]
    return lines


def engine_lines(engine: str, verified: list[str], disagreements: list[str]) -> list[str]:
    """How the runs were made, as the report's opening says it: with the in-process
    engine, which runs were re-made through the stack and whether they agreed."""
    if engine == "inprocess":
        if not verified:
            checked = " None was re-made through the stack."
        elif not disagreements:
            checked = (f" Re-made through the full stack, {', '.join(verified)} agreed with "
                       "it tick by tick.")
        else:
            checked = (f" Re-made through the full stack, {len(disagreements)} of "
                       f"{len(verified)} DISAGREED: {'; '.join(disagreements)}.")
        return ["Times are simulated seconds. Every run went through the in-process engine",
                "(`zenav run --engine inprocess`: the six services in one process on an",
                "in-memory bus, every message through the codec, lockstep on the simulated",
                f"clock); each number below is computed from that run's `run.json`.{checked}"]
    return ["Times are simulated seconds. Every run went through the full service stack",
            "(six processes over Zenoh on loopback, lockstep on the simulated clock); each",
            "number below is computed from that run's `run.json` (in `runs/PROFILE/`)."]


def write_report(out: Path, jobs: list[Job], records: dict[str, dict[str, Any]],
                 machine: str, wall: float, accuracy: list[str] | None = None,
                 engine: str = "stack", command: str = "",
                 verified: tuple[list[str], list[str]] = ([], [])) -> Path:
    """``verified``: the keys re-made through the stack and where any disagreed."""
    scenarios = {job.key: load_scenario(job.scenario) for job in jobs}
    seeds = tuple(s for s in SEEDS if any(k.endswith(f"seed{s}") for k in records))
    profiles = tuple(dict.fromkeys(job.profile for job in jobs))
    failed = failures(records)
    lines = [
        "# zenav: the paper's experiments",
        "",
        f"Produced by `{command or f'zenav paper --out {out}'}` on {machine} in {wall:.0f} s "
        "of wall time.",
        *engine_lines(engine, *verified),
        "",
        f"Profiles: {', '.join(PROFILE_TITLES.get(p, p) for p in profiles)}. The paper "
        "profile runs Section 3 as written (Eq. 3 alone, the decision tree and Eq. 15 "
        "over T, (e) when robot and crosser reach the PCP at the same time, Eq. 17's three "
        "terms, Algorithm 1's one threat per cycle and V_R - dV_R); `zenav params NAME "
        "--profile paper` lists what it changes.",
        "",
        "## The eight scenarios: time to the goal",
        "",
        f"Start to goal 6 m, V_R = 0.1 m/s, range noise {NOISE_STD} m, seeds "
        f"{', '.join(map(str, seeds))}. The paper's Table 3 beside. A run that did not "
        "reach the goal shows its outcome; its scenario then has no mean.",
        "",
        *eight_table(records, seeds, profiles),
        "",
    ]
    if failed:
        lines += ["Runs that did not reach the goal, and the planner's last word before:", "",
                  *failed, ""]
    for name in (*SIMULATIONS, ROBUSTNESS):
        for profile in profiles:
            key = f"{profile}/{name}"
            if key not in records or records[key].get("outcome") == "error":
                continue
            record = records[key]
            figure = f"{profile}-{name}"
            lines += [f"## {name}: {PROFILE_TITLES.get(profile, profile)}", "",
                      f"Outcome: {record['outcome']} at t = {record['time']:.2f} s.", "",
                      f"![{key}](figures/{figure}.png)", "",
                      f"Animation: [figures/{figure}.gif](figures/{figure}.gif)", "",
                      "Decisions:", "", *decision_list(record), ""]
    lines += accuracy or []
    lines += ["## Performance indicators of every run", "",
              *indicator_table(records, scenarios), ""]
    path = out / "report.md"
    path.write_text("\n".join(lines))
    (out / "records.json").write_text(json.dumps(
        {k: {"outcome": r["outcome"], "time": r.get("time"), "run": str(j.out / "run.json")}
         for j in jobs for k, r in records.items() if k == j.key}, indent=1))
    return path


def make_figures(out: Path, jobs: list[Job], records: dict[str, dict[str, Any]]) -> None:
    from zenav.plot import draw_animation, draw_experiment

    figures = out / "figures"
    figures.mkdir(parents=True, exist_ok=True)
    for job in jobs:
        name = job.key.split("/", 1)[1]
        record = records[job.key]
        if name not in (*SIMULATIONS, ROBUSTNESS) or record.get("outcome") == "error":
            continue
        scenario = load_scenario(job.scenario)
        window = window_radius(scenario.world.cell, scenario.laser.max_range)
        figure = f"{job.profile}-{name}"
        draw_experiment(scenario, record, figures / f"{figure}.png", window, job.key)
        draw_animation(scenario, record, figures / f"{figure}.gif", window)


def machine_description() -> str:
    import os
    import platform

    from zenav.bench.common import cpu_model

    return f"{os.cpu_count()} cores ({cpu_model()}), Python {platform.python_version()}"


def main(out: Path, quick: bool = False, parallel: int = 2,
         profiles: tuple[str, ...] = PROFILES, reuse: bool = False, engine: str = "stack",
         verify: int = DEFAULT_VERIFY) -> Path:
    """Run the experiments with a progress bar, draw the figures, write the report.
    ``reuse``: a run whose ``run.json`` is already in ``out`` is not run again."""
    import time

    from rich.progress import (
        BarColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    started = time.monotonic()
    jobs = plan_jobs(out, quick, profiles)
    with Progress(TextColumn("[bold]zenav paper"), BarColumn(), TextColumn("{task.completed}/"
                  "{task.total} runs"), TextColumn("{task.description}"),
                  TimeElapsedColumn(), TimeRemainingColumn()) as progress:
        task = progress.add_task("", total=len(jobs))
        finished: list[bool] = []

        def done(job: Job, record: dict[str, Any]) -> None:
            finished.append(record["outcome"] == "reached")
            progress.update(task, advance=1, description=f"{sum(finished)}/{len(finished)} "
                            f"reached; {job.key}")

        # keep_going: a run that fails is a result of the report, not the end of it
        records = run_batch(jobs, parallel, done, keep_going=True, reuse=reuse, engine=engine,
                            verify=verify)
        # The bar counts runs; the steps after them only name themselves.
        progress.update(task, description="figures")
        make_figures(out, jobs, records)
        progress.update(task, description="typing accuracy")
        accuracy = accuracy_lines(quick)
        progress.update(task, description="report")
    command = f"zenav paper --out {out}" + ("" if engine == "stack" else
                                             f" --engine {engine} --verify {verify}")
    if profiles != PROFILES:
        command += f" --profile {profiles[0]}"
    return write_report(out, jobs, records, machine_description(), time.monotonic() - started,
                        accuracy, engine=engine, command=command + (" --quick" if quick else ""),
                        verified=(records.verified, records.disagreements))


def _command(args: argparse.Namespace) -> int:
    from zenav.run import RunError

    profiles = PROFILES if args.profile == "both" else (args.profile,)
    try:
        if args.parallel < 1:
            raise ValueError(f"--jobs must be >= 1 (got {args.parallel})")
        verify = verify_count(args.engine, args.verify)
    except ValueError as exc:
        print(f"zenav paper: {exc}", file=sys.stderr)
        return 2
    try:
        report = main(args.out, quick=args.quick, parallel=args.parallel, profiles=profiles,
                      reuse=args.reuse, engine=args.engine, verify=verify)
    except RunError as exc:
        print(f"zenav paper: {exc}", file=sys.stderr)
        return 1
    print(f"report: {report}")
    return 0


def add_command(sub: Any) -> None:
    paper = sub.add_parser("paper", help="reproduce the paper's experiments as a report")
    paper.add_argument("--out", type=argtypes.path, default=Path("out/paper"),
                       help="report directory (default out/paper)")
    paper.add_argument("--quick", action="store_true",
                       help="scenario (a) once per profile only (a smoke test of the report)")
    paper.add_argument("--jobs", "--parallel", dest="parallel", type=int,
                       default=default_jobs(), help="runs at once (default: the cores)")
    paper.add_argument("--profile", choices=("both", *PROFILES), default="both",
                       help="parameter profile(s) to run: both (default, side by side), "
                            "zenav or paper")
    paper.add_argument("--reuse", action="store_true",
                       help="take a run.json already under --out as that run's record "
                            "(finish or redraw an interrupted report)")
    paper.add_argument("--engine", choices=ENGINES, default="stack",
                       help="stack (default): six processes over Zenoh per run; inprocess: "
                       "the same services in one process per run, worker processes in parallel")
    add_verify_argument(paper)
    paper.set_defaults(func=_command)
