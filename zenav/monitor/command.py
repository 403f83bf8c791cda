"""``zenav monitor``: the process that feeds a :class:`MonitorModel` from the bus and
shows it as a screen or as JSON lines."""

from __future__ import annotations

import argparse
import asyncio
import json
import sys
import time
from typing import IO, Any

from zenav.argtypes import float_at_least, positive_float
from zenav.monitor.model import MonitorModel
from zenav.monitor.screen import render
from zenav.services.runner import add_transport_arguments
from zenav.tooling import (
    CONNECT_TIMEOUT,
    Heard,
    StampedSubscriber,
    add_connect_timeout,
    note_if_quiet,
    open_bus,
    quiet_note,
    run_tool,
    stop_on_signals,
    tool_setup,
    wait_for_event,
)

MIN_PERIOD = 0.01
"""The shortest ``--period``: 100 screens or snapshots a second."""


async def monitor(transport: Any, robot_id: str, *, jsonl: bool, period: float,
                  duration: float | None, silence: float = 0.5, scale: float = 0.25,
                  out: IO[str] = sys.stdout, connect_timeout: float = CONNECT_TIMEOUT) -> None:
    model = MonitorModel(robot_id, silence_after=silence)
    loop = asyncio.get_running_loop()
    stop = asyncio.Event()
    stop_on_signals(stop)
    if duration is not None:
        loop.call_later(duration, stop.set)
    bus = await open_bus(transport, stop, connect_timeout, "zenav monitor")
    if bus is None:  # stopped (a signal or --duration) while connecting
        print("zenav monitor: stopped before the session opened; nothing shown",
              file=sys.stderr)
        return
    heard = Heard()

    def on_liveliness(key: str, alive: bool) -> None:
        heard.mark()
        model.on_liveliness(key, alive, time.time())

    subscriber = StampedSubscriber(
        bus, model.keys.everything,
        lambda key, payload, ns: model.on_sample(key, payload, ns / 1e9), heard)
    bus.watch_liveliness(model.keys.alive_any, on_liveliness)
    quiet = asyncio.create_task(
        note_if_quiet(heard, stop, quiet_note("monitor", transport, robot_id)))
    try:
        if jsonl:
            while not stop.is_set():
                now = time.time()
                model.tick(now)
                for event in model.drain_events():
                    out.write(json.dumps(event.as_dict()) + "\n")
                out.write(json.dumps(model.snapshot(now)) + "\n")
                out.flush()
                await wait_for_event(stop, period)
        else:
            from rich.live import Live

            with Live(render(model, time.time(), scale),
                      refresh_per_second=max(1, round(1 / period)), screen=False) as live:
                while not stop.is_set():
                    now = time.time()
                    model.tick(now)
                    model.drain_events()  # shown in "recent events"
                    live.update(render(model, now, scale))
                    await wait_for_event(stop, period)
    finally:
        quiet.cancel()
        subscriber.close()
        bus.close()


def main(args: argparse.Namespace) -> int:
    setup = tool_setup(args, "monitor")
    if setup is None:
        return 2
    robot_id, transport = setup
    return run_tool("monitor", monitor(transport, robot_id, jsonl=args.jsonl, period=args.period,
                                       duration=args.duration, silence=args.silence,
                                       scale=args.map_scale,
                                       connect_timeout=args.connect_timeout))


def add_command(sub: Any) -> None:
    monitor = sub.add_parser(
        "monitor", help="live read-only view of a running stack",
        description="Live view: robot pose and speed, obstacles, the planner's scenario and "
        "action, its global path and occupancy map (with a character map round the robot), "
        "each service's liveliness, message rates, scan-to-command latency. "
        "--connect ENDPOINT joins a router as a client from any host.")
    monitor.add_argument("--jsonl", action="store_true",
                         help="print events and snapshots as JSON lines, not a screen")
    monitor.add_argument("--period", type=float_at_least(MIN_PERIOD), default=0.25,
                         help="s between screen refreshes or snapshots (default 0.25, at "
                         f"least {MIN_PERIOD:g})")
    monitor.add_argument("--duration", type=positive_float, help="stop after this many s")
    monitor.add_argument("--silence", type=positive_float, default=0.5,
                         help="a topic silent this long (s, at least 4 typical gaps) counts "
                         "as stopped (default 0.5)")
    monitor.add_argument("--map-scale", type=positive_float, default=0.25, metavar="M",
                         help="m of the world per column of the map view, rows twice that "
                         "(default 0.25: 41 x 21 characters cover about 10 x 10 m)")
    add_transport_arguments(monitor)
    add_connect_timeout(monitor)
    monitor.set_defaults(func=main)
