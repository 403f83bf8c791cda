"""``zenav bench perf`` and ``zenav bench nav``: the benchmarks (see ``bench_perf`` and
``bench_nav``; results in ``docs/benchmarks.md``)."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path
from typing import Any

from zenav.sim.generate import FAMILIES


def _words(text: str) -> list[str]:
    return [w.strip() for w in text.split(",") if w.strip()]


def _perf(args: argparse.Namespace) -> int:
    from zenav.bench_perf import SECTIONS, run_perf

    sections = tuple(_words(args.sections))
    unknown = [s for s in sections if s not in SECTIONS]
    if unknown:
        print(f"zenav bench perf: unknown section {', '.join(unknown)}; choose from "
              f"{', '.join(SECTIONS)}", file=sys.stderr)
        return 2
    run_perf(sections, args.out, scans=args.scans,
             obstacle_counts=tuple(int(n) for n in _words(args.obstacles)),
             latency_seconds=args.latency_seconds,
             rates=tuple(float(r) for r in _words(args.rates)), rate_seconds=args.rate_seconds)
    return 0


def _nav(args: argparse.Namespace) -> int:
    from zenav.bench_nav import run_nav

    try:
        run_nav(_words(args.planners), args.worlds, args.seed, args.out,
                families=_words(args.families), jobs=args.jobs,
                progress=not args.no_progress)
    except ValueError as exc:
        print(f"zenav bench nav: {exc}", file=sys.stderr)
        return 2
    return 0


def add_commands(sub: Any) -> None:
    """Add ``bench perf`` and ``bench nav`` to the ``zenav`` parser's subcommands."""
    bench = sub.add_parser("bench", help="benchmarks: compute and transport, navigation")
    kinds = bench.add_subparsers(dest="bench", required=True)

    perf = kinds.add_parser("perf", help="compute per scan, latency, lockstep speed, "
                            "sustained rate, memory")
    perf.add_argument("--sections", default="compute,latency,lockstep,rate",
                      help="comma-separated: compute, latency (and memory), lockstep, rate")
    perf.add_argument("--scans", type=int, default=200, help="scans timed per world (compute)")
    perf.add_argument("--obstacles", default="0,5,20", help="obstacles in view (compute)")
    perf.add_argument("--latency-seconds", type=float, default=30.0,
                      help="wall seconds of the real-time run (latency)")
    perf.add_argument("--rates", default="10,50,100,200,300,400,600",
                      help="laser rates tried, Hz (rate)")
    perf.add_argument("--rate-seconds", type=float, default=6.0,
                      help="wall seconds measured per rate (rate)")
    perf.add_argument("--out", type=Path, help="directory for perf.md and the runs")
    perf.set_defaults(func=_perf)

    nav = kinds.add_parser("nav", help="planners on seeded random worlds through zenav run")
    nav.add_argument("--planners", default="paper,vfh,dwa,apf",
                     help="comma-separated planner names (default paper,vfh,dwa,apf)")
    nav.add_argument("--worlds", type=int, default=5, help="worlds per family (default 5)")
    nav.add_argument("--seed", type=int, default=0, help="first seed (default 0)")
    nav.add_argument("--families", default=",".join(FAMILIES),
                     help=f"comma-separated world families (default {','.join(FAMILIES)})")
    nav.add_argument("--jobs", type=int, default=os.cpu_count() or 1,
                     help="runs at a time (default: the number of cores; each run is six "
                     "processes)")
    nav.add_argument("--out", type=Path, default=Path("out/bench-nav"),
                     help="directory for the worlds, runs, nav.md, nav.png, nav.json")
    nav.add_argument("--no-progress", action="store_true", help="no progress bar")
    nav.set_defaults(func=_nav)
