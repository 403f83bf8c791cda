"""``zenav router``: a Zenoh router in a Python session, for a stack spread over hosts.

A Python session opened in ``router`` mode is a complete Zenoh router; no ``zenohd``
binary is needed. The robot runs one (under the supervisor, with the robot-side
services as its clients); the server side's services and any monitor connect to it as
clients. It holds the liveliness token ``zenav/<robot>/alive/router`` so monitors see it.
"""

from __future__ import annotations

import argparse
import logging
import re
import signal
import sys
import threading
from pathlib import Path
from types import FrameType
from typing import Any

import zenoh

from zenav.services.config import ConfigError, read_transport
from zenav.services.runner import (
    add_log_level_argument,
    add_standby_argument,
    endpoint,
    setup_logging,
    take_over,
)
from zenav.services.transport import TransportConfig, zenoh_problem

log = logging.getLogger(__name__)

DEFAULT_LISTEN = "tcp/0.0.0.0:7447"
"""Zenoh's own router port, on every interface of the robot."""


def router_transport(args: argparse.Namespace) -> TransportConfig:
    """The router's transport from its options; ConfigError with one line per problem in
    a transport file (``--listen`` and ``--connect`` are checked as they are parsed)."""
    if args.transport is not None:
        config = read_transport(args.transport)
    elif not args.listen and not args.connect:
        config = TransportConfig(mode="router", listen=[DEFAULT_LISTEN])
    else:
        config = TransportConfig(mode="router", listen=args.listen, connect=args.connect)
    return config.model_copy(update={"mode": "router"})


ROBOT_ID = re.compile(r"^[A-Za-z0-9_-]{1,64}$")
"""A robot id as :func:`zenav.schemas.keys.check_robot_id` accepts it (a test keeps the two
equal): checked here without loading the message schemas, so that a restarted router
listens again as soon as Python and Zenoh are up; its clients wait on it."""


def token_key(robot_id: str) -> str:
    """The router's liveliness token, ``Keys(robot_id).alive("router")`` spelled out."""
    return f"zenav/{robot_id}/alive/router"


def main(args: argparse.Namespace) -> int:
    setup_logging(args.log_level, "router")
    try:
        if not ROBOT_ID.match(args.robot_id):
            raise ValueError(f"robot id {args.robot_id!r} must be 1-64 letters, digits, '_' "
                             "or '-' (it becomes part of every key)")
        transport = router_transport(args)
    except (ConfigError, ValueError) as exc:
        for line in str(exc).splitlines():  # one per problem
            print(f"zenav router: {line}", file=sys.stderr)
        return 2
    stop = threading.Event()

    def on_signal(signum: int, frame: FrameType | None) -> None:
        stop.set()

    if args.standby_lock is not None:
        try:
            take_over(args.standby_lock, "router")
        except KeyboardInterrupt:
            return 0
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, on_signal)
    try:
        session: Any = zenoh.open(transport.to_zenoh())
    except Exception as exc:
        log.error("cannot open the router on %s: %s", ", ".join(transport.listen),
                  zenoh_problem(exc))
        return 1
    token = session.liveliness().declare_token(token_key(args.robot_id))
    joining = f", joining the routers at {', '.join(transport.connect)}" if transport.connect \
        else ""
    log.info("router up, listening on %s%s", ", ".join(transport.listen), joining)
    try:
        while not stop.wait(0.5):
            pass
    finally:
        token.undeclare()
        session.close()
    log.info("router stopped")
    return 0


def add_command(sub: Any) -> None:
    router = sub.add_parser("router", help="run a Zenoh router (the robot's, for off-board "
                            "services and monitors)")
    add_log_level_argument(router)
    # A router's own transport options: it is always a router, and the services' loopback
    # mesh (--mode, --base-port) is not its business.
    group = router.add_argument_group("transport")
    group.add_argument("--robot-id", default="robot0",
                       help="robot id of its liveliness token (default robot0)")
    group.add_argument("--transport", type=Path, metavar="FILE",
                       help="YAML file of transport settings (a TransportConfig: listen, "
                            "connect, ...; its mode is router whatever the file says)")
    group.add_argument("--listen", action="append", default=[], type=endpoint,
                       metavar="ENDPOINT",
                       help="listen on this Zenoh endpoint (repeatable; default "
                            f"{DEFAULT_LISTEN} when neither --listen nor --connect is given)")
    group.add_argument("--connect", action="append", default=[], type=endpoint,
                       metavar="ENDPOINT",
                       help="connect to another router at this endpoint (repeatable)")
    add_standby_argument(router)
    router.set_defaults(func=main)
