"""``zenav record``: a robot's messages and liveliness changes into an MCAP file, with
the same data in Foxglove's well-known schemas beside them (:mod:`zenav.foxglove`)."""

from __future__ import annotations

import argparse
import asyncio
import sys
import time
from pathlib import Path
from typing import Any

from zenav.argtypes import positive_float
from zenav.bag.mcapfile import BagWriter
from zenav.services.runner import add_transport_arguments
from zenav.services.writable import PathError, check_output_file
from zenav.tooling import (
    CONNECT_TIMEOUT,
    ConnectError,
    Heard,
    StampedSubscriber,
    add_connect_timeout,
    note_if_quiet,
    open_bus,
    quiet_note,
    signal_status,
    stop_on_signals,
    tool_setup,
    wait_for_event,
)


def recordable_topic(topic: str) -> str:
    """A topic ``--exclude`` can name (``scan``, ``sim/truth``, ``status/planner``, ...);
    ArgumentTypeError listing them otherwise."""
    from zenav.schemas import keys

    names = [t.name for t in keys.TOPICS]
    service = topic.removeprefix(keys.STATUS.name + "/")  # status/SERVICE
    if topic in names or (service != topic and service.replace("_", "").isalnum()):
        return topic
    raise argparse.ArgumentTypeError(f"no topic {topic!r}; the topics are {', '.join(names)} "
                                     f"and {keys.STATUS.name}/SERVICE")


async def record(transport: Any, robot_id: str, path: Path, *, duration: float | None,
                 exclude: tuple[str, ...], connect_timeout: float = CONNECT_TIMEOUT
                 ) -> tuple[int, int] | None:
    """Record until SIGINT/SIGTERM or ``duration``; (messages, liveliness changes), or
    None when stopped before the session opened (then no file is written)."""
    loop = asyncio.get_running_loop()
    stop = asyncio.Event()
    stop_on_signals(stop)
    if duration is not None:
        loop.call_later(duration, stop.set)
    changes = 0
    bus = await open_bus(transport, stop, connect_timeout, "zenav record")
    if bus is None:
        return None
    try:
        stream = path.open("wb")
    except BaseException:
        bus.close()
        raise
    with stream:
        writer = BagWriter(stream, robot_id, exclude, foxglove=True)
        try:
            heard = Heard()
            own = writer.keys.alive("record")
            subscriber = StampedSubscriber(bus, writer.keys.everything, writer.add, heard)

            def on_liveliness(key: str, alive: bool) -> None:
                nonlocal changes
                changes += 1
                if key != own:
                    heard.mark()
                writer.liveliness(key, alive, time.time_ns())

            bus.watch_liveliness(writer.keys.alive_any, on_liveliness)
            # Announced once subscribed: a simulator told to wait for `record` starts its
            # clock only when nothing can be missed.
            token = bus.declare_token(own)
            print(f"zenav record: recording {writer.keys.everything} to {path}", flush=True)
            quiet = asyncio.create_task(
                note_if_quiet(heard, stop, quiet_note("record", transport, robot_id)))
            await wait_for_event(stop, None)
            quiet.cancel()
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
    try:
        check_output_file(args.file)
    except PathError as exc:
        print(f"zenav record: {exc}", file=sys.stderr)
        return 2
    started = time.monotonic()
    try:
        done = asyncio.run(record(transport, robot_id, args.file, duration=args.duration,
                                  exclude=tuple(args.exclude),
                                  connect_timeout=args.connect_timeout))
        if done is None:
            print("zenav record: stopped before the session opened; nothing recorded",
                  file=sys.stderr)
            return signal_status(0)
        count, changes = done
        print(f"zenav record: {count} messages and {changes} liveliness changes in "
              f"{time.monotonic() - started:.1f} s -> {args.file} "
              f"({args.file.stat().st_size} B)", flush=True)
    except KeyboardInterrupt:
        return 130
    except ConnectError as exc:
        print(f"zenav record: {exc}", file=sys.stderr)
        return 1
    except OSError as exc:
        print(f"zenav record: {args.file}: cannot write ({exc.strerror or exc})",
              file=sys.stderr)
        return 2
    return signal_status(0)  # 130 after SIGINT: the file is complete all the same



def add_command(sub: Any) -> None:
    record = sub.add_parser("record", help="record every message of a robot to an MCAP file")
    record.add_argument("file", type=Path, help="the MCAP file to write (replaced if it exists)")
    record.add_argument("--duration", type=positive_float, help="stop after this many s")
    record.add_argument("--exclude", type=recordable_topic, action="append", default=[],
                        metavar="TOPIC",
                        help="leave out a topic, e.g. sim/truth (repeatable)")
    add_transport_arguments(record)
    add_connect_timeout(record)
    record.set_defaults(func=main)
