"""Start one service as its own process: ``zenav service NAME`` or ``python -m ...``.

Every service folder has the same shape: ``params.py`` (the pydantic model with every
default), pure modules, and a thin ``node.py`` with ``Service``, built as
``Service(node, params)``; :data:`SERVICES` and :data:`PLANNERS` say where each lives.
A service with work of its own (the simulator's clock, the motor bridge's watchdog)
has ``async def run()``; when ``run`` returns, the process stops. SIGINT and SIGTERM
stop it cleanly: inputs cancelled, liveliness token and declarations undeclared,
session closed. With ``--standby-lock FILE`` it loads everything, then serves only once it
holds the file's lock: a pair of such processes is a service and its warm spare.
"""

from __future__ import annotations

import argparse
import asyncio
import concurrent.futures
import contextlib
import importlib
import logging
import os
import signal
import sys
import threading
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

from pydantic import BaseModel

from zenav.services.config import (
    DEFAULT_BASE_PORT,
    SERVICE_ORDER,
    ConfigError,
    load_params,
    loopback_mesh,
    read_transport,
)
from zenav.services.inputs import OneLineParser
from zenav.services.transport import (
    NO_ROUTER,
    Bus,
    TransportConfig,
    ZenohBus,
    check_endpoint,
    zenoh_problem,
)
from zenav.services.writable import PathError, check_output_file

if TYPE_CHECKING:
    from zenav.schemas.keys import Keys

# The message schemas (numpy, pydantic models) and the node runtime are imported where they
# are used, not here: `zenav router` shares this module's transport options and would pay
# for them on every restart.

log = logging.getLogger(__name__)

class Where(NamedTuple):
    """Where a service's parameter model and its service class are ("module:Class"), and
    the function that checks its parameters beyond the model before anything starts
    (``check(params)`` raising ValueError, e.g. the simulator's scenario file), if any."""

    params: str
    service: str
    check: str | None = None


PLANNERS: dict[str, Where] = {
    "paper": Where("zenav.services.planner.params:Params", "zenav.services.planner.node:Service"),
    "vfh": Where("zenav.services.baselines.params:VFHParams",
                 "zenav.services.baselines.node:VFHService"),
    "dwa": Where("zenav.services.baselines.params:DWAParams",
                 "zenav.services.baselines.node:DWAService"),
    "apf": Where("zenav.services.baselines.params:APFParams",
                 "zenav.services.baselines.node:APFService"),
    "orca": Where("zenav.services.baselines.params:ORCAParams",
                  "zenav.services.baselines.node:ORCAService"),
}
"""Planner implementations: each reads the same inputs and publishes the same outputs
as the paper's planner, and runs as the ``planner`` service (``--planner NAME``)."""

SERVICES: dict[str, Where] = {
    "simulator": Where("zenav.sim.params:Params", "zenav.sim.node:Service",
                       "zenav.sim.params:check"),
    "laser_driver": Where("zenav.services.laser_driver.params:Params",
                          "zenav.services.laser_driver.node:Service"),
    "perception": Where("zenav.services.perception.params:PerceptionParams",
                        "zenav.services.perception.node:Service"),
    "tracking": Where("zenav.services.tracking.params:TrackingParams",
                      "zenav.services.tracking.node:Service"),
    "planner": PLANNERS["paper"],
    "motor_bridge": Where("zenav.services.motor_bridge.params:Params",
                          "zenav.services.motor_bridge.node:Service"),
}
assert tuple(SERVICES) == SERVICE_ORDER


class Implementation(NamedTuple):
    """A service's parameter model and its class (``Service(node, params)``)."""

    Params: type[BaseModel]
    Service: type[Any]


def _where(name: str, planner: str = "paper") -> Where:
    if name not in SERVICES:
        raise ConfigError(f"no service named {name!r}; the services are {', '.join(SERVICE_ORDER)}")
    if name == "planner":
        if planner not in PLANNERS:
            raise ConfigError(f"no planner named {planner!r}; the planners are "
                              f"{', '.join(PLANNERS)}")
        return PLANNERS[planner]
    return SERVICES[name]


def _load(spec: str) -> Any:
    module, _, attribute = spec.partition(":")
    return getattr(importlib.import_module(module), attribute)


def service_params(name: str, planner: str = "paper") -> type[BaseModel]:
    """The parameter model of a service (without importing its node); ConfigError if none."""
    model: type[BaseModel] = _load(_where(name, planner).params)
    return model


def check_params(name: str, params: BaseModel, planner: str = "paper") -> None:
    """What the service would refuse at start-up, found now: ValueError (ConfigError,
    ScenarioError) saying why, before a session is opened or a process told it runs."""
    where = _where(name, planner)
    if where.check is not None:
        _load(where.check)(params)


def implementation(name: str, planner: str = "paper") -> Implementation:
    """The parameter model and the service class of a service; ConfigError if none."""
    where = _where(name, planner)
    return Implementation(_load(where.params), _load(where.service))



def add_transport_arguments(parser: argparse.ArgumentParser, *, robot_id: bool = True) -> None:
    """Options every process that joins the bus shares (services and tools). A tool whose
    robot id comes from elsewhere (``zenav replay``: the recorded one) leaves out
    ``--robot-id`` (``robot_id=False``), so that a user who gives it hears it is not used."""
    group = parser.add_argument_group("transport")
    if robot_id:
        group.add_argument("--robot-id", default="robot0",
                           help="robot id in every key (default robot0)")
    group.add_argument("--transport", type=Path, metavar="FILE",
                       help="YAML file of transport settings (a TransportConfig: mode, "
                            "listen, connect, ...)")
    group.add_argument("--mode", choices=["peer", "client", "router"],
                       help="Zenoh mode (default peer; a tool given --connect joins as a "
                            "client)")
    group.add_argument("--listen", action="append", default=[], type=endpoint,
                       metavar="ENDPOINT",
                       help="listen on this Zenoh endpoint, e.g. tcp/0.0.0.0:7447 "
                            "(repeatable; default: the loopback mesh of --base-port)")
    group.add_argument("--connect", action="append", default=[], type=endpoint,
                       metavar="ENDPOINT",
                       help="connect to this Zenoh endpoint, e.g. a router at "
                            "tcp/127.0.0.1:7447 (repeatable; default: the loopback mesh "
                            "of --base-port)")
    group.add_argument(
        "--base-port",
        type=base_port,
        default=DEFAULT_BASE_PORT,
        help="first port of the loopback mesh used when no endpoint is given "
             f"(default {DEFAULT_BASE_PORT}: a service on each of tcp/127.0.0.1:"
             f"{DEFAULT_BASE_PORT}...{DEFAULT_BASE_PORT + len(SERVICE_ORDER) - 1}, the "
             f"tools on {DEFAULT_BASE_PORT + len(SERVICE_ORDER)})",
    )


def endpoint(text: str) -> str:
    """``--listen`` / ``--connect``: a Zenoh endpoint of the form Zenoh accepts."""
    try:
        return check_endpoint(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def base_port(text: str) -> int:
    """``--base-port``: the first of the mesh's ports, all of which must be TCP ports."""
    last = 65535 - len(SERVICE_ORDER)
    try:
        port = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number (got {text!r})") from None
    if not 1 <= port <= last:
        raise argparse.ArgumentTypeError(
            f"must be in 1..{last}: the mesh takes {len(SERVICE_ORDER) + 1} ports from it "
            f"(got {port})")
    return port


LOG_LEVELS = ("DEBUG", "INFO", "WARNING", "ERROR", "CRITICAL")


def add_log_level_argument(parser: argparse.ArgumentParser, what: str = "log level") -> None:
    """``--log-level``, one of :data:`LOG_LEVELS` in any case, checked by argparse: a
    wrong one is a one-line usage error before anything starts (every command that
    starts services or joins the bus shares it)."""
    parser.add_argument("--log-level", type=str.upper, choices=LOG_LEVELS, default="INFO",
                        metavar="LEVEL", help=f"{what}: {', '.join(LOG_LEVELS)} "
                                              "(default INFO; any case)")


def transport_from_args(args: argparse.Namespace, service: str | None) -> TransportConfig:
    if args.transport is not None:
        config = read_transport(args.transport)
    elif args.listen or args.connect:
        config = TransportConfig(listen=args.listen, connect=args.connect)
    else:
        config = loopback_mesh(service, args.base_port)
    if args.mode is not None:
        config = config.model_copy(update={"mode": args.mode})
    if config.finds_no_router():  # a client that could never reach a router
        source = f"{args.transport}: " if args.transport is not None else ""
        raise ConfigError(f"{source}{NO_ROUTER}")
    return config


def add_standby_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--standby-lock", type=Path, metavar="FILE",
        help="serve only while holding this file's lock: two processes given the same FILE "
             "make a pair, one serving and one a warm spare that has loaded everything and "
             "takes over the moment the other ends (kill -9 included)")


_HELD: list[int] = []
"""Descriptors of the standby locks this process holds (kept open for its whole life: the
kernel releases the lock when the process ends, however it ends)."""


def check_lock(lock: Path) -> None:
    """ConfigError unless ``lock`` can be opened (its folder created) as a standby lock."""
    try:
        check_output_file(lock)  # makes its folder; a file on the way, /proc, a folder named
    except PathError as exc:
        raise ConfigError(f"--standby-lock {exc}") from None
    try:
        os.close(os.open(lock, os.O_RDWR | os.O_CREAT, 0o644))
    except OSError as exc:
        raise ConfigError(f"--standby-lock {lock}: cannot open it as a lock file "
                          f"({exc.strerror or exc})") from None


def take_over(lock: Path, name: str) -> None:
    """Return once this process holds ``lock``, an exclusive ``flock`` on the file: at once
    when no other process holds it, else the moment its holder ends. The holder's pid is
    written into the file. Meanwhile SIGINT raises KeyboardInterrupt, and SIGTERM ends the
    process (its default action: a spare has nothing to clean up)."""
    import fcntl

    lock.parent.mkdir(parents=True, exist_ok=True)
    fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        log.info("standby: another process serves %s; taking over when it ends", name)
        fcntl.flock(fd, fcntl.LOCK_EX)
        log.info("standby: taking over %s", name)
    _HELD.append(fd)
    os.ftruncate(fd, 0)
    os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)


_OPENING: set[threading.Thread] = set()
"""Threads of this process still inside ``zenoh.open``."""


_CLOSED: list[str] = []
"""The service this process ran, once it has stopped and closed its session."""


def closed_cleanly() -> bool:
    """Whether this process's service has stopped and closed everything it opened: the
    ``zenav`` command then ends the process with ``os._exit`` (after flushing), as all that
    is left of the interpreter's teardown is freeing memory, which took ~0.4 s with six
    services stopping at once on a loaded 2-core machine."""
    return bool(_CLOSED)


def still_opening() -> bool:
    """Whether a session is still being opened in a thread no one waits for any more (the
    service was stopped while it connected): the ``zenav`` command then ends the process
    with ``os._exit``, as Zenoh's native teardown would stall its exit."""
    return any(thread.is_alive() for thread in _OPENING)


class SessionOpening:
    """A Zenoh session being opened on a thread of its own, started before the service
    loads its modules (the planner's and the tracker's pull in scipy). In peer mode
    ``zenoh.open`` returns only once it is linked to every peer it connects to, or after
    its scouting delay (half a second by default) when some are not up yet: time those
    imports now fill instead of following. The session is the same as one opened in
    place: nothing is declared on it before it is open, so a service is no sooner alive,
    nor less connected, than before."""

    def __init__(self, transport: TransportConfig) -> None:
        self._future: concurrent.futures.Future[Any] = concurrent.futures.Future()
        self._lock = threading.Lock()
        self._settled = False  # handed over, or abandoned
        thread = threading.Thread(target=self._open, args=(transport,), name="zenav-open",
                                  daemon=True)
        _OPENING.add(thread)
        thread.start()

    def _open(self, transport: TransportConfig) -> None:
        import zenoh

        session: Any = None
        error: Exception | None = None
        try:
            session = zenoh.open(transport.to_zenoh())
        except Exception as exc:  # raised where the session is awaited
            error = exc
        _OPENING.discard(threading.current_thread())  # before anyone hears of the outcome
        with self._lock:
            if error is not None:
                self._future.set_exception(error)
            elif self._settled:
                session.close()
            else:
                self._future.set_result(session)

    async def session(self) -> Any:
        """The open session (or what ``zenoh.open`` raised); from then on it is the
        caller's to close."""
        session = await asyncio.wrap_future(self._future)
        with self._lock:
            self._settled = True  # nothing left to close here
        return session

    def abandon(self) -> None:
        """The service will not start: close the session, now or once it is open."""
        with self._lock:
            if self._settled:
                return
            self._settled = True
            if self._future.done() and self._future.exception() is None:
                self._future.result().close()


def setup_logging(level: str, name: str) -> None:
    logging.basicConfig(
        level=level.upper(),
        stream=sys.stderr,
        format=f"%(asctime)s {name} %(levelname)s %(message)s",
    )


async def serve(name: str, bus: Bus, keys: Keys, params: Any, planner: str = "paper") -> None:
    """Build the service on ``bus`` and run it until stopped or until its run() ends."""
    from zenav.services.node import Node

    node = Node(name, bus, keys)
    service = implementation(name, planner).Service(node, params)
    loop = asyncio.get_running_loop()
    for signum in (signal.SIGINT, signal.SIGTERM):
        with contextlib.suppress(NotImplementedError, RuntimeError):  # not the main thread
            loop.add_signal_handler(signum, node.request_stop)
    run = getattr(service, "run", None)
    failure: list[BaseException] = []
    if run is not None:

        async def run_then_stop() -> None:
            try:
                await run()
            except asyncio.CancelledError:
                raise
            except Exception as exc:
                failure.append(exc)
            finally:
                node.request_stop()

        node.add_task(run_then_stop(), name="run")
    await node.spin()
    close = getattr(service, "close", None)
    if close is not None:
        close()
    if failure:
        raise failure[0]


def main(name: str, argv: list[str] | None = None) -> int:
    parser = OneLineParser(prog=f"zenav service {name}",
                           epilog=f"Its parameters, their defaults and units: zenav params {name}")
    parser.add_argument("--config", type=Path, action="append", default=[], metavar="FILE",
                        help="YAML parameter file (repeatable; later files win)")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help="override one parameter (dotted names for nested ones)")
    add_log_level_argument(parser)
    if name == "planner":
        parser.add_argument("--planner", default="paper",
                            help=f"implementation: {', '.join(PLANNERS)} (default paper)")
    add_transport_arguments(parser)
    add_standby_argument(parser)
    args = parser.parse_args(argv)
    setup_logging(args.log_level, name)
    from zenav.schemas.keys import Keys, check_robot_id

    try:
        planner = getattr(args, "planner", "paper")
        params = load_params(service_params(name, planner), args.config, args.set)
        check_params(name, params, planner)
        keys = Keys(check_robot_id(args.robot_id))
        transport = transport_from_args(args, name)
        if args.standby_lock is not None:
            check_lock(args.standby_lock)
    except (ConfigError, ValueError) as exc:
        for line in str(exc).splitlines():  # one line per problem, each naming the service
            print(f"{parser.prog}: {line}", file=sys.stderr)
        return 2
    # Its input known good, the service opens its session while it loads its modules (a
    # warm spare stays off the bus until it takes over).
    opening = SessionOpening(transport) if args.standby_lock is None else None
    if args.standby_lock is not None:
        try:
            implementation(name, planner)  # everything loaded before waiting: a warm spare
            take_over(args.standby_lock, name)
        except KeyboardInterrupt:
            return 0

    async def amain() -> None:
        loop = asyncio.get_running_loop()
        session = await opening.session() if opening is not None else None
        bus = ZenohBus(transport, loop, session=session)
        log.info("on the bus for robot %s: Zenoh %s, listening on %s, connecting to %s",
                 keys.robot_id, transport.mode, ", ".join(transport.listen) or "nothing",
                 ", ".join(transport.connect) or "nothing")
        try:
            await serve(name, bus, keys, params, planner)
        finally:
            bus.close()
        _CLOSED.append(name)
        log.info("stopped")

    try:
        implementation(name, planner)  # the service's modules, while the session opens
        asyncio.run(amain())
    except KeyboardInterrupt:
        if opening is not None:
            opening.abandon()
    except Exception as exc:
        if opening is not None:
            opening.abandon()
        log.debug("service %s failed", name, exc_info=True)
        log.error("service %s failed: %s: %s", name, type(exc).__name__, zenoh_problem(exc))
        return 1
    return 0
