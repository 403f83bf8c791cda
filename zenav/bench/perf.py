"""``zenav bench perf``: compute per scan, latency over Zenoh, lockstep speed, the
in-process engine's speed, sustained scan rate and memory of the service stack.

Seven measurements (one module each: :mod:`.compute`, :mod:`.latency`, :mod:`.memory`,
:mod:`.lockstep`, :mod:`.rate`, :mod:`.floor`), each printed as a Markdown table with the
issue's target beside the measured figure (targets are reported, never asserted), and at
the end one summary table of every target measured in this run:

- **compute**: the pure cores timed in one process on simulated 361-beam scans with 0,
  5 and 20 obstacles in view, the robot standing, one box on its path and half the
  others moving (clustering = ``Perceiver.process``, tracking = ``Tracker.update`` and
  the track messages, collision prediction and Morphin inside ``Planner.step``, and the
  baselines' steps on the same scans);
- **latency**: a real stack over Zenoh in real time; a tool process takes the wall time
  (in Zenoh's callback, one clock) at which it receives the scan stamped *s* (the laser
  driver's publish) and the base command stamped *s* (the motor bridge's publish right
  after it received the velocity command): the interval is the laser driver's publish to
  the motor bridge's publish, both seen one hop away;
- **lockstep**: ``zenav run`` on the eight paper scenarios, simulated seconds per wall
  second of the simulator's loop (from its log) and of the whole command;
- **engine**: ``zenav run --engine inprocess`` on the same scenarios, simulated seconds
  per wall second (the six services in this process, modules already imported);
- **rate**: the real-time simulator with the laser rate raised; the highest rate at which
  no service drops an input (the ``status/<service>`` counters) and every scan gets its
  base command;
- **memory**: resident set size of each service process (psutil), during the latency run;
- **floor**: the hops alone (:mod:`.floor`): relays on the stack's mesh that forward the
  bytes with no work, along the latency section's path (taking their input through the
  asyncio loop as the services do, then from Zenoh's callback) and around the lockstep
  tick: the part of those two sections' figures that the services' own work does not
  spend on this machine.
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import tempfile
from collections.abc import Callable
from datetime import datetime
from pathlib import Path
from typing import Any

from zenav import argtypes
from zenav.bench.common import machine, percentile, verdict, words
from zenav.bench.compute import (
    TARGET_PIPELINE_20_MEDIAN_US,
    TARGET_PIPELINE_MEDIAN_US,
    compute_table,
    time_compute,
)
from zenav.bench.floor import FloorError, floor_table, measure_chain, measure_ring
from zenav.bench.latency import (
    TARGET_LATENCY_MEDIAN_MS,
    TARGET_LATENCY_P99_MS,
    latency_table,
    measure_latency,
)
from zenav.bench.lockstep import (
    TARGET_COMMAND_FACTOR,
    TARGET_ENGINE_FACTOR,
    TARGET_LOCKSTEP_FACTOR,
    engine_factor,
    engine_table,
    lockstep_table,
    measure_engine,
    measure_lockstep,
)
from zenav.bench.memory import memory_table
from zenav.bench.rate import highest_rate, measure_rate, rate_table
from zenav.sim.scenario import MAX_TICKS

SECTIONS = ("compute", "latency", "lockstep", "engine", "rate", "floor")


def summary_table(figures: dict[str, tuple[str, str, bool]]) -> str:
    """The issue's table: each measure that was run, its figure and target side by side."""
    lines = ["| measure | measured | target | |", "|---|---|---|---|"]
    for name, (measured, target, met) in figures.items():
        lines.append(f"| {name} | {measured} | {target} | {verdict(met)} |")
    return "\n".join(lines)

def run_perf(sections: tuple[str, ...], out: Path | None, scans: int = 200,
             obstacle_counts: tuple[int, ...] = (0, 5, 20), latency_seconds: float = 30.0,
             rates: tuple[float, ...] = (10, 50, 100, 200, 300, 400, 600),
             rate_seconds: float = 6.0, floor_seconds: float = 20.0,
             echo: Callable[[str], None] = print) -> str:
    """Run the chosen sections; print and return the report (Markdown)."""
    parts = [f"# zenav bench perf\n\n{datetime.now().astimezone():%Y-%m-%d %H:%M %Z}, "
             f"{machine()}, Python {sys.version.split()[0]}\n"]
    echo(parts[0])
    figures: dict[str, tuple[str, str, bool]] = {}
    with tempfile.TemporaryDirectory(prefix="zenav-bench-") as tmp:
        work = out if out is not None else Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        for section in sections:
            if section == "compute":
                results = [time_compute(n, scans) for n in obstacle_counts]
                for r in results:
                    if r.obstacles in (5, 20) and r.micros["pipeline"]:
                        values = r.micros["pipeline"]
                        median = statistics.median(values)
                        goal = (TARGET_PIPELINE_MEDIAN_US if r.obstacles == 5
                                else TARGET_PIPELINE_20_MEDIAN_US)
                        figures[f"per-scan pipeline, {r.obstacles} obstacles, median / p99"] = (
                            f"{median:.0f} / {percentile(values, 99):.0f} µs",
                            f"≤ {goal:.0f} µs median", median <= goal)
                text = ("## Compute per scan, in process (361 beams)\n\n"
                        + compute_table(results))
            elif section == "latency":
                lat = measure_latency(latency_seconds, work)
                if lat.scan_to_base_ms:
                    med = statistics.median(lat.scan_to_base_ms)
                    p99 = percentile(lat.scan_to_base_ms, 99)
                    figures["scan → base command over Zenoh at 10 Hz, median / p99"] = (
                        f"{med:.1f} / {p99:.1f} ms", f"≤ {TARGET_LATENCY_MEDIAN_MS:g} / "
                        f"{TARGET_LATENCY_P99_MS:g} ms",
                        med <= TARGET_LATENCY_MEDIAN_MS and p99 <= TARGET_LATENCY_P99_MS)
                text = (f"## Scan-to-command latency over Zenoh (real time, 10 Hz, "
                        f"h-mixed, {latency_seconds:g} s)\n\n{latency_table(lat)}\n\n"
                        f"## Resident memory per service process (during that run)\n\n"
                        f"{memory_table(lat)}")
            elif section == "lockstep":
                steps = measure_lockstep(work)
                sim = sum(r.sim_time for r in steps)
                loop = sum(r.loop_wall or math.nan for r in steps)
                whole = sum(r.command_wall for r in steps)
                figures["lockstep, simulator loop (stack)"] = (
                    f"{sim / loop:.1f}× real time", f"≥ {TARGET_LOCKSTEP_FACTOR:g}×",
                    sim / loop >= TARGET_LOCKSTEP_FACTOR)
                figures["lockstep, whole `zenav run` command (stack)"] = (
                    f"{sim / whole:.1f}× real time", f"≥ {TARGET_COMMAND_FACTOR:g}×",
                    sim / whole >= TARGET_COMMAND_FACTOR)
                text = ("## Lockstep simulation speed (zenav run, paper planner)\n\n"
                        + lockstep_table(steps))
            elif section == "engine":
                engine_rows = measure_engine(work)
                factor = engine_factor(engine_rows)
                figures["in-process engine, paper scenarios"] = (
                    f"{factor:.1f}× real time "
                    f"({engine_factor(engine_rows, cpu=True):.1f}× per CPU s)",
                    f"≥ {TARGET_ENGINE_FACTOR:g}×", factor >= TARGET_ENGINE_FACTOR)
                text = ("## In-process engine speed (zenav run --engine inprocess, paper "
                        "planner, eight paper scenarios, one process)\n\n"
                        + engine_table(engine_rows))
            elif section == "rate":
                rows = []
                for rate in rates:
                    rows.append(measure_rate(rate, rate_seconds, work))
                text = (f"## Sustained scan rate in real time (h-mixed, {rate_seconds:g} s "
                        f"per rate)\n\n{rate_table(rows)}")
            elif section == "floor":
                chain = measure_chain(floor_seconds)
                direct = measure_chain(floor_seconds / 2, direct=True)
                ring = measure_ring(floor_seconds / 2)
                text = (f"## The hops alone: relays that forward with no work ({floor_seconds:g} s "
                        f"of the chain, {floor_seconds / 2:g} s of the others)\n\n"
                        + floor_table(chain, direct, ring, TARGET_LATENCY_MEDIAN_MS,
                                      TARGET_LOCKSTEP_FACTOR))
            else:
                raise ValueError(f"unknown section {section!r}; choose from {', '.join(SECTIONS)}")
            parts.append(text)
            echo(text + "\n")
    if figures:
        text = "## Summary: the targets of issue 13\n\n" + summary_table(figures)
        parts.append(text)
        echo(text + "\n")
    report = "\n\n".join(parts) + "\n"
    if out is not None:
        (out / "perf.md").write_text(report)
    return report


def _command(args: argparse.Namespace) -> int:
    sections = tuple(words(args.sections))
    unknown = [s for s in sections if s not in SECTIONS]
    if not sections:
        print(f"zenav bench perf: --sections is empty; choose from {', '.join(SECTIONS)}",
              file=sys.stderr)
        return 2
    if unknown:
        print(f"zenav bench perf: unknown section {', '.join(unknown)}; choose from "
              f"{', '.join(SECTIONS)}", file=sys.stderr)
        return 2
    top = highest_rate(args.rate_seconds)
    too_fast = [r for r in args.rates if r > top]
    if "rate" in sections and too_fast:
        print(f"zenav bench perf: --rates {', '.join(f'{r:g}' for r in too_fast)} Hz: at most "
              f"{top:.0f} Hz, so that a run of {args.rate_seconds:g} s measured (--rate-seconds) "
              f"fits the simulator's {MAX_TICKS} ticks", file=sys.stderr)
        return 2
    try:
        run_perf(sections, args.out, scans=args.scans,
                 obstacle_counts=args.obstacles, latency_seconds=args.latency_seconds,
                 rates=args.rates, rate_seconds=args.rate_seconds,
                 floor_seconds=args.floor_seconds)
    except FloorError as exc:
        print(f"zenav bench perf: floor: {exc}", file=sys.stderr)
        return 1
    return 0


def add_command(kinds: Any) -> None:
    """``zenav bench perf`` (``kinds``: the subcommands of ``zenav bench``)."""
    perf = kinds.add_parser("perf", help="compute per scan, latency, lockstep speed, "
                            "sustained rate, memory, the hops alone")
    perf.add_argument("--sections", default=",".join(SECTIONS),
                      help="comma-separated: compute, latency (and memory), lockstep, "
                      "engine (the in-process engine's speed), rate, floor (the hops "
                      "with no work in them) (default all)")
    perf.add_argument("--scans", type=argtypes.positive_int, default=200,
                      help="scans timed per world (compute; default 200)")
    perf.add_argument("--obstacles", type=argtypes.ints(argtypes.non_negative_int),
                      default="0,5,20",
                      help="obstacles in view, comma-separated (compute; default 0,5,20)")
    perf.add_argument("--latency-seconds", type=argtypes.positive_float, default=30.0,
                      help="wall seconds of the real-time run (latency; default 30)")
    perf.add_argument("--rates", type=argtypes.floats(argtypes.positive_float),
                      default="10,50,100,200,300,400,600",
                      help="laser rates tried, Hz, comma-separated (rate; default "
                      "10,50,100,200,300,400,600)")
    perf.add_argument("--rate-seconds", type=argtypes.positive_float, default=6.0,
                      help="wall seconds measured per rate (rate; default 6)")
    perf.add_argument("--floor-seconds", type=argtypes.positive_float, default=20.0,
                      help="wall seconds measured along the scan's path, half that "
                      "along it with no asyncio loop and around the lockstep tick (floor; "
                      "default 20)")
    perf.add_argument("--out", type=argtypes.path,
                      help="directory for perf.md and the runs (default: "
                      "a temporary one; the report is printed either way)")
    perf.set_defaults(func=_command)
