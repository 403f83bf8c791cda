"""``zenav foxglove``: a robot's messages served live to Foxglove, read-only.

It joins the bus like the monitor (``--connect ENDPOINT`` from any host), converts each
sample with the same step as recordings (:class:`zenav.foxglove.recording.SampleConverter`)
and logs it on the Foxglove SDK's WebSocket server (Foxglove's WebSocket protocol). In
Foxglove: Open connection > Foxglove WebSocket > ``ws://HOST:8765``; the layout in
``deploy/foxglove/zenav.json`` shows the 3D scene, the scan and the planner's log.
"""

from __future__ import annotations

import argparse
import asyncio
import sys
from typing import Any

import foxglove
from foxglove import channels

from zenav.argtypes import port, positive_float
from zenav.foxglove.recording import SampleConverter
from zenav.foxglove.scene import TOPICS
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
)


class LiveChannels:
    """One Foxglove SDK channel per topic, in a context of their own."""

    def __init__(self, robot_id: str) -> None:
        self.context = foxglove.Context()
        self.converter = SampleConverter(robot_id)
        self.channels: dict[str, Any] = {
            topic: getattr(channels, f"{kind.__name__}Channel")(topic, context=self.context)
            for topic, kind in TOPICS.items()
        }
        self.count = 0

    def add(self, key: str, payload: bytes, log_time_ns: int) -> None:
        for topic, message, _ in self.converter.convert(key, payload):
            self.channels[topic].log(message, log_time=log_time_ns)
            self.count += 1


async def serve(transport: Any, robot_id: str, host: str, port: int,
                duration: float | None = None,
                connect_timeout: float = CONNECT_TIMEOUT) -> None:
    loop = asyncio.get_running_loop()
    stop = asyncio.Event()
    stop_on_signals(stop)
    if duration is not None:
        loop.call_later(duration, stop.set)
    live = LiveChannels(robot_id)
    server = foxglove.start_server(name=f"zenav {robot_id}", host=host, port=port,
                                   context=live.context)
    bus = await open_bus(transport, stop, connect_timeout, "zenav foxglove")
    if bus is None:  # stopped while connecting
        server.stop()
        return
    heard = Heard()
    subscriber = StampedSubscriber(bus, live.converter.keys.everything, live.add, heard)
    print(f"zenav foxglove: serving {live.converter.keys.everything} on "
          f"ws://{host}:{server.port}", flush=True)
    quiet = asyncio.create_task(
        note_if_quiet(heard, stop, quiet_note("foxglove", transport, robot_id)))
    try:
        await stop.wait()
    finally:
        quiet.cancel()
        subscriber.close()
        bus.close()
        server.stop()


def host_problem(host: str) -> str | None:
    """Why the server cannot listen on ``host`` (a name that does not resolve), or None. An
    address literal is taken as it is; a name is looked up as the server would."""
    import ipaddress
    import socket

    try:
        ipaddress.ip_address(host)
        return None
    except ValueError:
        pass
    try:
        socket.getaddrinfo(host, None, type=socket.SOCK_STREAM)
    except (socket.gaierror, UnicodeError) as exc:
        return f"--host {host!r}: not an address or a host name that resolves ({exc})"
    return None


def main(args: argparse.Namespace) -> int:
    setup = tool_setup(args, "foxglove")
    if setup is None:
        return 2
    if (problem := host_problem(args.host)) is not None:
        print(f"zenav foxglove: {problem}", file=sys.stderr)
        return 2
    robot_id, transport = setup
    # RuntimeError: the SDK's server could not bind its port
    return run_tool("foxglove", serve(transport, robot_id, args.host, args.port, args.duration,
                                      args.connect_timeout), failures=(RuntimeError,))


def add_command(sub: Any) -> None:
    parser = sub.add_parser(
        "foxglove", help="serve a robot's messages live to Foxglove (WebSocket, read-only)",
        description="Foxglove's WebSocket protocol through the Foxglove SDK's server: the "
        "scan, the robot's frames and pose, obstacles, tracks, the planner's target, global path, "
        "map and events, and ground truth in simulation. --connect ENDPOINT joins a router as a "
        "client from any host.")
    parser.add_argument("--host", default="127.0.0.1",
                        help="address to serve on (default 127.0.0.1; 0.0.0.0 for any host)")
    parser.add_argument("--port", type=port, default=8765, help="WebSocket port (default 8765)")
    parser.add_argument("--duration", type=positive_float, help="stop after this many s")
    add_transport_arguments(parser)
    add_connect_timeout(parser)
    parser.set_defaults(func=main)
