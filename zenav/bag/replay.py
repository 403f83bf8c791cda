"""``zenav replay``: the messages of an MCAP file published again, at the recorded pace."""

from __future__ import annotations

import argparse
import asyncio
import math
import sys
import time
from pathlib import Path
from typing import Any

from zenav.argtypes import positive_float
from zenav.bag.mcapfile import bag_contents, read_bag
from zenav.schemas.keys import Keys
from zenav.services.config import SERVICE_ORDER, ConfigError
from zenav.services.runner import add_transport_arguments
from zenav.services.transport import Bus
from zenav.tooling import (
    CONNECT_TIMEOUT,
    ConnectError,
    add_connect_timeout,
    open_bus,
    signal_status,
    stop_on_signals,
    tool_transport,
    wait_for_event,
)


def check_replay(path: Path, topics: set[str] | None, rate: float) -> str:
    """The recorded robot id, once the input and options make sense; ValueError with one
    line naming the problem (not MCAP, no such topic in the file, a bad rate)."""
    if not (math.isfinite(rate) and rate > 0):
        raise ValueError(f"--rate must be a finite number above 0 (got {rate})")
    robot, recorded = bag_contents(path)
    unknown = sorted((topics or set()) - recorded)
    if unknown:
        raise ValueError(f"--topics: {', '.join(unknown)} not in {path} (it has "
                         f"{', '.join(sorted(recorded)) or 'no messages'})")
    return robot


WAITABLE: tuple[str, ...] = (*SERVICE_ORDER, "router", "record", "run")
"""What ``--wait-for`` can name: the liveliness tokens on a robot's bus (its services,
its router, a recorder, a run)."""


def parse_wait_for(text: str) -> list[str]:
    """``--wait-for``'s names; ValueError with one line for a name no process announces."""
    names = [name.strip() for name in text.split(",") if name.strip()]
    unknown = [name for name in names if name not in WAITABLE]
    if unknown:
        raise ValueError(f"--wait-for: no process is called {', '.join(unknown)} (the "
                         f"names are {', '.join(WAITABLE)})")
    return names


async def wait_alive(bus: Bus, target: Keys, names: list[str], timeout: float,
                     stop: asyncio.Event) -> bool:
    """Until every one of ``names`` has its liveliness token on the bus: True then, False
    when ``stop`` is set first; TimeoutError naming the missing ones after ``timeout`` s.
    Says once on stderr what it waits for and for how long."""
    loop = asyncio.get_running_loop()
    alive: set[str] = set()
    changed = asyncio.Event()

    def on_liveliness(key: str, is_alive: bool) -> None:
        service = key.rsplit("/", 1)[-1]
        (alive.add if is_alive else alive.discard)(service)
        changed.set()

    bus.watch_liveliness(target.alive_any, on_liveliness)
    await asyncio.sleep(0)  # tokens already there are reported at once
    if set(names) - alive:
        print(f"zenav replay: waiting for {', '.join(names)} on robot {target.robot_id} "
              f"(up to {timeout:g} s)", file=sys.stderr, flush=True)
    deadline = loop.time() + timeout
    stopped = asyncio.ensure_future(stop.wait())
    try:
        while missing := set(names) - alive:
            if stop.is_set():
                return False
            left = deadline - loop.time()
            if left <= 0:
                raise TimeoutError(f"not alive after {timeout:g} s: "
                                   f"{', '.join(sorted(missing))}")
            changed.clear()
            woken = asyncio.ensure_future(changed.wait())
            await asyncio.wait({woken, stopped}, timeout=left,
                               return_when=asyncio.FIRST_COMPLETED)
            woken.cancel()
    finally:
        stopped.cancel()
    return not stop.is_set()


async def replay(transport: Any, path: Path, *, rate: float, topics: set[str] | None,
                 as_robot: str | None, wait_for: list[str], timeout: float,
                 connect_timeout: float = CONNECT_TIMEOUT) -> int:
    """Publish the file's messages again; the number published (SIGINT or SIGTERM stop it
    early, also while it waits for the router or for ``wait_for``)."""
    source = check_replay(path, topics, rate)
    target = Keys(as_robot or source)
    loop = asyncio.get_running_loop()
    stop = asyncio.Event()
    stop_on_signals(stop)
    bus = await open_bus(transport, stop, connect_timeout, "zenav replay")
    if bus is None:
        return 0
    published = 0
    try:
        if wait_for and not await wait_alive(bus, target, wait_for, timeout, stop):
            return 0
        publishers: dict[str, Any] = {}
        start_wall: float | None = None
        start_log = 0
        for item in read_bag(path, topics):
            if stop.is_set():
                break
            if start_wall is None:
                start_wall, start_log = loop.time(), item.log_time
            due = start_wall + (item.log_time - start_log) / 1e9 / rate
            delay = due - loop.time()
            if delay > 0 and await wait_for_event(stop, delay):
                break
            key = f"{target.prefix}/{item.topic}"
            publisher = publishers.get(key)
            if publisher is None:
                publisher = publishers[key] = bus.publisher(key, reliable=True)
            publisher.put(item.payload)
            published += 1
        await asyncio.sleep(0.2)  # let the last messages leave before the session closes
    finally:
        bus.close()
    return published


def main(args: argparse.Namespace) -> int:
    topics = {t.strip() for t in args.topics.split(",") if t.strip()} or None
    try:
        if args.robot_id is not None:
            raise ValueError("--robot-id: replay publishes under the robot id recorded in the "
                             "file; give --as-robot ID to publish under another")
        wait_for = parse_wait_for(args.wait_for)
        transport = tool_transport(args)
        if args.as_robot is not None:
            Keys(args.as_robot)
        started = time.monotonic()
        check_replay(args.file, topics, args.rate)  # before the session: bad input is exit 2
        count = asyncio.run(replay(transport, args.file, rate=args.rate, topics=topics,
                                   as_robot=args.as_robot, wait_for=wait_for,
                                   timeout=args.timeout, connect_timeout=args.connect_timeout))
    except (TimeoutError, ConnectError) as exc:  # before OSError, of which it is a subclass
        print(f"zenav replay: {exc}", file=sys.stderr)
        return 1
    except (ConfigError, ValueError, OSError) as exc:
        for line in str(exc).splitlines():  # one per problem
            print(f"zenav replay: {line}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130
    print(f"zenav replay: {count} messages in {time.monotonic() - started:.1f} s "
          f"at rate {args.rate:g}{'; stopped by a signal' if signal_status(0) else ''}",
          flush=True)
    return signal_status(0)


def add_command(sub: Any) -> None:
    replay = sub.add_parser("replay", help="publish a recorded MCAP file again")
    replay.add_argument("file", type=Path, help="the MCAP file to publish (from zenav record "
                        "or zenav run)")
    replay.add_argument("--rate", type=positive_float, default=1.0,
                        help="speed-up over the recorded timing (default 1: as recorded)")
    replay.add_argument("--topics", default="",
                        help="comma-separated topics to publish, e.g. scan,odom (default all)")
    replay.add_argument("--as-robot", metavar="ID",
                        help="publish under this robot id instead of the recorded one")
    replay.add_argument("--wait-for", default="", metavar="SERVICES",
                        help="comma-separated services whose liveliness is awaited first "
                        f"(any of {', '.join(WAITABLE)}; default none)")
    replay.add_argument("--timeout", type=positive_float, default=30.0,
                        help="s to wait for --wait-for (default 30)")
    add_transport_arguments(replay, robot_id=False)  # the recorded one, or --as-robot
    replay.add_argument("--robot-id", metavar="ID", help=argparse.SUPPRESS)  # refused in main
    add_connect_timeout(replay)
    replay.set_defaults(func=main)
