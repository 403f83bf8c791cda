"""What every service process shares: typed inputs and outputs, health counters,
liveliness, and a clean stop.

A service declares its inputs with :meth:`Node.subscribe` (a topic and a handler) and
its outputs with :meth:`Node.publisher`, then awaits :meth:`Node.spin`. Every input is
handled on one asyncio loop, as soon as its sample is buffered (no task in between), so
handlers never run concurrently. A payload that
does not decode is counted and logged (once per key and kind, then at most every
``LOG_EVERY`` seconds) and the service carries on; so does a handler that raises.
"""

from __future__ import annotations

import asyncio
import functools
import inspect
import logging
import time
from collections import Counter
from collections.abc import Awaitable, Callable, Coroutine, Mapping
from typing import Any, Generic, Protocol, TypeVar

from zenav.schemas.codec import DecodeError, decode, encode
from zenav.schemas.keys import Keys, Topic
from zenav.schemas.messages import Message, ServiceStatus
from zenav.services.transport import Bus, Publisher, Subscription, Token

log = logging.getLogger(__name__)

M = TypeVar("M", bound=Message)
Handler = Callable[[M], Awaitable[None] | None]

LOG_EVERY = 10.0
"""Seconds between two log lines about the same kind of rejected input."""

STATUS_PERIOD = 1.0
"""Seconds between two status messages (wall clock: this is health, not control)."""

MAX_FUTURE = 5.0
"""Stamp-clock seconds an input may be ahead of the newest stamp the service has accepted
on any input (its view of the stack's clock). A later stamp is refused as ``future``:
accepted, it would make every genuine message after it look out of order."""

RESYNC_AFTER = 1.0
RESYNC_COUNT = 3
"""The way back after a long link cut (stamps jump ahead) or a restarted publisher
(stamps start again): once nothing has been accepted for ``RESYNC_AFTER`` wall seconds
(on the key for a past stamp, on any input for a future one), ``RESYNC_COUNT`` refused
stamps in a row on one key that form a coherent stream (increasing, each within
``MAX_FUTURE`` of the one before; a repeated stamp neither counts nor breaks the run)
are taken as the new order. A lone stamp, or scattered ones, never move the clock. Three
at 10 Hz is 0.2 s from a restarted publisher's first message to its acceptance, well
within the motor bridge's stale timeout (0.5 s); the :class:`StampGate` of a service that
answers the key follows at once."""


class TypedPublisher(Generic[M]):
    """Publishes one topic's messages and numbers them."""

    def __init__(self, publisher: Publisher, topic: Topic) -> None:
        self._publisher = publisher
        self.topic = topic
        self._seq = 0
        self.last: M | None = None

    def next_seq(self) -> int:
        seq = self._seq
        self._seq += 1
        return seq

    def publish(self, message: M) -> bytes:
        """Send ``message``; returns the payload sent."""
        if not isinstance(message, self.topic.message):
            raise TypeError(f"{self.topic.name} carries {self.topic.message.__name__}")
        payload = encode(message)
        self._publisher.put(payload)
        self.last = message
        return payload

    def republish(self) -> None:
        """Send the last message again (answers a retransmitted input)."""
        if self.last is not None:
            self._publisher.put(encode(self.last))


class _RateLimitedLog:
    def __init__(self, service: str) -> None:
        self._service = service
        self._last: dict[tuple[str, str], float] = {}
        self._since: Counter[tuple[str, str]] = Counter()

    def __call__(self, key: str, kind: str, text: str) -> None:
        now = time.monotonic()
        mark = (key, kind)
        self._since[mark] += 1
        last = self._last.get(mark)
        if last is None or now - last >= LOG_EVERY:
            count = self._since.pop(mark)
            extra = f" ({count} of this kind since the last report)" if last is not None else ""
            log.warning("%s rejected input: %s%s", self._service, text, extra)
            self._last[mark] = now


class Node:
    """One service's connection to the bus."""

    def __init__(
        self,
        name: str,
        bus: Bus,
        keys: Keys,
        *,
        max_future: float = MAX_FUTURE,
        resync_after: float = RESYNC_AFTER,
    ) -> None:
        self.name = name
        self.bus = bus
        self.keys = keys
        self.received: Counter[str] = Counter()
        self.rejected: Counter[str] = Counter()
        self.handler_errors = 0
        self._inputs: list[tuple[Subscription, Topic, Callable[[Any], Any]]] = []
        self._tasks: list[asyncio.Task[None]] = []
        self._awaiting: set[asyncio.Task[None]] = set()  # handlers' awaitables in progress
        self._stop = asyncio.Event()
        self._token: Token | None = None
        self._accepted_wall = time.monotonic()
        self._log_rejection = _RateLimitedLog(name)
        self.max_future = max_future
        self.resync_after = resync_after
        self.clock: float | None = None
        """Newest stamp accepted on any input: the service's view of the stack's clock."""
        self._latest: dict[str, tuple[float, float]] = {}  # key -> (stamp, wall accepted)
        self._refused: dict[str, tuple[float, int]] = {}  # key -> (last stamp, run length)
        self.resyncs: Counter[str] = Counter()
        """Per key, how often its order restarted (a :class:`StampGate` follows it)."""
        self._status = TypedPublisher[ServiceStatus](
            bus.publisher(keys.status(name)), Topic(f"status/{name}", ServiceStatus)
        )

    # -- declarations ------------------------------------------------------------------

    def publisher(
        self, topic: Topic, message_type: type[M], *, reliable: bool = False, urgent: bool = False
    ) -> TypedPublisher[M]:
        if topic.message is not message_type:
            raise TypeError(f"{topic.name} carries {topic.message.__name__}")
        return TypedPublisher[M](
            self.bus.publisher(self.keys.of(topic), reliable=reliable, urgent=urgent), topic
        )

    def subscribe(
        self, topic: Topic, message_type: type[M], handler: Handler[M], *, depth: int = 1
    ) -> Subscription:
        """Call ``handler`` with each valid message on ``topic``; keep at most ``depth``
        waiting (newest wins)."""
        if topic.message is not message_type:
            raise TypeError(f"{topic.name} carries {topic.message.__name__}")
        sub = self.bus.subscribe(self.keys.of(topic), depth)
        self._inputs.append((sub, topic, handler))
        return sub

    def add_task(self, coro: Coroutine[Any, Any, None], name: str) -> None:
        """Run ``coro`` alongside the inputs; it is cancelled at stop."""
        self._tasks.append(asyncio.get_running_loop().create_task(coro, name=name))

    # -- running -----------------------------------------------------------------------

    @property
    def stopping(self) -> bool:
        return self._stop.is_set()

    def request_stop(self) -> None:
        self._stop.set()

    async def spin(self) -> None:
        """Serve every input until :meth:`request_stop`; then undeclare and return."""
        loop = asyncio.get_running_loop()
        self._token = self.bus.declare_token(self.keys.alive(self.name))
        for sub, topic, handler in self._inputs:
            sub.consume(functools.partial(self._deliver, sub, topic, handler))
        self._tasks.append(loop.create_task(self._report_status(), name="status"))
        try:
            await self._stop.wait()
        finally:
            for sub, _, _ in self._inputs:
                sub.pause()
            for task in (*self._tasks, *self._awaiting):
                task.cancel()
            await asyncio.gather(*self._tasks, *self._awaiting, return_exceptions=True)
            self._tasks.clear()
            for sub, _, _ in self._inputs:
                sub.close()
            if self._token is not None:
                self._token.undeclare()
                self._token = None

    def _deliver(self, sub: Subscription, topic: Topic, handler: Callable[[Any], Any],
                 key: str, payload: bytes) -> None:
        """One input sample, on the loop as soon as it is buffered: decode, check its
        stamp, count it, handle it. A handler that returns an awaitable holds back this
        input's next samples (buffered, newest wins) until it has finished."""
        try:
            message = decode(payload, topic.message, key, topic.max_bytes)
        except DecodeError as exc:
            self.reject(key, exc.kind, str(exc))
            return
        except Exception as exc:  # decode promises DecodeError; never lose the input
            self.reject(key, "invalid", f"{key}: invalid: {type(exc).__name__}: {exc}")
            return
        refused = self.check_stamp(key, message.stamp)
        if refused is not None:
            self.reject(key, *refused)
            return
        self.received[topic.name] += 1
        try:
            result = handler(message)
        except Exception:
            self._handler_failed(key)
            return
        if inspect.isawaitable(result):
            sub.pause()
            task = asyncio.get_running_loop().create_task(self._finish(sub, key, result),
                                                          name=f"input:{topic.name}")
            self._awaiting.add(task)
            task.add_done_callback(self._awaiting.discard)

    async def _finish(self, sub: Subscription, key: str, result: Awaitable[Any]) -> None:
        try:
            await result
        except asyncio.CancelledError:
            raise
        except Exception:
            self._handler_failed(key)
        sub.resume()

    def _handler_failed(self, key: str) -> None:
        self.handler_errors += 1
        log.exception("%s: handler for %s failed; input dropped", self.name, key)

    def check_stamp(self, key: str, stamp: float) -> tuple[str, str] | None:
        """Order the inputs of one key by stamp, against the service's clock.

        Returns ``None`` to accept ``stamp`` (later than or equal to the key's newest:
        an equal one is a retransmission the service answers), or ``(kind, text)``:
        ``out_of_order`` for a stamp earlier than the key's newest, ``future`` for one
        more than ``max_future`` ahead of :attr:`clock`. See :data:`RESYNC_COUNT` for
        how the order restarts after a cut link or a restarted publisher.
        """
        now = time.monotonic()
        latest = self._latest.get(key)
        problem: tuple[str, str] | None = None
        if latest is not None and stamp < latest[0]:
            problem = ("out_of_order", f"{key}: out_of_order: stamp {stamp} after {latest[0]}")
            silent = now - latest[1]
        elif self.clock is not None and stamp > self.clock + self.max_future:
            problem = ("future", f"{key}: future: stamp {stamp} is more than "
                       f"{self.max_future} s ahead of the clock {self.clock}")
            silent = now - self._accepted_wall
        if problem is not None:
            # A refused stamp counts toward a resynchronisation only as part of a
            # coherent stream: increasing, each within max_future of the one before.
            run = self._refused.get(key)
            if run is not None and run[0] == stamp:
                pass  # a retransmission of the run's newest stamp: neither more nor less
            elif run is not None and run[0] < stamp <= run[0] + self.max_future:
                run = (stamp, run[1] + 1)
            else:
                run = (stamp, 1)
            self._refused[key] = run
            if run[1] < RESYNC_COUNT or silent < self.resync_after:
                return problem
            log.warning("%s: %s refused for %.1f s, then %d coherent stamps; the order "
                        "restarts at %s", self.name, key, silent, run[1], stamp)
            if problem[0] == "future":
                self.clock = stamp
            self.resyncs[key] += 1
        self._refused.pop(key, None)
        self._latest[key] = (stamp, now)
        self._accepted_wall = now
        if self.clock is None or stamp > self.clock:
            self.clock = stamp
        return None

    def reject(self, key: str, kind: str, text: str) -> None:
        """Count an input refused for ``kind`` and log it, rate-limited per key and kind."""
        self.rejected[kind] += 1
        self._log_rejection(key, kind, text)

    def status(self, stamp: float = 0.0) -> ServiceStatus:
        return ServiceStatus(
            stamp=stamp,
            seq=self._status.next_seq(),
            service=self.name,
            received=dict(self.received),
            rejected=dict(self.rejected),
            dropped={sub.key_expr: sub.dropped for sub, _, _ in self._inputs if sub.dropped},
            handler_errors=self.handler_errors,
        )

    async def _report_status(self) -> None:
        while True:
            await asyncio.sleep(STATUS_PERIOD)
            self._status.publish(self.status(stamp=time.time()))


class Republisher(Protocol):
    def republish(self) -> None: ...


class StampGate:
    """Orders one input stream by stamp.

    ``check(stamp)`` answers ``"new"`` for a stamp later than any seen, ``"repeat"`` for
    the latest one again (a retransmission: answer it by republishing the last output),
    and ``"old"`` for anything earlier (out of order: drop it). ``admit`` does all three
    for a service whose output answers this input. When the node has restarted the
    key's order (a restarted publisher, see :data:`RESYNC_COUNT`), the gate restarts with
    it: the first stamp of the new order is new, not old.
    """

    def __init__(self, node: Node | None = None, topic: Topic | None = None) -> None:
        self.last: float | None = None
        self.node = node
        self.topic = topic
        self._resyncs = self._node_resyncs()

    def _node_resyncs(self) -> int:
        if self.node is None or self.topic is None:
            return 0
        return self.node.resyncs[self.node.keys.of(self.topic)]

    def admit(self, stamp: float, output: Republisher) -> bool:
        """True for a new stamp; a repeat is answered with ``output``'s last message, an
        earlier stamp is refused and counted (``out_of_order``)."""
        order = self.check(stamp)
        if order == "repeat":
            output.republish()
        elif order == "old" and self.node is not None and self.topic is not None:
            self.node.reject(self.node.keys.of(self.topic), "out_of_order",
                             f"stamp {stamp} after {self.last}")
        return order == "new"

    def check(self, stamp: float) -> str:
        resyncs = self._node_resyncs()
        if resyncs != self._resyncs:  # the node took a new order on this key
            self._resyncs = resyncs
            self.last = None
        if self.last is None or stamp > self.last:
            self.last = stamp
            return "new"
        if stamp == self.last:
            return "repeat"
        return "old"


class Stamped(Protocol):
    """Anything with a stamp: a message, or what a service builds from several."""

    @property
    def stamp(self) -> float: ...


A = TypeVar("A", bound=Message)
B = TypeVar("B", bound=Stamped)


def latest_at(kept: Mapping[float, object], stamp: float) -> float | None:
    """The stamp of the kept message for ``stamp``: the same, else the newest before it
    (what a message decided without its companion falls back to)."""
    if stamp in kept:
        return stamp
    earlier = [s for s in kept if s <= stamp]
    return max(earlier) if earlier else None


class StampJoin(Generic[A, B]):
    """Joins a message with its companion of the same stamp (a planner's track list with
    the scan of that stamp), whichever of the two comes first, so that what the service
    decides does not depend on their arrival order.

    :meth:`companion` keeps the latest ``kept`` companions by stamp and completes the
    message waiting for one. :meth:`arrive` decides a message at once when its companion
    is in; else it waits, one at most, until its companion comes, until ``wait`` seconds
    of the loop's clock have passed, or until a newer message arrives, whichever is
    first; the last two decide it without one (``None``). ``decide(message, companion)``
    is the service's.
    """

    def __init__(self, decide: Callable[[A, B | None], None], wait: float, kept: int) -> None:
        self.decide = decide
        self.wait = wait
        self.kept = kept
        self.companions: dict[float, B] = {}
        """The latest companions, by stamp."""
        self.pending: A | None = None
        """The message waiting for its companion."""
        self._timer: asyncio.TimerHandle | None = None

    def companion(self, message: B) -> None:
        self.companions[message.stamp] = message
        while len(self.companions) > self.kept:
            del self.companions[min(self.companions)]
        if self.pending is not None and self.pending.stamp == message.stamp:
            self._decide(self.pending, message)

    def arrive(self, message: A) -> None:
        if self.pending is not None:  # overtaken before its companion came: decided now
            self._decide(self.pending, None)
        companion = self.companions.get(message.stamp)
        if companion is not None:
            self._decide(message, companion)
            return
        self.pending = message
        self._timer = asyncio.get_running_loop().call_later(self.wait, self._late,
                                                            message.stamp)

    def _late(self, stamp: float) -> None:
        if self.pending is not None and self.pending.stamp == stamp:
            self._decide(self.pending, None)

    def _decide(self, message: A, companion: B | None) -> None:
        self.pending = None
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None
        self.decide(message, companion)
