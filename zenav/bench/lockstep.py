"""``zenav bench perf``, lockstep: ``zenav run`` on the eight paper scenarios, simulated
seconds per wall second of the simulator's loop (from its log) and of the whole run, with
the whole run split into start-up (the command's start to the simulator's 'all services
alive'), the loop, and the rest (the stop of the processes and the record)."""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
import time
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

from zenav.bench.common import fmt, verdict
from zenav.sim import SCENARIO_DIR

PAPER_SCENARIOS = tuple(sorted(SCENARIO_DIR.glob("[a-h]-*.yaml")))
TARGET_LOCKSTEP_FACTOR = 50.0
TARGET_COMMAND_FACTOR = 30.0

_LOG_TIME = re.compile(r"^(\d{4}-\d\d-\d\d \d\d:\d\d:\d\d,\d{3}) ")


def _log_times(log: Path) -> tuple[float | None, float | None]:
    """Wall times (s since the epoch) of the simulator's 'run ... starts' and 'run ...
    ended' lines."""
    start = end = None
    for line in log.read_text(errors="replace").splitlines():
        match = _LOG_TIME.match(line)
        if match is None:
            continue
        when = datetime.strptime(match.group(1), "%Y-%m-%d %H:%M:%S,%f").timestamp()
        if " starts (" in line:
            start = when
        elif " ended: " in line:
            end = when
    return start, end


def _log_seconds(log: Path) -> float | None:
    """Wall seconds between the simulator's 'run ... starts' and 'run ... ended' lines."""
    start, end = _log_times(log)
    return None if start is None or end is None else end - start


@dataclass
class LockstepRow:
    scenario: str
    outcome: str
    sim_time: float
    loop_wall: float | None
    command_wall: float
    startup: float | None = None
    """Wall seconds from the command's start to the simulator's loop starting."""


def measure_lockstep(work: Path, scenarios: tuple[Path, ...] = PAPER_SCENARIOS,
                     planner: str = "paper") -> list[LockstepRow]:
    rows = []
    for path in scenarios:
        out = work / "lockstep" / path.stem
        launched = time.time()
        done = subprocess.run(
            [sys.executable, "-m", "zenav", "run", str(path), "--out", str(out),
             "--planner", planner], capture_output=True, text=True, check=False, timeout=1800)
        if done.returncode != 0:
            raise RuntimeError(f"zenav run {path.name} failed: {done.stderr.strip()}")
        record = json.loads((out / "run.json").read_text())
        log = out / "logs" / "simulator.log"
        start, _ = _log_times(log)
        rows.append(LockstepRow(path.stem, record["outcome"], record["time"],
                                _log_seconds(log), record["wall_time"],
                                None if start is None else start - launched))
    return rows


def lockstep_table(rows: list[LockstepRow]) -> str:
    lines = ["| scenario | outcome | simulated s | start-up wall s | simulator loop wall s | "
             "× real time (loop) | zenav run wall s | × real time (whole command) |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        loop = r.loop_wall if r.loop_wall else math.nan
        startup = r.startup if r.startup is not None else math.nan
        lines.append(f"| {r.scenario} | {r.outcome} | {r.sim_time:.1f} | {fmt(startup, 1)} | "
                     f"{fmt(loop, 1)} | {fmt(r.sim_time / loop, 1)} | {r.command_wall:.1f} | "
                     f"{r.sim_time / r.command_wall:.1f} |")
    sim = sum(r.sim_time for r in rows)
    loop_total = sum(r.loop_wall or math.nan for r in rows)
    startup_total = sum(math.nan if r.startup is None else r.startup for r in rows)
    wall = sum(r.command_wall for r in rows)
    factor = sim / loop_total
    lines.append(f"| **all** | | {sim:.1f} | {fmt(startup_total, 1)} | {fmt(loop_total, 1)} | "
                 f"**{fmt(factor, 1)}** | {wall:.1f} | **{sim / wall:.1f}** |")
    lines.append("")
    lines.append(f"Targets: ≥ {TARGET_LOCKSTEP_FACTOR:g}× real time in the simulator's loop — "
                 f"measured {fmt(factor, 1)}× ({verdict(factor >= TARGET_LOCKSTEP_FACTOR)}); "
                 f"≥ {TARGET_COMMAND_FACTOR:g}× for the whole command with the processes' start "
                 f"and stop — measured {sim / wall:.1f}× "
                 f"({verdict(sim / wall >= TARGET_COMMAND_FACTOR)}). The command's wall time is "
                 f"run.json's (from the start of the run to the record, without the picture); "
                 f"start-up is from the command's launch, its own interpreter included, to "
                 f"the simulator's loop starting (seven interpreters and their imports, the "
                 f"Zenoh mesh, every service alive).")
    return "\n".join(lines)


TARGET_ENGINE_FACTOR = 300.0


@dataclass
class EngineRow:
    scenario: str
    outcome: str
    sim_time: float
    wall: float
    cpu: float  # this process's CPU seconds for the run


def measure_engine(work: Path, scenarios: tuple[Path, ...] = PAPER_SCENARIOS,
                   planner: str = "paper") -> list[EngineRow]:
    """The in-process engine (``zenav run --engine inprocess``, without the picture) on
    each scenario in this process, once the modules are imported: simulated s and wall s."""
    import time

    from zenav.run import run_scenario

    rows = []
    for path in scenarios:
        started, cpu = time.perf_counter(), time.process_time()
        record = run_scenario(path, work / "engine" / path.stem, planner=planner,
                              picture=False, engine="inprocess", log_level="WARNING")
        rows.append(EngineRow(path.stem, record["outcome"], record["time"],
                              time.perf_counter() - started, time.process_time() - cpu))
    return rows


def engine_factor(rows: list[EngineRow], cpu: bool = False) -> float:
    """Simulated seconds per wall second (``cpu``: per CPU second of this process)."""
    return sum(r.sim_time for r in rows) / sum(r.cpu if cpu else r.wall for r in rows)


def engine_table(rows: list[EngineRow]) -> str:
    lines = ["| scenario | outcome | simulated s | wall s | × real time (wall) | CPU s | "
             "× real time (CPU) |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r.scenario} | {r.outcome} | {r.sim_time:.1f} | {r.wall:.2f} | "
                     f"{r.sim_time / r.wall:.1f} | {r.cpu:.2f} | {r.sim_time / r.cpu:.1f} |")
    sim = sum(r.sim_time for r in rows)
    factor, per_cpu = engine_factor(rows), engine_factor(rows, cpu=True)
    lines.append(f"| **all** | | {sim:.1f} | {sum(r.wall for r in rows):.2f} | "
                 f"**{factor:.1f}** | {sum(r.cpu for r in rows):.2f} | **{per_cpu:.1f}** |")
    lines.append("")
    lines.append(f"Target: ≥ {TARGET_ENGINE_FACTOR:g}× real time — measured {factor:.1f}× in "
                 f"wall time, {per_cpu:.1f}× per CPU second of the process "
                 f"({verdict(factor >= TARGET_ENGINE_FACTOR)}).")
    return "\n".join(lines)
