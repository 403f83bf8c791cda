"""``zenav soak``: the stack in real time at a high scan rate for a long time.

    zenav soak --minutes 30 --rate-hz 100 --out out/soak

starts the six services on loopback (as ``zenav run`` does) with the simulator on the
wall clock and the laser at ``--rate-hz`` (10x the paper's 10 Hz by default), on a
generated scenario that keeps the robot busy for the whole time: it creeps toward a far
goal while discs cross its view. The soak watches the stack as a monitor does and
reports, for a first window (after ``--warmup``) and the last window of the run:

- each service's resident memory (psutil), and its growth from start to end;
- messages dropped per stage (newest-wins buffers, from the ``status/<service>``
  counters) and rejected per reason, over the run;
- scan-to-command latency percentiles (the monitor's model: wall time between the scan
  stamped s and the command stamped s, received in one process).

It writes ``OUT/soak.json`` and prints a summary; the exit status is 1 when a service
died or the memory grew by more than ``--max-growth`` (5 %).
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import json
import math
import statistics
import sys
import time
from pathlib import Path
from typing import Any

import yaml

from zenav import argtypes
from zenav.bench.common import rss_mb
from zenav.launch import Stack
from zenav.monitor.model import MonitorModel
from zenav.schemas import keys
from zenav.schemas.codec import DecodeError, decode
from zenav.schemas.keys import Keys
from zenav.schemas.messages import ServiceStatus
from zenav.services.mission import stack_params
from zenav.services.transport import ZenohBus
from zenav.sim.scenario import load_scenario


def soak_scenario(path: Path, seconds: float, rate_hz: float) -> Path:
    """A scenario that lasts ``seconds``: a slow robot, a static box beside its path and
    a disc crossing its view every 20 s."""
    speed = 3.0 / max(seconds, 1.0)  # 3 m in the whole run: never reaches the 6 m goal
    crossers = [{"shape": "disc", "center": [6.5, 0.2], "radius": 0.2,
                 "velocity": [0.0, 0.5], "appear": float(t), "vanish": float(t + 19)}
                for t in range(0, int(seconds) + 20, 20)]
    data = {
        "name": "soak",
        "description": f"soak: {seconds:.0f} s at {rate_hz:g} Hz",
        "world": {"size": [10.0, 10.0], "cell": 0.5},
        "robot": {"start": [1.0, 5.0], "heading_deg": 0.0, "goal": [9.0, 5.0],
                  "speed": speed, "radius": 0.2},
        "laser": {"rate_hz": rate_hz},
        "obstacles": [{"shape": "box", "center": [4.0, 7.5], "size": [0.5, 0.5]}, *crossers],
        "duration": seconds + 60.0,
        "seed": 0,
    }
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def percentiles(samples: list[float]) -> dict[str, float | int | None]:
    if not samples:
        return {"n": 0, "p50": None, "p90": None, "p99": None, "max": None}
    ordered = sorted(samples)

    def at(q: float) -> float:
        return ordered[min(len(ordered) - 1, max(0, math.ceil(q * len(ordered)) - 1))]

    return {"n": len(ordered), "p50": statistics.median(ordered), "p90": at(0.90),
            "p99": at(0.99), "max": ordered[-1]}


def counters(statuses: dict[str, ServiceStatus]) -> dict[str, dict[str, Any]]:
    return {name: {"received": dict(s.received), "rejected": dict(s.rejected),
                   "dropped": dict(s.dropped), "handler_errors": s.handler_errors}
            for name, s in statuses.items()}


def _diff(end: dict[str, int], start: dict[str, int]) -> dict[str, int]:
    return {k: v - start.get(k, 0) for k, v in end.items() if v - start.get(k, 0)}


async def _soak(stack: Stack, seconds: float, warmup: float, window: float,
                progress: bool) -> dict[str, Any]:
    k = Keys(stack.robot_id)
    loop = asyncio.get_running_loop()
    bus = ZenohBus(stack.transport(driver=True), loop)
    model = MonitorModel(robot_id=stack.robot_id)
    statuses: dict[str, ServiceStatus] = {}
    lat_samples: list[tuple[float, float]] = []  # (wall, latency)
    try:
        alive: set[str] = set()
        bus.watch_liveliness(k.alive_any, lambda key, up: (alive.add if up else alive.discard)(
            key.rsplit("/", 1)[-1]))
        deadline = time.monotonic() + 60
        while not set(stack.services) <= alive:
            if stack.failure() or time.monotonic() > deadline:
                raise RuntimeError(stack.failure() or f"stack not up: {sorted(alive)}")
            await asyncio.sleep(0.05)
        sub = bus.subscribe(k.everything, depth=100_000)
        token = bus.declare_token(k.alive("run"))
        started = time.monotonic()
        marks: dict[str, Any] = {}
        pids = {name: proc.pid for name, proc in stack.processes.items()}
        next_print = started + 60
        while True:
            now = time.monotonic()
            elapsed = now - started
            if stack.failure():
                raise RuntimeError(stack.failure())
            if "start" not in marks and elapsed >= warmup:
                marks["start"] = {"t": elapsed, "rss_mb": rss_mb(pids),
                                  "counters": counters(statuses)}
            if elapsed >= seconds:
                marks["end"] = {"t": elapsed, "rss_mb": rss_mb(pids),
                                "counters": counters(statuses)}
                break
            if progress and now >= next_print:
                next_print += 60
                print(f"soak: {elapsed / 60:.0f} min, rss "
                      + ", ".join(f"{n} {v:.0f}" for n, v in rss_mb(pids).items()) + " MB",
                      file=sys.stderr, flush=True)
            try:
                key, payload = await asyncio.wait_for(sub.get(), timeout=0.2)
            except TimeoutError:
                continue
            wall = time.monotonic()
            if key.startswith(k.status_any[:-1]):
                with contextlib.suppress(DecodeError):
                    status = decode(payload, ServiceStatus)
                    statuses[status.service] = status
                continue
            before = len(model.latency.samples)
            last = model.latency.samples[-1] if model.latency.samples else None
            model.on_sample(key, payload, wall)
            if model.latency.samples and (len(model.latency.samples) != before
                                          or model.latency.samples[-1] is not last):
                lat_samples.append((wall - started, model.latency.samples[-1]))
        token.undeclare()
        dropped_in_bus = sub.dropped
    finally:
        bus.close()
    start, end = marks["start"], marks["end"]
    rss = {name: {"start": round(start["rss_mb"][name], 2), "end": round(v, 2),
                  "growth_pct": round(100 * (v / start["rss_mb"][name] - 1), 2)}
           for name, v in end["rss_mb"].items() if name in start["rss_mb"]}
    stages = {}
    for name, c in end["counters"].items():
        s = start["counters"].get(name, {"received": {}, "rejected": {}, "dropped": {}})
        stages[name] = {"received": _diff(c["received"], s["received"]),
                        "dropped": _diff(c["dropped"], s["dropped"]),
                        "dropped_total": c["dropped"], "rejected_total": c["rejected"],
                        "handler_errors": c["handler_errors"]}
    first = [lat for t, lat in lat_samples if start["t"] <= t < start["t"] + window]
    last_ = [lat for t, lat in lat_samples if t >= end["t"] - window]
    return {"seconds": round(end["t"], 1), "warmup": warmup, "window": window,
            "rss_mb": rss, "stages": stages,
            "latency_s": {"start": percentiles(first), "end": percentiles(last_)},
            "monitor_dropped": dropped_in_bus,
            "scans_seen": model.topics[keys.SCAN.name].count
            if keys.SCAN.name in model.topics else None}


def run_soak(out: Path, minutes: float, rate_hz: float, warmup: float = 30.0,
             window: float = 60.0, progress: bool = True) -> dict[str, Any]:
    out.mkdir(parents=True, exist_ok=True)
    seconds = minutes * 60.0
    scenario_path = soak_scenario(out / "soak-scenario.yaml", seconds + warmup, rate_hz)
    params = stack_params(load_scenario(scenario_path), scenario_path, "paper")
    params["simulator"] |= {"clock": "realtime", "realtime_factor": 1.0}
    params["motor_bridge"] |= {"clock": "realtime"}
    stack = Stack(out_dir=out, params=params, log_level="WARNING")
    try:  # a start that fails half-way leaves no service running
        stack.start()
        report = asyncio.run(_soak(stack, seconds, warmup, min(window, seconds / 3), progress))
    finally:
        codes = stack.stop()
    report |= {"rate_hz": rate_hz, "minutes": minutes, "exit_codes": codes}
    (out / "soak.json").write_text(json.dumps(report, indent=1))
    return report


def summary(report: dict[str, Any]) -> str:
    lines = [f"soak: {report['seconds']:.0f} s at {report['rate_hz']:g} Hz scans"]
    for name, r in report["rss_mb"].items():
        lines.append(f"  {name:13s} rss {r['start']:7.1f} -> {r['end']:7.1f} MB "
                     f"({r['growth_pct']:+.2f} %)")
    for name, s in report["stages"].items():
        lines.append(f"  {name:13s} received {sum(s['received'].values()):7d}, dropped "
                     f"{s['dropped'] or 0}, rejected {s['rejected_total'] or 0}")
    for when in ("start", "end"):
        p = report["latency_s"][when]
        if p["n"]:
            lines.append(f"  latency {when:5s} n={p['n']} p50 {1e3 * p['p50']:.2f} ms, "
                         f"p90 {1e3 * p['p90']:.2f} ms, p99 {1e3 * p['p99']:.2f} ms, "
                         f"max {1e3 * p['max']:.2f} ms")
    return "\n".join(lines)


MAX_RATE_HZ = 10_000.0
"""The fastest laser a soak may ask for (a scan every 0.1 ms: far past what a stack on
this machine keeps up with, and short of a clock that never advances)."""


def add_command(sub: Any) -> None:
    soak = sub.add_parser("soak", help="run the stack in real time for a long time and "
                          "report memory, drops and latency")
    soak.add_argument("--minutes", type=argtypes.positive_float, default=30.0,
                      help="wall minutes of the real-time run (default 30)")
    soak.add_argument("--rate-hz", type=argtypes.positive_float_at_most(MAX_RATE_HZ),
                      default=100.0, help="laser scan rate (default 100: 10x the paper's; "
                      f"at most {MAX_RATE_HZ:g})")
    soak.add_argument("--warmup", type=argtypes.non_negative_float, default=30.0,
                      help="s before the first sample (default 30)")
    soak.add_argument("--window", type=argtypes.positive_float, default=60.0,
                      help="s of latency samples at the start and at the end (default 60)")
    soak.add_argument("--max-growth", type=argtypes.non_negative_float, default=5.0,
                      help="allowed RSS growth, %% (default 5; above it the exit status is 1)")
    soak.add_argument("--out", type=argtypes.path, default=Path("out/soak"),
                      help="directory for soak.json and the run (default out/soak)")
    soak.set_defaults(func=_cmd_soak)


def _cmd_soak(args: argparse.Namespace) -> int:
    report = run_soak(args.out, args.minutes, args.rate_hz, args.warmup, args.window)
    print(summary(report))
    grown = {n: r["growth_pct"] for n, r in report["rss_mb"].items()
             if r["growth_pct"] > args.max_growth}
    if grown or len(report["rss_mb"]) < 6:
        print(f"zenav soak: memory grew beyond {args.max_growth} % or a service died: "
              f"{grown}", file=sys.stderr)
        return 1
    return 0
