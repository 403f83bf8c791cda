"""The in-process engine: the six production services in one process and one loop.

``zenav run SCENARIO --engine inprocess`` builds every service exactly as its own process
would (the same ``Service(node, params)`` class, its parameters from the same
scenario-to-parameters function and read back the way a service process reads its YAML
file) and joins them on one :class:`~zenav.services.transport.InMemoryBus`. Every message
is encoded and decoded by the codec as it would be over Zenoh; only the processes and
the network are left out. The simulator's lockstep clock drives the run, as in the
stack, so the two engines give the same trajectory and events tick by tick
(``tests/integration/test_engine_equal.py`` checks it).

Nothing in the run may depend on how fast this machine is. The services' time-based
fallbacks (the simulator's retransmit and answer timeout, the status period, the
latched result's repeat) all wait on the asyncio loop's clock, and the engine's loop,
:class:`IdleClockLoop`, has a clock that only moves while the loop has nothing else to
do: a fallback fires only when the pipeline is really stuck, at the same point of every
run, never because a step was slow. The stamp checks that read the wall clock
(:meth:`Node.check_stamp`'s resynchronisation) only act on refused stamps, which a
lockstep run never sends.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import selectors
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from zenav.schemas import keys
from zenav.schemas.codec import DecodeError, decode
from zenav.schemas.keys import Keys
from zenav.schemas.messages import GlobalPath, OccupancyMap, PlannerEvent, RunResult
from zenav.services.config import SERVICE_ORDER, Layer, resolve
from zenav.services.node import Node
from zenav.services.runner import implementation
from zenav.services.transport import InMemoryBus

ENGINES = ("stack", "inprocess")
"""How ``zenav run`` and the batch runner run a scenario: six processes over Zenoh (the
acceptance path and the default), or this module's one process."""

PATHS_KEPT = 10_000
"""Global path messages buffered between two looks (the planner sends one each time it
plans again and repeats it every ``path_period``; only the distinct ones are kept, see
:func:`add_path`)."""

RESULT_TIMEOUT = 3600.0
"""Loop-clock seconds the engine waits for the simulator's result. The loop's clock
only moves when every service is idle, so this is reached only by a pipeline that stopped
answering (the simulator's own answer timeout normally ends such a run first)."""


class EngineError(RuntimeError):
    """The in-process run could not be completed; the message is the one-line reason."""


class _IdleSelector(selectors.BaseSelector):
    """A selector that never sleeps: when the loop would wait ``timeout`` s for I/O and
    none is ready, it moves the loop's clock on by ``timeout`` instead."""

    def __init__(self, inner: selectors.BaseSelector, loop: IdleClockLoop) -> None:
        self._inner = inner
        self._loop = loop

    def register(self, fileobj: Any, events: int, data: Any = None) -> selectors.SelectorKey:
        return self._inner.register(fileobj, events, data)

    def unregister(self, fileobj: Any) -> selectors.SelectorKey:
        return self._inner.unregister(fileobj)

    def modify(self, fileobj: Any, events: int, data: Any = None) -> selectors.SelectorKey:
        return self._inner.modify(fileobj, events, data)

    def select(self, timeout: float | None = None) -> list[tuple[selectors.SelectorKey, int]]:
        ready = self._inner.select(0)
        if ready or (timeout is not None and timeout <= 0):
            return ready
        if timeout is None:  # nothing scheduled at all: only I/O (a signal) can wake us
            return self._inner.select(1.0)
        self._loop.advance(timeout)
        return ready

    def close(self) -> None:
        self._inner.close()

    def get_map(self) -> Mapping[Any, selectors.SelectorKey]:
        return self._inner.get_map()


class IdleClockLoop(asyncio.SelectorEventLoop):
    """An event loop whose clock stands still while there is work to do and jumps to the
    next timer when there is none: timeouts measure idleness, not the machine's speed."""

    def __init__(self) -> None:
        self._now = 0.0
        super().__init__(_IdleSelector(selectors.DefaultSelector(), self))

    def time(self) -> float:
        return self._now

    def advance(self, seconds: float) -> None:
        self._now += seconds


def read_back(name: str, values: Mapping[str, Any], planner: str = "paper") -> Any:
    """A service's parameters as its process builds them from the YAML file ``zenav run``
    writes for it (:func:`zenav.launch.write_params`, then ``load_params``)."""
    text = yaml.safe_dump(dict(values), sort_keys=False)
    layer = Layer("file", f"{name} parameters", yaml.safe_load(text) or {})
    return resolve(implementation(name, planner).Params, [layer])[0]


IGNORED = frozenset({"wall_time", "engine", "unclean_exits"})
"""Record fields that say how a run was made, not what happened in it."""


def first_difference(stack: Mapping[str, Any], inprocess: Mapping[str, Any]) -> str | None:
    """Where two run records part: the first trajectory row, the first event, or the first
    other field that differs (``None`` when they are the same run)."""
    rows_a, rows_b = stack.get("trajectory", []), inprocess.get("trajectory", [])
    for i, (a, b) in enumerate(zip(rows_a, rows_b, strict=False)):
        if a != b:
            return f"trajectory row {i}: stack {a} vs in-process {b}"
    if len(rows_a) != len(rows_b):
        return f"trajectory lengths: stack {len(rows_a)} vs in-process {len(rows_b)}"
    events_a, events_b = stack.get("events", []), inprocess.get("events", [])
    for i, (a, b) in enumerate(zip(events_a, events_b, strict=False)):
        if a != b:
            return f"event {i}: stack {a} vs in-process {b}"
    for name in sorted((set(stack) | set(inprocess)) - IGNORED):
        if stack.get(name) != inprocess.get(name):
            return f"{name}: stack {stack.get(name)!r} vs in-process {inprocess.get(name)!r}"
    return None


@dataclass(repr=False)
class EngineRun:
    """What the engine gathered: the simulator's result and the planner's events."""

    result: RunResult
    events: list[PlannerEvent]
    counters: dict[str, dict[str, Any]]
    path: GlobalPath | None = None  # the newest global path the planner published
    occupancy: OccupancyMap | None = None  # and the newest map
    paths: list[GlobalPath] = field(default_factory=list)  # each distinct path, oldest first

    def __repr__(self) -> str:
        # Short: asyncio's runner formats the main task (and so this, its result) into
        # an error message it then drops, twice a run; the full repr of the record's
        # arrays cost 16 ms each time (a crowd case).
        return (f"EngineRun({self.result.outcome} at t={self.result.time:.2f} s, "
                f"{len(self.events)} events, {len(self.paths)} paths)")


def add_path(paths: list[GlobalPath], path: GlobalPath) -> None:
    """Append ``path`` to ``paths`` (oldest first) unless it repeats the last of them: the
    planner sends an unchanged path again every ``path_period``, and each distinct path
    is kept once, so a long run does not pile up copies."""
    if not (paths and path.repeats(paths[-1])):
        paths.append(path)


def unique_events(payloads: list[bytes], key: str) -> list[PlannerEvent]:
    """Decode event payloads, each sequence number once (history and live overlap)."""
    seen: set[int] = set()
    events: list[PlannerEvent] = []
    for payload in payloads:
        try:
            event = decode(payload, PlannerEvent, key)
        except DecodeError:
            continue
        if event.seq not in seen:
            seen.add(event.seq)
            events.append(event)
    return events


async def _run_services(params: Mapping[str, Mapping[str, Any]], planner: str,
                        robot_id: str) -> EngineRun:
    bus = InMemoryBus(keep_published=False)
    k = Keys(robot_id)
    nodes: dict[str, Node] = {}
    services: dict[str, Any] = {}
    for name in SERVICE_ORDER:
        node = Node(name, bus, k)
        nodes[name] = node
        services[name] = implementation(name, planner).Service(
            node, read_back(name, params.get(name, {}), planner))
    failures: dict[str, BaseException] = {}

    def add_run(name: str, node: Node, service: Any) -> None:
        run = getattr(service, "run", None)
        if run is None:
            return

        async def run_then_stop() -> None:  # as zenav.services.runner.serve does
            try:
                await run()
            except asyncio.CancelledError:
                raise
            except Exception as exc:
                failures[name] = exc
            finally:
                node.request_stop()

        node.add_task(run_then_stop(), name=f"{name}:run")

    results = bus.subscribe(k.of(keys.RESULT), depth=1)
    live_events = bus.subscribe(k.of(keys.EVENTS), depth=100_000)
    paths = bus.subscribe(k.of(keys.PATH), depth=PATHS_KEPT)
    maps = bus.subscribe(k.of(keys.MAP), depth=1)
    heard: list[GlobalPath] = []

    async def take_paths() -> None:  # as they come: the repeats of a long run add up
        while True:
            payload = (await paths.get())[1]
            with contextlib.suppress(DecodeError):
                add_path(heard, decode(payload, GlobalPath, k.of(keys.PATH),
                                       keys.PATH.max_bytes))

    path_taker = asyncio.create_task(take_paths(), name="run:paths")
    spins: dict[str, asyncio.Task[None]] = {}
    for name in SERVICE_ORDER:
        add_run(name, nodes[name], services[name])
        spins[name] = asyncio.create_task(nodes[name].spin(), name=f"{name}:spin")
    await asyncio.sleep(0)  # every node declares its liveliness token
    token = bus.declare_token(k.alive("run"))  # the simulator waits for this run
    try:
        waiter = asyncio.create_task(results.get())
        done, _ = await asyncio.wait({waiter, spins["simulator"]}, timeout=RESULT_TIMEOUT,
                                     return_when=asyncio.FIRST_COMPLETED)
        if waiter not in done:
            waiter.cancel()
            why = failures.get("simulator")
            raise EngineError(f"the simulator stopped without a result: "
                              f"{type(why).__name__}: {why}" if why is not None else
                              "no result from the simulator")
        _, payload = waiter.result()
        try:
            result = decode(payload, RunResult, k.of(keys.RESULT), keys.RESULT.max_bytes)
        except DecodeError as exc:
            raise EngineError(str(exc)) from None
        history = await bus.query(k.of(keys.EVENT_HISTORY))
        payloads = [p for _, p in history]
        while live_events.pending():
            payloads.append((await live_events.get())[1])
        counters = {name: {"received": dict(node.received), "rejected": dict(node.rejected),
                           "handler_errors": node.handler_errors}
                    for name, node in nodes.items()}
        occupancy = None
        while (taken := paths.take()) is not None:  # those the path taker has not had
            with contextlib.suppress(DecodeError):
                add_path(heard, decode(taken[1], GlobalPath, k.of(keys.PATH),
                                       keys.PATH.max_bytes))
        while maps.pending():
            with contextlib.suppress(DecodeError):
                occupancy = decode((await maps.get())[1], OccupancyMap, k.of(keys.MAP),
                                   keys.MAP.max_bytes)
        return EngineRun(result, unique_events(payloads, k.of(keys.EVENTS)), counters,
                         heard[-1] if heard else None, occupancy, heard)
    finally:
        path_taker.cancel()
        # The simulator first, so that it does not log the others going away.
        nodes["simulator"].request_stop()
        await asyncio.gather(spins["simulator"], return_exceptions=True)
        bus.stop_watching()
        token.undeclare()
        for node in nodes.values():
            node.request_stop()
        await asyncio.gather(*spins.values(), return_exceptions=True)
        for service in services.values():
            close = getattr(service, "close", None)
            if close is not None:
                close()
        bus.close()


def run_services(params: Mapping[str, Mapping[str, Any]], planner: str = "paper",
                 robot_id: str = "robot0", log_path: Path | None = None,
                 log_level: str = "INFO") -> EngineRun:
    """Run the six services on one in-memory bus until the simulator's result; the result
    and the planner's events (as ``zenav run`` collects them from the stack). The
    services' log lines go to ``log_path`` (where the stack has one file per service)."""
    root = logging.getLogger()
    handler: logging.Handler | None = None
    level = root.level
    if log_path is not None:
        log_path.parent.mkdir(parents=True, exist_ok=True)
        handler = logging.FileHandler(log_path)
        handler.setFormatter(logging.Formatter("%(asctime)s %(name)s %(levelname)s %(message)s"))
        root.addHandler(handler)
        root.setLevel(log_level.upper())
    try:
        with asyncio.Runner(loop_factory=IdleClockLoop) as runner:
            return runner.run(_run_services(params, planner, robot_id))
    finally:
        if handler is not None:
            root.removeHandler(handler)
            root.setLevel(level)
            handler.close()
