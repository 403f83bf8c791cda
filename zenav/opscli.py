"""The operating commands of ``zenav``: up, down, ctl, router, monitor, record, replay,
graph. Each parser sets ``func``, which ``zenav.cli.main`` calls with the arguments."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from zenav.services.runner import add_transport_arguments


def _router(args: argparse.Namespace) -> int:
    from zenav.router import main

    return main(args)


def _monitor(args: argparse.Namespace) -> int:
    from zenav.monitor import main

    return main(args)


def _record(args: argparse.Namespace) -> int:
    from zenav.bag import record_main

    return record_main(args)


def _replay(args: argparse.Namespace) -> int:
    from zenav.bag import replay_main

    return replay_main(args)


def _graph(args: argparse.Namespace) -> int:
    from zenav.graph import main

    return main(args)


def add_commands(sub: Any) -> None:
    from zenav.deploy import add_commands as add_deploy_commands

    add_deploy_commands(sub)

    router = sub.add_parser("router", help="run a Zenoh router (the robot's, for off-board "
                            "services and monitors)")
    router.add_argument("--log-level", default="INFO")
    add_transport_arguments(router)
    router.set_defaults(func=_router)

    monitor = sub.add_parser(
        "monitor", help="live read-only view of a running stack",
        description="Live view: robot pose and speed, obstacles, the planner's scenario and "
        "action, each service's liveliness, message rates, scan-to-command latency. "
        "--connect ENDPOINT joins a router as a client from any host.")
    monitor.add_argument("--jsonl", action="store_true",
                         help="print events and snapshots as JSON lines, not a screen")
    monitor.add_argument("--period", type=float, default=0.25,
                         help="s between screen refreshes or snapshots (default 0.25)")
    monitor.add_argument("--duration", type=float, help="stop after this many s")
    monitor.add_argument("--silence", type=float, default=0.5,
                         help="a topic silent this long (s, at least 4 typical gaps) counts "
                         "as stopped (default 0.5)")
    add_transport_arguments(monitor)
    monitor.set_defaults(func=_monitor)

    record = sub.add_parser("record", help="record every message of a robot to an MCAP file")
    record.add_argument("file", type=Path)
    record.add_argument("--duration", type=float, help="stop after this many s")
    record.add_argument("--exclude", action="append", default=[], metavar="TOPIC",
                        help="leave out a topic, e.g. sim/truth (repeatable)")
    add_transport_arguments(record)
    record.set_defaults(func=_record)

    replay = sub.add_parser("replay", help="publish a recorded MCAP file again")
    replay.add_argument("file", type=Path)
    replay.add_argument("--rate", type=float, default=1.0,
                        help="speed-up over the recorded timing (default 1: as recorded)")
    replay.add_argument("--topics", default="",
                        help="comma-separated topics to publish, e.g. scan,odom (default all)")
    replay.add_argument("--as-robot", metavar="ID",
                        help="publish under this robot id instead of the recorded one")
    replay.add_argument("--wait-for", default="", metavar="SERVICES",
                        help="comma-separated services whose liveliness is awaited first")
    replay.add_argument("--timeout", type=float, default=30.0,
                        help="s to wait for --wait-for (default 30)")
    add_transport_arguments(replay)
    replay.set_defaults(func=_replay)

    graph = sub.add_parser("graph", help="print each service's input and output keys with "
                           "their message types (as in deploy/graph.yaml)")
    graph.set_defaults(func=_graph)
