"""``zenav paper``: the paper's experiments through the real stack, as a report.

Every run goes through ``zenav run``'s path (six processes over Zenoh, lockstep on the
simulated clock). The report (``report.md``) puts the measured figures beside the
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

from zenav.batch import Job, run_batch
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


def plan_jobs(out: Path, quick: bool = False) -> list[Job]:
    """The runs of the report; ``quick``: scenario (a) once, for CI."""
    jobs = []
    letters = ["a"] if quick else list(PAPER_TIMES)
    seeds = SEEDS[:1] if quick else SEEDS
    for letter in letters:
        source = next(SCENARIO_DIR.glob(f"{letter}-*.yaml"))
        for seed in seeds:
            scenario = noisy_copy(source, out / "scenarios" / f"{letter}-seed{seed}.yaml", seed)
            run_dir = out / "runs" / f"{letter}-seed{seed}"
            jobs.append(Job(f"{letter}/seed{seed}", scenario, run_dir))
    if not quick:
        for name in (*SIMULATIONS, ROBUSTNESS):
            jobs.append(Job(name, SCENARIO_DIR / f"{name}.yaml", out / "runs" / name))
    return jobs


# --- report --------------------------------------------------------------------------


def _fmt(value: float, digits: int = 2) -> str:
    return "-" if math.isinf(value) else f"{value:.{digits}f}"


def eight_table(records: dict[str, dict[str, Any]], seeds: tuple[int, ...]) -> list[str]:
    rows = ["| scenario | run 1 | run 2 | run 3 | mean (s) | ratio to (a) | paper runs (s) | "
            "paper mean | paper ratio |",
            "|---|---|---|---|---|---|---|---|---|"]
    means: dict[str, float] = {}
    for letter in PAPER_TIMES:
        times = [records[f"{letter}/seed{s}"]["time"] for s in seeds
                 if f"{letter}/seed{s}" in records]
        if times:
            means[letter] = statistics.fmean(times)
    base = means.get("a")
    for letter, mean in means.items():
        times = [records[f"{letter}/seed{s}"]["time"] for s in seeds]
        cells = [f"{t:.2f}" for t in times] + [""] * (3 - len(times))
        paper = PAPER_TIMES[letter]
        ratio = mean / base if base else math.nan
        outcomes = {records[f"{letter}/seed{s}"]["outcome"] for s in seeds}
        note = "" if outcomes == {"reached"} else f" ({', '.join(sorted(outcomes))})"
        rows.append(f"| ({letter}){note} | {' | '.join(cells)} | {mean:.2f} | {ratio:.3f} | "
                    f"{paper[0]:.2f} {paper[1]:.2f} {paper[2]:.2f} | {paper[3]:.2f} | "
                    f"{paper[3] / PAPER_TIMES['a'][3]:.3f} |")
    return rows


def indicator_table(
    records: dict[str, dict[str, Any]], scenarios: dict[str, Scenario]
) -> list[str]:
    rows = ["| run | outcome | T (s) | L (m) | mean speed (m/s) | max speed (m/s) | "
            "max off path (m) | mean off path (m) | min clearance (m) | decisions |",
            "|---|---|---|---|---|---|---|---|---|---|"]
    for key in sorted(records):
        record = records[key]
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


def write_report(out: Path, jobs: list[Job], records: dict[str, dict[str, Any]],
                 machine: str, wall: float) -> Path:
    scenarios = {job.key: load_scenario(job.scenario) for job in jobs}
    seeds = tuple(s for s in SEEDS if any(k.endswith(f"seed{s}") for k in records))
    lines = [
        "# zenav: the paper's experiments",
        "",
        f"Produced by `zenav paper --out {out}` on {machine} in {wall:.0f} s of wall time.",
        "Times are simulated seconds. Every run went through the full service stack",
        "(six processes over Zenoh on loopback, lockstep on the simulated clock); each",
        "number below is computed from that run's `run.json` (in `runs/`).",
        "",
        "## The eight scenarios: time to the goal",
        "",
        f"Start to goal 6 m, V_R = 0.1 m/s, range noise {NOISE_STD} m, seeds "
        f"{', '.join(map(str, seeds))}. The paper's Table 3 beside.",
        "",
        *eight_table(records, seeds),
        "",
    ]
    for name in (*SIMULATIONS, ROBUSTNESS):
        if name not in records:
            continue
        record = records[name]
        lines += [f"## {name}", "", f"![{name}](figures/{name}.png)", "",
                  f"Animation: [figures/{name}.gif](figures/{name}.gif)", "",
                  "Decisions:", "", *decision_list(record), ""]
    lines += ["## Performance indicators of every run", "",
              *indicator_table(records, scenarios), ""]
    path = out / "report.md"
    path.write_text("\n".join(lines))
    (out / "records.json").write_text(json.dumps(
        {k: {"outcome": r["outcome"], "time": r["time"], "run": str(j.out / "run.json")}
         for j in jobs for k, r in records.items() if k == j.key}, indent=1))
    return path


def make_figures(out: Path, jobs: list[Job], records: dict[str, dict[str, Any]]) -> None:
    from zenav.plot import draw_animation, draw_experiment

    figures = out / "figures"
    figures.mkdir(parents=True, exist_ok=True)
    for job in jobs:
        if job.key not in (*SIMULATIONS, ROBUSTNESS):
            continue
        scenario = load_scenario(job.scenario)
        window = window_radius(scenario.world.cell, scenario.laser.max_range)
        record = records[job.key]
        draw_experiment(scenario, record, figures / f"{job.key}.png", window, job.key)
        draw_animation(scenario, record, figures / f"{job.key}.gif", window)


def machine_description() -> str:
    import os
    import platform

    from zenav.bench.common import cpu_model

    return f"{os.cpu_count()} cores ({cpu_model()}), Python {platform.python_version()}"


def main(out: Path, quick: bool = False, parallel: int = 2) -> Path:
    """Run the experiments with a progress bar, draw the figures, write the report."""
    import time

    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    started = time.monotonic()
    jobs = plan_jobs(out, quick)
    with Progress(TextColumn("[bold]zenav paper"), BarColumn(), TextColumn("{task.completed}/"
                  "{task.total} runs"), TextColumn("{task.description}"),
                  TimeElapsedColumn()) as progress:
        task = progress.add_task("", total=len(jobs) + 1)

        def done(job: Job, record: dict[str, Any]) -> None:
            progress.update(task, advance=1, description=job.key)

        records = run_batch(jobs, parallel, done)
        progress.update(task, description="figures")
        make_figures(out, jobs, records)
        progress.update(task, advance=1, description="report")
    return write_report(out, jobs, records, machine_description(), time.monotonic() - started)


def _command(args: argparse.Namespace) -> int:
    from zenav.run import RunError

    try:
        report = main(args.out, quick=args.quick, parallel=args.parallel)
    except RunError as exc:
        print(f"zenav paper: {exc}", file=sys.stderr)
        return 1
    print(f"report: {report}")
    return 0


def add_command(sub: Any) -> None:
    paper = sub.add_parser("paper", help="reproduce the paper's experiments as a report")
    paper.add_argument("--out", type=Path, default=Path("out/paper"), help="report directory")
    paper.add_argument("--quick", action="store_true",
                       help="scenario (a) once only (a smoke test of the report)")
    paper.add_argument("--parallel", type=int, default=2, help="runs at once (default 2)")
    paper.set_defaults(func=_command)
