"""``zenav record``: a robot's messages and liveliness changes into an MCAP file, with
the same data in Foxglove's well-known schemas beside them (:mod:`zenav.foxglove`)."""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import time
from pathlib import Path
from typing import Any

from zenav.bag.mcapfile import BagWriter
from zenav.services.runner import add_transport_arguments
from zenav.services.transport import ZenohBus
from zenav.tooling import StampedSubscriber, stop_on_signals, tool_setup, wait_for_event


async def record(transport: Any, robot_id: str, path: Path, *, duration: float | None,
                 exclude: tuple[str, ...]) -> tuple[int, int]:
    """Record until SIGINT/SIGTERM or ``duration``; (messages, liveliness changes)."""
    loop = asyncio.get_running_loop()
    stop = asyncio.Event()
    stop_on_signals(stop)
    changes = 0
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("wb") as stream:
        writer = BagWriter(stream, robot_id, exclude, foxglove=True)
        bus = ZenohBus(transport, loop)
        try:
            subscriber = StampedSubscriber(bus, writer.keys.everything, writer.add)

            def on_liveliness(key: str, alive: bool) -> None:
                nonlocal changes
                changes += 1
                writer.liveliness(key, alive, time.time_ns())

            bus.watch_liveliness(writer.keys.alive_any, on_liveliness)
            # Announced once subscribed: a simulator told to wait for `record` starts its
            # clock only when nothing can be missed.
            token = bus.declare_token(writer.keys.alive("record"))
            print(f"zenav record: recording {writer.keys.everything} to {path}", flush=True)
            await wait_for_event(stop, duration)
            token.undeclare()
            subscriber.close()
        finally:
            bus.close()
            writer.close()
    return writer.count, changes



def main(args: argparse.Namespace) -> int:
    setup = tool_setup(args, "record")
    if setup is None:
        return 2
    robot_id, transport = setup
    started = time.monotonic()
    with contextlib.suppress(KeyboardInterrupt):
        count, changes = asyncio.run(record(transport, robot_id, args.file,
                                            duration=args.duration, exclude=tuple(args.exclude)))
        print(f"zenav record: {count} messages and {changes} liveliness changes in "
              f"{time.monotonic() - started:.1f} s -> {args.file} "
              f"({args.file.stat().st_size} B)", flush=True)
    return 0



def add_command(sub: Any) -> None:
    record = sub.add_parser("record", help="record every message of a robot to an MCAP file")
    record.add_argument("file", type=Path)
    record.add_argument("--duration", type=float, help="stop after this many s")
    record.add_argument("--exclude", action="append", default=[], metavar="TOPIC",
                        help="leave out a topic, e.g. sim/truth (repeatable)")
    add_transport_arguments(record)
    record.set_defaults(func=main)
