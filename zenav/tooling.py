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
from collections.abc import Callable, Coroutine
from typing import Any, TypeVar

from zenav.argtypes import positive_float
from zenav.services.config import ConfigError, loopback_mesh, tool_port
from zenav.services.runner import transport_from_args
from zenav.services.transport import TransportConfig, ZenohBus, zenoh_problem

log = logging.getLogger(__name__)

T = TypeVar("T")

CONNECT_TIMEOUT = 5.0
"""Seconds a tool (monitor, record, replay, ``zenav up``'s wait) waits for its router
before it gives up with one line saying so (``--connect-timeout``)."""

CLIENT_EXTRA: dict[str, Any] = {
    # Wait for the router instead of failing to open when it is not up yet (a service
    # under a supervisor may start before the router, or before the link is up).
    "connect/timeout_ms": -1,
    # Retry a lost router every 0.1 s (Zenoh's default backs off to 4 s): a restarted
    # router is joined within 0.1 s of listening again, and a cut link within 0.1 s of
    # coming back. A refused or unanswered connection attempt costs next to nothing.
    "connect/retry": {"period_init_ms": 100, "period_max_ms": 100, "period_increase_factor": 1.0},
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
    """Transport of a tool from the shared transport options (see module doc). A client
    gives up on a missing router after ``--connect-timeout`` s instead of waiting forever.
    A bad option or transport file is a ConfigError with one line per problem."""
    if args.connect and args.mode is None and args.transport is None:
        config = client_transport(list(args.connect))
    else:
        config = transport_from_args(args, None)
        if (args.transport is None and not (args.listen or args.connect)
                and config.mode == "peer"):
            config = on_the_mesh(config, args.base_port)
        config = with_client_defaults(config)
    return with_connect_timeout(config, getattr(args, "connect_timeout", CONNECT_TIMEOUT))


MESH_RETRY: dict[str, Any] = {
    "connect/retry": {"period_init_ms": 100, "period_max_ms": 1000, "period_increase_factor": 2.0},
}
"""How often a tool on the loopback mesh tries a service that is not up yet: from every
0.1 s, backing off to 1 s (Zenoh's default starts at 1 s and backs off to 4 s). A refused
connection on loopback costs next to nothing."""


class MeshTool(TransportConfig):
    """A tool's transport on the loopback mesh (:func:`on_the_mesh`). Its ``listen`` is
    the mesh's tool port when that port was free as the options were read; if another
    process binds it before this session opens, :func:`open_bus` opens the session
    without listening (:meth:`connecting_only`)."""

    def connecting_only(self) -> TransportConfig:
        return TransportConfig.model_validate({**self.model_dump(), "listen": []})


def on_the_mesh(config: TransportConfig, base_port: int) -> MeshTool:
    """A tool's loopback-mesh transport (``config``, from :func:`loopback_mesh`), made to
    hear each service from that service's first message.

    A tool that only connects reaches a service started after it at its next connection
    attempt, and misses what the service sends before then: a recorder started first
    could miss the planner's first global path and event, and seconds of the simulator's
    odometry. Every service connects to the mesh's tool port from its start, so the tool
    listens there when the port is free, and then a service's link to it is made before
    the service sends anything. A second tool finds the port taken and connects only, as
    does one that loses the port to another tool started in the same instant
    (:func:`open_bus` then opens its session without listening). Either way it tries
    services that are not up yet more often (:data:`MESH_RETRY`).
    """
    from zenav.launch import loopback_ports_free

    free = loopback_ports_free([tool_port(base_port)])
    listen = loopback_mesh(None, base_port, tool_listens=free).listen
    return MeshTool.model_validate({**config.model_dump(), "listen": listen,
                                    "extra": {**MESH_RETRY, **config.extra}})


def with_connect_timeout(config: TransportConfig, timeout: float) -> TransportConfig:
    """``config`` whose first connection to a router fails after ``timeout`` s (a client's
    default here is to wait forever, right for a supervised service, wrong for a tool)."""
    if config.mode != "client":
        return config
    extra = {**config.extra, "connect/timeout_ms": max(1, round(timeout * 1000)),
             "connect/exit_on_failure": True}
    return config.model_copy(update={"extra": extra})


def add_connect_timeout(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--connect-timeout", type=positive_float, default=CONNECT_TIMEOUT,
                        metavar="S",
                        help="s to wait for the router before giving up "
                        f"(default {CONNECT_TIMEOUT:g})")


class ConnectError(RuntimeError):
    """The session could not be opened; the message is the one-line reason."""


def router_place(transport: TransportConfig) -> str:
    """Where a client looks for its router, for a message: ``at ENDPOINTS`` or ``found by
    multicast scouting``."""
    if transport.connect:
        return f"at {', '.join(transport.connect)}"
    return "found by multicast scouting"


def connect_problem(transport: TransportConfig, timeout: float, exc: BaseException | None
                    ) -> str:
    """The one line a tool prints when its session does not open."""
    if transport.mode == "client":
        return f"no Zenoh router {router_place(transport)} after {timeout:g} s: is it running?"
    detail = f": {zenoh_problem(exc)}" if exc is not None else ""
    return f"cannot open a Zenoh {transport.mode} session within {timeout:g} s{detail}"


_OPENING: set[threading.Thread] = set()
"""Threads still inside ``zenoh.open`` (a tool stopped while it was connecting)."""


def still_opening() -> bool:
    """Whether a session is still being opened in a thread no one waits for. The
    interpreter's own exit then stalls for seconds in Zenoh's native teardown; the
    ``zenav`` command ends such a process with ``os._exit`` instead (after flushing)."""
    return any(thread.is_alive() for thread in _OPENING)


WAITING_NOTE_AFTER = 1.0
"""s after which a tool still connecting says on stderr what it waits for."""


async def open_bus(transport: TransportConfig, stop: asyncio.Event,
                   timeout: float = CONNECT_TIMEOUT, command: str | None = None
                   ) -> ZenohBus | None:
    """A :class:`ZenohBus` on the running loop, its session opened in a thread of its own:
    opening blocks the calling thread while a client looks for its router, and a blocked
    main thread would ignore SIGINT, SIGTERM and ``--duration``. None when ``stop`` is set
    first; :class:`ConnectError` when the session does not open within ``timeout`` s (plus
    a grace second: a client's own connect timeout is ``timeout``). With ``command``, a
    client still waiting after :data:`WAITING_NOTE_AFTER` s says so on stderr."""
    import zenoh

    loop = asyncio.get_running_loop()
    opened: asyncio.Future[Any] = loop.create_future()
    conf = transport.to_zenoh()

    def deliver(session: Any, exc: BaseException | None) -> None:
        if opened.done():  # nobody waits any more: close what came too late
            if session is not None:
                with contextlib.suppress(Exception):
                    session.close()
        elif exc is not None:
            opened.set_exception(exc)
        else:
            opened.set_result(session)

    def work() -> None:
        session: Any = None
        error: BaseException | None = None
        try:
            try:
                session = zenoh.open(conf)
            except Exception:
                if not (isinstance(transport, MeshTool) and transport.listen):
                    raise
                # Another tool took the mesh's tool port since the options were read.
                session = zenoh.open(transport.connecting_only().to_zenoh())
        except Exception as exc:  # handed to the loop
            error = exc
        finally:
            _OPENING.discard(threading.current_thread())
        try:
            loop.call_soon_threadsafe(deliver, session, error)
        except RuntimeError:  # the loop is closed: the tool stopped meanwhile
            if session is not None:
                with contextlib.suppress(Exception):
                    session.close()

    opener = threading.Thread(target=work, name="zenav-open", daemon=True)
    _OPENING.add(opener)
    opener.start()
    stopped = asyncio.ensure_future(stop.wait())
    try:
        if command is not None and transport.mode == "client" and timeout > WAITING_NOTE_AFTER:
            await asyncio.wait({opened, stopped}, timeout=WAITING_NOTE_AFTER,
                               return_when=asyncio.FIRST_COMPLETED)
            if not (opened.done() or stopped.done()):
                print(f"{command}: waiting for the router {router_place(transport)} "
                      f"(up to {timeout:g} s)", file=sys.stderr, flush=True)
        await asyncio.wait({opened, stopped}, timeout=timeout + 1.0,
                           return_when=asyncio.FIRST_COMPLETED)
    finally:
        stopped.cancel()
    if not opened.done():
        opened.cancel()
        if stop.is_set():
            return None
        raise ConnectError(connect_problem(transport, timeout, None))
    if opened.exception() is not None:
        raise ConnectError(connect_problem(transport, timeout, opened.exception()))
    return ZenohBus(transport, loop, session=opened.result())


def tool_setup(args: argparse.Namespace, command: str) -> tuple[str, TransportConfig] | None:
    """(robot id, transport) of a tool from its options; None after printing the reason
    (the tool then exits with status 2)."""
    from zenav.schemas.keys import check_robot_id

    try:
        return check_robot_id(args.robot_id), tool_transport(args)
    except (ConfigError, ValueError) as exc:
        for line in str(exc).splitlines():  # one per problem
            print(f"zenav {command}: {line}", file=sys.stderr)
        return None


def run_tool(command: str, main: Coroutine[Any, Any, None],
             failures: tuple[type[Exception], ...] = ()) -> int:
    """Run a tool's main coroutine to the end: 0 when it finishes, 130 (143) when SIGINT
    (SIGTERM) stopped it, 1 with one line ``zenav COMMAND: reason`` when the router cannot
    be reached or one of ``failures`` (the tool's own ways to fail at start, e.g. a port in
    use) is raised."""
    expected: tuple[type[Exception], ...] = (ConnectError, *failures)
    try:
        asyncio.run(main)
    except KeyboardInterrupt:
        return 130
    except expected as exc:
        print(f"zenav {command}: {exc}", file=sys.stderr)
        return 1
    return signal_status(0)


_SIGNALLED: list[int] = []
"""The signals :func:`stop_on_signals` caught in this process, in order."""


def signal_status(otherwise: int) -> int:
    """The exit status of a tool that has stopped: 128 + the signal that stopped it (130
    for SIGINT, 143 for SIGTERM, as a shell expects), else ``otherwise``."""
    return 128 + _SIGNALLED[0] if _SIGNALLED else otherwise


def stop_on_signals(stop: asyncio.Event) -> None:
    """Set ``stop`` on SIGINT or SIGTERM (call from the running loop's thread); the signal
    is kept for :func:`signal_status`."""
    loop = asyncio.get_running_loop()

    def caught(signum: int) -> None:
        _SIGNALLED.append(signum)
        stop.set()

    for signum in (signal.SIGINT, signal.SIGTERM):
        with contextlib.suppress(NotImplementedError, RuntimeError):
            loop.add_signal_handler(signum, caught, signum)


async def wait_for_event(event: asyncio.Event, timeout: float | None) -> bool:
    """Whether ``event`` was set within ``timeout`` s (None: however long it takes)."""
    try:
        await asyncio.wait_for(event.wait(), timeout=timeout)
    except TimeoutError:
        return False
    return True


QUIET_NOTE_AFTER = 3.0
"""s of hearing nothing of the robot after which a tool says on stderr where to look."""


def quiet_note(command: str, transport: TransportConfig, robot_id: str,
               after: float = QUIET_NOTE_AFTER) -> str:
    """The one line a tool prints when it has heard nothing of ``robot_id`` for ``after``
    s. On the loopback mesh (a tool's default, where ``zenav run`` puts its services) the
    usual cause is a stack started with ``zenav up``: its services talk only through its
    router, so a tool that does not connect to that router hears none of them."""
    head = f"zenav {command}: nothing heard from {robot_id} in {after:g} s"
    if isinstance(transport, MeshTool):
        return (f"{head} on the loopback mesh, where `zenav run` puts its services; a stack "
                "started with `zenav up` is reached through its router: --connect "
                "tcp/127.0.0.1:7447 (its default)")
    if transport.mode == "client":
        return (f"{head} through the router {router_place(transport)}: are the services "
                "up and joined to it, with this --robot-id?")
    return f"{head}: are the services up on this transport, with this --robot-id?"


class Heard:
    """Whether a tool has heard anything of its robot yet: a message, or a liveliness token
    other than its own. Marked from any thread."""

    def __init__(self) -> None:
        self.anything = False

    def mark(self) -> None:
        self.anything = True


async def note_if_quiet(heard: Heard, stop: asyncio.Event, line: str,
                        after: float = QUIET_NOTE_AFTER) -> None:
    """Print ``line`` on stderr, once, if nothing is heard within ``after`` s of the call
    and the tool is not stopped first. Run as a task beside the tool's own work, so a
    tool that hears nothing says why instead of showing an empty view without a word."""
    if not await wait_for_event(stop, after) and not heard.anything:
        print(line, file=sys.stderr, flush=True)


SampleCallback = Callable[[str, bytes, int], None]
"""Called on the asyncio loop with (key, payload, wall-clock receive time in ns)."""


class StampedSubscriber:
    """Every sample of ``key_expr``, stamped with the wall clock in Zenoh's own callback
    (before any queueing), handed to ``callback`` on the asyncio loop. For tools that
    measure time (monitor latency, recorder log times); services use ``Bus.subscribe``.
    ``heard``, when given, is marked at every sample (for :func:`note_if_quiet`)."""

    def __init__(self, bus: ZenohBus, key_expr: str, callback: SampleCallback,
                 heard: Heard | None = None) -> None:
        loop = asyncio.get_running_loop()

        def on_sample(sample: Any) -> None:
            if heard is not None:
                heard.mark()
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
