"""``zenav paper``: the paper's experiments through the real stack, as a report.

Every run goes through ``zenav run``'s path (six processes over Zenoh, lockstep on the
simulated clock). The report (``report.md``) puts the measured figures beside the
paper's and links the figures drawn from each run record; every number in it is
computed from a ``run.json`` by :func:`indicators`.
"""

from __future__ import annotations

import json
import math
import statistics
import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from zenav.run import run_scenario
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

_plot_lock = threading.Lock()  # pyplot keeps global state: one figure at a time


@dataclass(frozen=True)
class Job:
    """One run of the report."""

    key: str  # e.g. "a/seed1", "paper-mixed"
    scenario: Path
    out: Path


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


def run_jobs(
    jobs: list[Job], parallel: int, on_done: Callable[[Job], None]
) -> dict[str, dict[str, Any]]:
    """Run every job through the full stack, ``parallel`` at a time."""

    def one(job: Job) -> tuple[str, dict[str, Any]]:
        record = run_scenario(job.scenario, job.out, picture=False)
        with _plot_lock:  # pyplot keeps global state: one figure at a time
            from zenav.plot import plot_run

            plot_run(load_scenario(job.scenario), record, job.out / "run.png")
        return job.key, record

    records: dict[str, dict[str, Any]] = {}
    with ThreadPoolExecutor(parallel) as pool:
        futures = {pool.submit(one, job): job for job in jobs}
        for future in as_completed(futures):
            key, record = future.result()
            records[key] = record
            on_done(futures[future])
    return records


# --- figures -------------------------------------------------------------------------


def _decision_points(record: dict[str, Any]) -> list[tuple[float, float, float, str]]:
    """(t, x, y, label) of every event that is not plain driving."""
    traj = record["trajectory"]
    times = [row[0] for row in traj]
    found = []
    for event in record["events"]:
        if event["action"] in ("keep", "resume") and event["scenario"] in "a":
            continue
        i = min(range(len(times)), key=lambda k: abs(times[k] - event["t"]))
        found.append((event["t"], traj[i][1], traj[i][2],
                      f"{event['scenario']}:{event['action']}"))
    return found


def draw_experiment(scenario: Scenario, record: dict[str, Any], path: Path,
                    window_radius: float, title: str) -> None:
    """The paper-style figure: grid, obstacles and movers' paths, global path,
    trajectory, the sliding windows where decisions happened (V1..) and the decision
    points with their scenario letter and action."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle, Rectangle

    width, height = scenario.world.size
    end = float(record["time"])
    with _plot_lock:
        fig, ax = plt.subplots(figsize=(7.5, 7.5 * height / width))
        ax.set_xlim(0, width)
        ax.set_ylim(0, height)
        ax.set_aspect("equal")
        cell = scenario.world.cell
        ax.set_xticks(np.arange(0, width + 1e-9, cell), minor=True)
        ax.set_yticks(np.arange(0, height + 1e-9, cell), minor=True)
        ax.grid(which="minor", color="0.9", linewidth=0.5)
        traj_all = np.asarray(record["trajectory"])
        for index, ob in enumerate(scenario.obstacles):
            moving = not ob.is_static
            colour = "tab:purple" if moving else "0.35"
            if moving:
                t0, t1 = ob.appear, min(ob.vanish_time, end)
                stops = np.linspace(t0, max(t0, t1 - 1e-6), 60)
                path_xy = np.array([ob.center_at(t) for t in stops])
                ax.plot(path_xy[:, 0], path_xy[:, 1], ls=":", color=colour, lw=1)
                # drawn where it came closest to the robot, with its heading
                robot_at = np.array([np.interp(stops, traj_all[:, 0], traj_all[:, 1]),
                                     np.interp(stops, traj_all[:, 0], traj_all[:, 2])]).T
                k = int(np.argmin(np.hypot(*(path_xy - robot_at).T)))
                cx, cy = path_xy[k]
                tip = path_xy[min(k + 3, len(path_xy) - 1)]
                ax.annotate("", xy=tuple(tip), xytext=(cx, cy),
                            arrowprops={"arrowstyle": "->", "color": colour})
            else:
                cx, cy = ob.center
            if ob.shape == "disc" and ob.radius is not None:
                ax.add_patch(Circle((cx, cy), ob.radius, color=colour, alpha=0.75))
            elif ob.size is not None:
                ax.add_patch(Rectangle((cx - ob.size[0] / 2, cy - ob.size[1] / 2), ob.size[0],
                                       ob.size[1], color=colour, alpha=0.75))
            label = f"{'D' if moving else 'S'}{index}"
            ax.annotate(label, (cx, cy), xytext=(3, 3), textcoords="offset points", fontsize=7)
        start, goal = scenario.robot.start, scenario.robot.goal
        ax.plot([start[0], goal[0]], [start[1], goal[1]], ls="--", color="tab:green", lw=1,
                label="global path")
        traj = np.asarray(record["trajectory"])
        ax.plot(traj[:, 1], traj[:, 2], color="tab:blue", lw=1.6, label="trajectory")
        points = _decision_points(record)
        windows: list[tuple[float, float]] = []
        for _, x, y, label in points:  # the windows where decisions happened, spaced out
            if label.split(":")[1] in ("morphin", "stop", "slow", "speed_up") and all(
                    math.dist((x, y), w) > window_radius / 2 for w in windows):
                windows.append((x, y))
        for k, (x, y) in enumerate(windows[:4]):
            ax.add_patch(Circle((x, y), window_radius, fill=False, ls="--", color="tab:orange",
                                lw=0.8))
            ax.annotate(f"V{k + 1}", (x + window_radius * 0.7, y + window_radius * 0.7),
                        color="tab:orange", fontsize=8)
        for _, x, y, label in points:
            ax.plot(x, y, marker="x", color="tab:red", markersize=6)
            ax.annotate(label, (x, y), xytext=(4, -9), textcoords="offset points", fontsize=7,
                        color="tab:red")
        ax.plot(*start, marker="o", color="tab:green")
        ax.plot(*goal, marker="*", markersize=12, color="tab:green")
        ax.set_title(f"{title}: {record['outcome']} at {end:.1f} s (simulated)", fontsize=10)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.legend(loc="lower right", fontsize=7)
        fig.tight_layout()
        fig.savefig(path, dpi=110)
        plt.close(fig)


def draw_animation(scenario: Scenario, record: dict[str, Any], path: Path,
                   window_radius: float, fps: int = 8, seconds_per_frame: float = 1.0) -> None:
    """An animated GIF of the run: obstacles where they were, the robot and its window."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation, PillowWriter
    from matplotlib.patches import Circle, Rectangle

    traj = np.asarray(record["trajectory"])
    frames = np.arange(0.0, float(record["time"]) + 1e-9, seconds_per_frame)
    width, height = scenario.world.size
    with _plot_lock:
        fig, ax = plt.subplots(figsize=(5, 5 * height / width))

        def draw(t: float) -> None:
            ax.clear()
            ax.set_xlim(0, width)
            ax.set_ylim(0, height)
            ax.set_aspect("equal")
            ax.plot([scenario.robot.start[0], scenario.robot.goal[0]],
                    [scenario.robot.start[1], scenario.robot.goal[1]], ls="--",
                    color="tab:green", lw=0.8)
            for ob in scenario.obstacles:
                if not ob.exists_at(t):
                    continue
                cx, cy = ob.center_at(t)
                colour = "0.35" if ob.is_static else "tab:purple"
                if ob.shape == "disc" and ob.radius is not None:
                    ax.add_patch(Circle((cx, cy), ob.radius, color=colour))
                elif ob.size is not None:
                    ax.add_patch(Rectangle((cx - ob.size[0] / 2, cy - ob.size[1] / 2),
                                           ob.size[0], ob.size[1], color=colour))
            i = int(np.searchsorted(traj[:, 0], t, side="right")) - 1
            i = max(0, min(i, len(traj) - 1))
            ax.plot(traj[: i + 1, 1], traj[: i + 1, 2], color="tab:blue", lw=1.2)
            x, y, heading = traj[i, 1], traj[i, 2], traj[i, 3]
            ax.add_patch(Circle((x, y), scenario.robot.radius, color="tab:blue", alpha=0.8))
            ax.add_patch(Circle((x, y), window_radius, fill=False, ls="--", color="tab:orange",
                                lw=0.8))
            ax.plot([x, x + 0.4 * math.cos(heading)], [y, y + 0.4 * math.sin(heading)],
                    color="k", lw=1)
            ax.set_title(f"{scenario.name}  t = {t:5.1f} s", fontsize=9)

        animation = FuncAnimation(fig, draw, frames=frames)
        animation.save(path, writer=PillowWriter(fps=fps))
        plt.close(fig)


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
    return [f"- t = {t:.1f} s at ({x:.2f}, {y:.2f}): {label}"
            for t, x, y, label in _decision_points(record)]


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
    figures = out / "figures"
    figures.mkdir(parents=True, exist_ok=True)
    for job in jobs:
        if job.key not in (*SIMULATIONS, ROBUSTNESS):
            continue
        scenario = load_scenario(job.scenario)
        window = min(8 * scenario.world.cell, scenario.laser.max_range)
        record = records[job.key]
        draw_experiment(scenario, record, figures / f"{job.key}.png", window, job.key)
        draw_animation(scenario, record, figures / f"{job.key}.gif", window)


def machine_description() -> str:
    import os
    import platform

    model = "unknown CPU"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{os.cpu_count()} cores ({model}), Python {platform.python_version()}"


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

        def done(job: Job) -> None:
            progress.update(task, advance=1, description=job.key)

        records = run_jobs(jobs, parallel, done)
        progress.update(task, description="figures")
        make_figures(out, jobs, records)
        progress.update(task, advance=1, description="report")
    return write_report(out, jobs, records, machine_description(), time.monotonic() - started)
