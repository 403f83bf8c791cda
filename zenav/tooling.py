"""What the tool processes (router, monitor, record, replay, ``zenav up``) share: how they
join the bus, and how they stop on SIGINT or SIGTERM.

A tool given ``--connect ENDPOINT`` and no ``--mode`` joins as a Zenoh **client** of that
endpoint (a router): peers behind a router get no data from each other, clients do.
Without an endpoint it joins the embedded loopback mesh of ``zenav service`` processes.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import logging
import signal
import sys
import threading
import time
from collections.abc import Callable
from typing import Any, TypeVar

from zenav.services.runner import transport_from_args
from zenav.services.transport import TransportConfig, ZenohBus

log = logging.getLogger(__name__)

T = TypeVar("T")

CLIENT_EXTRA: dict[str, Any] = {
    # Wait for the router instead of failing to open when it is not up yet (a service
    # under a supervisor may start before the router, or before the link is up).
    "connect/timeout_ms": -1,
    # Retry a lost router every 0.25..0.5 s (Zenoh's default backs off to 4 s): after a
    # cut link comes back the stack resumes within half a second.
    "connect/retry": {"period_init_ms": 250, "period_max_ms": 500, "period_increase_factor": 1.5},
}
"""Zenoh settings every client of a zenav router gets, unless its configuration says
otherwise."""


def with_client_defaults(config: TransportConfig) -> TransportConfig:
    """``config`` with :data:`CLIENT_EXTRA` under its own extra settings, when a client."""
    if config.mode != "client":
        return config
    return config.model_copy(update={"extra": {**CLIENT_EXTRA, **config.extra}})


def client_transport(connect: list[str], **extra: Any) -> TransportConfig:
    return with_client_defaults(TransportConfig(mode="client", connect=connect, extra=extra))


def tool_transport(args: argparse.Namespace) -> TransportConfig:
    """Transport of a tool from the shared transport options (see module doc)."""
    if args.connect and args.mode is None and args.transport is None:
        return client_transport(list(args.connect))
    return with_client_defaults(transport_from_args(args, None))


def tool_setup(args: argparse.Namespace, command: str) -> tuple[str, TransportConfig] | None:
    """(robot id, transport) of a tool from its options; None after printing the reason
    (the tool then exits with status 2)."""
    from zenav.schemas.keys import check_robot_id
    from zenav.services.config import ConfigError

    try:
        return check_robot_id(args.robot_id), tool_transport(args)
    except (ConfigError, ValueError) as exc:
        print(f"zenav {command}: {exc}", file=sys.stderr)
        return None


def stop_on_signals(stop: asyncio.Event) -> None:
    """Set ``stop`` on SIGINT or SIGTERM (call from the running loop's thread)."""
    loop = asyncio.get_running_loop()
    for signum in (signal.SIGINT, signal.SIGTERM):
        with contextlib.suppress(NotImplementedError, RuntimeError):
            loop.add_signal_handler(signum, stop.set)


async def wait_for_event(event: asyncio.Event, timeout: float | None) -> bool:
    """Whether ``event`` was set within ``timeout`` s (None: however long it takes)."""
    try:
        await asyncio.wait_for(event.wait(), timeout=timeout)
    except TimeoutError:
        return False
    return True


SampleCallback = Callable[[str, bytes, int], None]
"""Called on the asyncio loop with (key, payload, wall-clock receive time in ns)."""


class StampedSubscriber:
    """Every sample of ``key_expr``, stamped with the wall clock in Zenoh's own callback
    (before any queueing), handed to ``callback`` on the asyncio loop. For tools that
    measure time (monitor latency, recorder log times); services use ``Bus.subscribe``."""

    def __init__(self, bus: ZenohBus, key_expr: str, callback: SampleCallback) -> None:
        loop = asyncio.get_running_loop()

        def on_sample(sample: Any) -> None:
            try:
                now = time.time_ns()
                loop.call_soon_threadsafe(callback, str(sample.key_expr),
                                          sample.payload.to_bytes(), now)
            except RuntimeError:  # the loop is closed: the tool is stopping
                pass
            except Exception:  # never let an exception reach Zenoh's thread
                log.exception("subscriber callback failed on %s", key_expr)

        self._handle: Any = bus.session.declare_subscriber(key_expr, on_sample)

    def close(self) -> None:
        if self._handle is not None:
            with contextlib.suppress(Exception):
                self._handle.undeclare()
            self._handle = None


class ThreadedBus:
    """A :class:`ZenohBus` whose asyncio loop runs in a thread of its own, for a tool that
    is not asynchronous (a benchmark that listens while its main thread waits and
    measures). Declare subscribers with :meth:`call`: they belong on the bus's loop."""

    def __init__(self, transport: TransportConfig) -> None:
        self.loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self.loop.run_forever, name="zenav-bus",
                                        daemon=True)
        self._thread.start()
        try:
            self.bus: ZenohBus = self.call(lambda: ZenohBus(transport, self.loop))
        except BaseException:
            self._stop()
            raise

    def call(self, function: Callable[[], T]) -> T:
        """``function()`` run on the bus's loop; its result."""

        async def run() -> T:
            return function()

        return asyncio.run_coroutine_threadsafe(run(), self.loop).result()

    def _stop(self) -> None:
        self.loop.call_soon_threadsafe(self.loop.stop)
        self._thread.join(5.0)
        self.loop.close()

    def close(self) -> None:
        try:
            self.call(self.bus.close)
        finally:
            self._stop()
