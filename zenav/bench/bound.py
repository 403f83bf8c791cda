"""``zenav bench bound``: how fast a robot that knew the humans' future could reach its goal
in CrowdNav's invisible cases, as a yardstick for ``zenav bench crowd``'s time to goal.

In the invisible setting the humans ignore the robot, so their paths are the same
whatever it does: :func:`humans_paths` moves them with the simulator's own ORCA crowd
(:class:`zenav.sim.agents.Crowd`) and no robot. :func:`fastest_arrival` then finds, for
one fixed path of the robot, the earliest time it can be within ``tolerance`` of the
path's end, driving forward along it with zenav's speed and acceleration limits and never
closer to a human than the two radii plus ``margin`` at any tick: a search over
(distance along the path, speed) at every tick. The paths tried are CrowdNav's straight
start-goal line and, for each lateral ``offset``, the two legs through the point that far
to the side of the line's middle. The robot turns its corners at no cost here (zenav's
robot is a unicycle that turns at 1 rad/s), so the figures flatter such paths.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import sys
import time
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from zenav import argtypes
from zenav.bench.common import machine, words
from zenav.services.mission import ACCEL, DECEL
from zenav.sim.agents import Crowd
from zenav.sim.crowdnav import (
    HUMAN_RADIUS,
    LAYOUTS,
    ROBOT_RADIUS,
    ROBOT_SPEED,
    TIME_LIMIT,
    Layout,
    check_cases,
    crowdnav_scenario,
)
from zenav.sim.scenario import Scenario

__all__ = ["Limits", "agents_ignore_robot", "case_bound", "fastest_arrival", "humans_paths",
           "side_path"]

FloatArray = NDArray[np.float64]

TICK = 0.1
"""Time step of the search and of the humans' sampled paths, s (the simulator's tick)."""
STATION = 0.02
"""Distance step along the robot's path, m."""


@dataclass(frozen=True)
class Limits:
    """The robot's forward motion: top speed (m/s), acceleration and braking (m/s^2)."""

    top_speed: float = ROBOT_SPEED
    accel: float = ACCEL
    decel: float = DECEL


def agents_ignore_robot(scenario: Scenario) -> bool:
    """Whether no agent of ``scenario`` sees the robot: only then do the agents' paths not
    depend on the robot's (one that sees it moves the others it meets)."""
    return not any(o.is_agent and o.sees_robot for o in scenario.obstacles)


def humans_paths(scenario: Scenario, duration: float, dt: float = TICK) -> FloatArray:
    """Every agent's centre at t = 0, dt, ..., duration: (ticks, agents, 2), m; NaN while an
    agent is absent. Only for agents that ignore the robot (their paths do not depend on
    it); ValueError if one sees it."""
    if not agents_ignore_robot(scenario):
        raise ValueError(f"{scenario.name}: an agent sees the robot, so its path depends on "
                         "the robot's; the bound needs humans that ignore it (invisible)")
    crowd = Crowd(scenario)
    ticks = round(duration / dt) + 1
    out = np.full((ticks, crowd.count, 2), np.nan)
    crowd.start(None)
    for k in range(ticks):
        t = round(k * dt, 9)
        crowd.advance(t, None)
        on = crowd.exists(t)
        out[k, on] = crowd.positions_at(t)[on]
    return out


def side_path(start: Sequence[float], goal: Sequence[float], offset: float) -> FloatArray:
    """The straight line ``start`` -> ``goal`` (offset 0), or its two legs through the point
    ``offset`` m to the left of the line's middle (negative: to the right)."""
    a, b = np.asarray(start, dtype=np.float64), np.asarray(goal, dtype=np.float64)
    if offset == 0.0:
        return np.vstack([a, b])
    d = b - a
    left = np.array([-d[1], d[0]]) / float(np.hypot(*d))
    return np.vstack([a, (a + b) / 2 + offset * left, b])


def fastest_arrival(humans: FloatArray, path: FloatArray, clearance: float, tolerance: float,
                    limits: Limits = Limits(), dt: float = TICK,
                    station: float = STATION) -> float | None:
    """The earliest tick time (s) at which a robot starting at rest at ``path[0]`` can be
    within ``tolerance`` (m, along the path) of its end, driving forward along ``path``
    within ``limits``, with its centre at least ``clearance`` (m) from every human centre of
    ``humans`` ((ticks, agents, 2), NaN when absent, sampled every ``dt`` s) at every tick.
    None if no such motion exists within the ticks given. Speeds are multiples of
    accel x dt, braking a whole number of those steps per tick."""
    legs = np.diff(path, axis=0)
    lengths = np.hypot(legs[:, 0], legs[:, 1])
    ends = np.concatenate([[0.0], np.cumsum(lengths)])
    goal = max(float(ends[-1]) - tolerance, 0.0)
    stations = math.ceil(goal / station) + 1
    s = np.arange(stations) * station
    leg = np.clip(np.searchsorted(ends, s, side="right") - 1, 0, len(lengths) - 1)
    points = path[leg] + legs[leg] * ((s - ends[leg]) / lengths[leg])[:, None]
    gaps = np.hypot(humans[:, :, None, 0] - points[None, None, :, 0],
                    humans[:, :, None, 1] - points[None, None, :, 1])
    free = np.all(np.nan_to_num(gaps, nan=np.inf) >= clearance, axis=1)  # (ticks, stations)
    step = limits.accel * dt
    speeds = np.arange(round(limits.top_speed / step) + 1) * step
    brake = max(1, round(limits.decel / limits.accel))
    # reach[i, j]: at station i with speed j, reachable at this tick.
    reach = np.zeros((stations, len(speeds)), dtype=bool)
    reach[0, 0] = bool(free[0, 0])
    for tick in range(1, len(free)):
        if not reach.any():
            return None
        ahead = np.zeros_like(reach)
        for j in map(int, np.flatnonzero(reach.any(axis=0))):
            for k in range(max(0, j - brake), min(len(speeds), j + 2)):
                shift = round(0.5 * float(speeds[j] + speeds[k]) * dt / station)
                if shift == 0:
                    ahead[:, k] |= reach[:, j]
                elif shift < stations:
                    ahead[shift:, k] |= reach[:-shift, j]
                    ahead[-1, k] |= reach[-shift:, j].any()  # past the goal: at it
                else:
                    ahead[-1, k] |= reach[:, j].any()
        reach = ahead & free[tick][:, None]
        if reach[-1].any():
            return round(tick * dt, 9)
    return None


def case_bound(layout: str, case: int, offsets: Sequence[float], margin: float,
               limits: Limits = Limits()) -> dict[str, Any]:
    """The fastest arrival of one invisible case along each path (its straight line, then
    each side offset): ``{"case", "times": {offset: s or None}}``."""
    scenario = crowdnav_scenario(cast(Layout, layout), case)
    humans = humans_paths(scenario, TIME_LIMIT)
    robot = scenario.robot
    clearance = ROBOT_RADIUS + HUMAN_RADIUS + margin
    times = {str(o): fastest_arrival(humans, side_path(robot.start, robot.goal, o), clearance,
                                     robot.goal_tolerance, limits)
             for o in offsets}
    return {"case": case, "times": times}


def _row(name: str, times: list[float | None]) -> str:
    done = [t for t in times if t is not None]
    mean = f"{statistics.mean(done):.2f}" if done else "-"
    median = f"{statistics.median(done):.2f}" if done else "-"
    return f"| {name} | {len(done)}/{len(times)} | {mean} | {median} |"


def report(results: list[dict[str, Any]], offsets: Sequence[float]) -> list[str]:
    """The table: per path, and the best of them per case."""
    lines = ["| path | cases with a way | mean time s | median time s |", "|---|---|---|---|"]
    for o in offsets:
        name = "straight line" if o == 0.0 else f"through {o:+g} m to the side"
        lines.append(_row(name, [r["times"][str(o)] for r in results]))
    best = []
    for r in results:
        done = [t for t in r["times"].values() if t is not None]
        best.append(min(done) if done else None)
    lines.append(_row("the best of these, per case", best))
    return lines


def _offsets(text: str) -> list[float]:
    try:
        values = [float(w) for w in words(text)]
    except ValueError:
        raise argparse.ArgumentTypeError(f"offsets must be numbers in m, got {text!r}") from None
    if not values or not all(math.isfinite(v) and abs(v) < 6.0 for v in values):
        raise argparse.ArgumentTypeError(f"offsets must be finite, within ±6 m, got {text!r}")
    return values


def _command(args: argparse.Namespace) -> int:
    for name, value, least in (("--cases", args.cases, 1), ("--jobs", args.jobs, 1),
                               ("--seed", args.seed, 0), ("--margin", args.margin, 0)):
        if not value >= least:  # NaN too
            print(f"zenav bench bound: {name} must be >= {least} (got {value})",
                  file=sys.stderr)
            return 2
    try:
        check_cases(args.seed, args.cases)
    except ValueError as exc:
        print(f"zenav bench bound: {exc}", file=sys.stderr)
        return 2
    started = time.monotonic()
    cases = range(args.seed, args.seed + args.cases)
    try:
        with ProcessPoolExecutor(max_workers=args.jobs) as pool:
            results = list(pool.map(case_bound, [args.layout] * len(cases), cases,
                                    [args.offsets] * len(cases), [args.margin] * len(cases),
                                    chunksize=4))
    except KeyboardInterrupt:
        print("zenav bench bound: interrupted", file=sys.stderr)
        return 130
    lines = [f"# zenav bench bound: {args.layout} crossing, invisible humans, cases "
             f"{cases.start}..{cases.stop - 1}", "",
             f"{machine()}; {time.monotonic() - started:.0f} s; robot top speed "
             f"{ROBOT_SPEED} m/s, acceleration {ACCEL} m/s², braking {DECEL} m/s²; "
             f"centres kept {ROBOT_RADIUS + HUMAN_RADIUS + args.margin:.2f} m apart at every "
             f"{TICK} s tick", "", *report(results, args.offsets)]
    print("\n".join(lines))
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        (args.out / "bound.md").write_text("\n".join(lines) + "\n")
        (args.out / "bound.json").write_text(json.dumps(
            {"layout": args.layout, "margin": args.margin, "offsets": args.offsets,
             "cases": results}, indent=1))
    return 0


def add_command(kinds: Any) -> None:
    """``zenav bench bound`` (``kinds``: the subcommands of ``zenav bench``)."""
    bound = kinds.add_parser(
        "bound", help="the fastest arrival with the humans' future known (CrowdNav's "
        "invisible cases): a yardstick for bench crowd's time to goal")
    bound.add_argument("--cases", type=int, default=500,
                       help="CrowdNav test cases (default 500)")
    bound.add_argument("--seed", type=int, default=0, help="first test case (default 0)")
    bound.add_argument("--layout", choices=LAYOUTS, default="circle",
                       help="circle or square crossing (default circle)")
    bound.add_argument("--offsets", type=_offsets, default=[0.0, -1.0, 1.0, -2.0, 2.0, -3.0, 3.0],
                       help="the paths: 0 is the straight line, x goes through the point x m "
                       "left of its middle (default 0,-1,1,-2,2,-3,3)")
    bound.add_argument("--margin", type=float, default=0.0,
                       help="gap kept beyond the two radii at every tick, m (default 0)")
    bound.add_argument("--jobs", type=int, default=os.cpu_count() or 1,
                       help="cases at a time (default: the number of cores)")
    bound.add_argument("--out", type=argtypes.path, default=None,
                       help="also write bound.md and bound.json here")
    bound.set_defaults(func=_command)
