"""The message bus: one interface, a Zenoh implementation and an in-memory one.

Services see bytes in and bytes out; encoding lives in :mod:`zenav.schemas.codec`.

Zenoh delivers samples on its own threads and has no asyncio API. The Zenoh callback
here does one thing: put the payload into the subscription's buffer and, unless a
wake-up is already on its way, wake the asyncio loop with ``call_soon_threadsafe``.
Everything else (decode, validate, compute) happens on the service's loop, so nothing
ever blocks a Zenoh thread. Each subscription keeps a bounded newest-wins buffer: when a
consumer falls behind, the oldest sample is dropped and counted, and no queue grows
without bound (not even the loop's own: one wake-up waits at most per subscription).
"""

from __future__ import annotations

import asyncio
import contextlib
import functools
import json
import logging
import re
import threading
import uuid
from abc import ABC, abstractmethod
from collections import deque
from collections.abc import Callable
from typing import Annotated, Any, Literal

import zenoh
from pydantic import AfterValidator, BaseModel, ConfigDict, Field

log = logging.getLogger(__name__)

LivelinessCallback = Callable[[str, bool], None]
"""Called on the asyncio loop with (token key, alive)."""

Snapshot = Callable[[], list[bytes]]
"""Answers a query with payloads. Called on a middleware thread: it must only read
(copy) data, never touch the asyncio loop."""


ENDPOINT_PROTOCOLS: dict[str, bool] = {
    "tcp": True, "udp": True, "tls": True, "quic": True, "ws": True,
    "unixsock-stream": False, "unixpipe": False, "serial": False, "vsock": False,
}
"""The link protocols of a Zenoh endpoint, each with whether its address ends in a port."""


def check_endpoint(endpoint: str) -> str:
    """``endpoint`` when it has the form Zenoh accepts, ``PROTOCOL/ADDRESS`` with an
    optional ``?metadata`` and ``#config`` (e.g. ``tcp/127.0.0.1:7447``,
    ``unixsock-stream//tmp/zenoh.sock``), a port from 0 to 65535 where the protocol takes
    one; else ValueError with one line saying what is wrong. Zenoh's own refusal comes
    only when the session opens, as a multi-line error."""
    example = "e.g. tcp/127.0.0.1:7447"
    protocol, slash, rest = endpoint.partition("/")
    address = rest.split("?", 1)[0].split("#", 1)[0]
    if not slash or not address:
        raise ValueError(f"{endpoint!r} is not a Zenoh endpoint: expected PROTOCOL/ADDRESS, "
                         f"{example}")
    if protocol not in ENDPOINT_PROTOCOLS:
        raise ValueError(f"{endpoint!r}: unknown protocol {protocol!r} (one of "
                         f"{', '.join(ENDPOINT_PROTOCOLS)}), {example}")
    if ENDPOINT_PROTOCOLS[protocol]:
        host, colon, port = address.rpartition(":")
        if not colon or not host or not port.isdigit():
            raise ValueError(f"{endpoint!r}: expected {protocol}/HOST:PORT, {example}")
        if int(port) > 65535:
            raise ValueError(f"{endpoint!r}: port {port} is not from 0 to 65535")
        if host.startswith("[") != host.endswith("]") or any(c.isspace() for c in host):
            raise ValueError(f"{endpoint!r}: {host!r} is not a host name or address")
    return endpoint


Endpoint = Annotated[str, AfterValidator(check_endpoint)]
"""A Zenoh endpoint, checked by :func:`check_endpoint`."""


_RUST_PLACE = re.compile(r"\s+at /\S+\.rs:\d+\.?")


def zenoh_problem(exc: BaseException) -> str:
    """A Zenoh error's text without the places in Zenoh's Rust source it names (`` at
    /root/.cargo/.../tcp.rs:61.``), of no use to the reader, on one line."""
    return " ".join(_RUST_PLACE.sub("", str(exc)).split())


NO_ROUTER = ("mode client needs a router to connect to: give connect: [ENDPOINT] (or --connect "
             "ENDPOINT)")
"""What is wrong with a transport that :meth:`TransportConfig.finds_no_router`."""


class TransportConfig(BaseModel):
    """How a process joins the Zenoh network.

    The embedded default is a peer listening on its own loopback port and connecting
    to the other services' ports, with multicast scouting off: nothing to install or
    start, and two stacks on different ports never meet.
    """

    model_config = ConfigDict(extra="forbid")

    mode: Literal["peer", "client", "router"] = "peer"
    listen: list[Endpoint] = Field(
        default_factory=list, description="endpoints, e.g. tcp/127.0.0.1:7450"
    )
    connect: list[Endpoint] = Field(default_factory=list,
                                    description="endpoints to connect to")
    multicast_scouting: bool = False
    lease_ms: int = Field(1000, ge=100, description="link lease: how soon a dead peer is noticed")
    extra: dict[str, Any] = Field(
        default_factory=dict, description="further Zenoh settings, path -> JSON value"
    )

    def finds_no_router(self) -> bool:
        """A client with nowhere to look for its router: no endpoint to connect to and
        multicast scouting off. Its session could never open (:data:`NO_ROUTER` says so)."""
        return (self.mode == "client" and not self.connect and not self.multicast_scouting
                and "connect/endpoints" not in self.extra)

    def to_zenoh(self) -> zenoh.Config:
        conf = zenoh.Config()
        conf.insert_json5("mode", json.dumps(self.mode))
        conf.insert_json5("scouting/multicast/enabled", json.dumps(self.multicast_scouting))
        conf.insert_json5("listen/endpoints", json.dumps(self.listen))
        conf.insert_json5("connect/endpoints", json.dumps(self.connect))
        conf.insert_json5("transport/link/tx/lease", json.dumps(self.lease_ms))
        for path, value in self.extra.items():
            conf.insert_json5(path, json.dumps(value))
        return conf


class Subscription:
    """Samples of one key expression, buffered newest-wins for an asyncio consumer.

    Two ways to consume: ``await get()`` (a task of the consumer's own), or
    :meth:`consume`, where the loop calls a function with each sample as soon as it is
    buffered, with no task to wake in between (a service's inputs: one loop iteration
    less per message). Samples come in with ``push`` on the loop's thread (the in-memory
    bus), or with ``offer`` from any thread (Zenoh's): the sample goes into the buffer
    there and then, and the loop is woken once for all the samples that come before it
    gets to them; it then hands them over one per turn (:meth:`_wake`). Either way at
    most ``depth`` samples wait; a newer one drops the oldest and counts it in
    ``dropped``.
    """

    def __init__(self, key_expr: str, depth: int,
                 loop: asyncio.AbstractEventLoop | None = None) -> None:
        if depth < 1:
            raise ValueError("a subscription needs a depth of at least 1")
        self.key_expr = key_expr
        self.depth = depth
        self.dropped = 0
        self._buffer: deque[tuple[str, bytes]] = deque()
        self._lock = threading.Lock()  # the buffer, between Zenoh's thread and the loop's
        self._ready = asyncio.Event()
        self._closed = False
        self._loop = loop
        self._consumer: Callable[[str, bytes], None] | None = None
        self._paused = False
        self._wake_pending = False  # a wake-up is scheduled on the loop and not yet run
        self.on_close: Callable[[], None] | None = None

    def _add(self, key: str, payload: bytes) -> None:
        """Buffer a sample, newest wins (the caller holds the lock)."""
        if len(self._buffer) >= self.depth:
            self._buffer.popleft()
            self.dropped += 1
        self._buffer.append((key, payload))

    def push(self, key: str, payload: bytes) -> None:
        """Buffer a sample (on the loop's thread)."""
        with self._lock:
            if self._closed:
                return
            self._add(key, payload)
            if self._consumer is None:
                wake = False
            else:
                wake = not self._wake_pending
                self._wake_pending = True
        if self._consumer is None:
            self._ready.set()
        elif wake:
            assert self._loop is not None  # set with the consumer
            self._loop.call_soon(self._wake)

    def offer(self, key: str, payload: bytes) -> None:
        """Buffer a sample from any thread and wake the loop, unless a wake-up is already
        on its way."""
        with self._lock:
            if self._closed:
                return
            self._add(key, payload)
            if self._wake_pending:
                return
            self._wake_pending = True
        if self._loop is not None:
            with contextlib.suppress(RuntimeError):  # a closed loop: the process is stopping
                self._loop.call_soon_threadsafe(self._wake)

    def _wake(self) -> None:
        """On the loop: hand the oldest buffered sample to the consumer, and come back on
        the loop's next turn while more wait (so that a service's inputs take turns, one
        sample each, as their samples came, and a burst on one input does not run ahead
        of another's: perception's scan and the odometry it waits for); or wake the task
        waiting in :meth:`get`."""
        if self._consumer is None:
            with self._lock:
                self._wake_pending = False
            self._ready.set()
            return
        with self._lock:
            if self._closed or self._paused or not self._buffer:
                self._wake_pending = False
                return
            key, payload = self._buffer.popleft()
        try:
            self._consumer(key, payload)
        finally:  # a consumer that raises: the loop reports it; the samples after it come
            with self._lock:
                more = (self._consumer is not None and not self._closed and not self._paused
                        and bool(self._buffer))
                self._wake_pending = more
            if more:
                assert self._loop is not None  # set with the consumer
                self._loop.call_soon(self._wake)

    def consume(self, consumer: Callable[[str, bytes], None]) -> None:
        """From now on, call ``consumer(key, payload)`` on the loop for each sample, oldest
        first, one at a time (call on the loop's thread). :meth:`get` is not for use then."""
        self._loop = asyncio.get_running_loop()
        self._consumer = consumer
        self.resume()

    def pause(self) -> None:
        """Hand no more samples to the consumer until :meth:`resume`; they keep being
        buffered (newest wins)."""
        self._paused = True

    def resume(self) -> None:
        """Hand samples to the consumer again, those buffered meanwhile first."""
        self._paused = False
        self._schedule()

    def _schedule(self) -> None:
        """Wake the consumer on the loop's next turn if samples wait for it (on the loop)."""
        with self._lock:
            if (self._consumer is None or self._paused or self._closed or not self._buffer
                    or self._wake_pending):
                return
            self._wake_pending = True
        assert self._loop is not None
        self._loop.call_soon(self._wake)

    async def get(self) -> tuple[str, bytes]:
        """The oldest buffered (key, payload); waits when there is none."""
        while True:
            with self._lock:
                if self._buffer:
                    return self._buffer.popleft()
            if self._closed:
                raise asyncio.CancelledError("subscription closed")
            self._ready.clear()
            await self._ready.wait()

    def pending(self) -> int:
        return len(self._buffer)

    def take(self) -> tuple[str, bytes] | None:
        """The oldest buffered (key, payload), or None; never waits."""
        with self._lock:
            return self._buffer.popleft() if self._buffer else None

    def close(self) -> None:
        with self._lock:
            self._closed = True
        self._consumer = None
        self._ready.set()
        if self.on_close is not None:
            self.on_close()
            self.on_close = None


class Latest(ABC):
    """The newest sample of a key expression, for a consumer that looks now and then
    (a tool checking progress) rather than handling every sample: nothing is scheduled
    on the asyncio loop when a sample arrives, so a fast stream costs that process no
    wake-up. Newest wins, one sample deep."""

    @abstractmethod
    def take(self) -> tuple[str, bytes] | None:
        """The newest (key, payload) not taken yet, or None; never waits."""

    @abstractmethod
    def close(self) -> None: ...


class Publisher(ABC):
    @abstractmethod
    def put(self, payload: bytes, attachment: bytes | None = None) -> None:
        """Send ``payload``; ``attachment`` is Zenoh's per-sample metadata (ROS 2 over
        rmw_zenoh carries a sequence number, a source time and a GID there)."""


class Token(ABC):
    @abstractmethod
    def undeclare(self) -> None: ...


class Bus(ABC):
    """What a service needs from the middleware."""

    _session_id: str | None = None

    def session_id(self) -> str:
        """This participant's id in lowercase hex (Zenoh's session id on Zenoh)."""
        if self._session_id is None:
            self._session_id = uuid.uuid4().hex
        return self._session_id

    @abstractmethod
    def publisher(self, key: str, *, reliable: bool = False, urgent: bool = False) -> Publisher:
        """A publisher on ``key``. ``reliable`` blocks instead of dropping under congestion;
        ``urgent`` raises the priority (velocity and base commands)."""

    @abstractmethod
    def subscribe(self, key_expr: str, depth: int = 1) -> Subscription: ...

    @abstractmethod
    def latest(self, key_expr: str) -> Latest:
        """The newest sample of ``key_expr``, held by the middleware until taken."""

    @abstractmethod
    def declare_token(self, key: str) -> Token:
        """Announce this process's liveliness on ``key`` until undeclared."""

    @abstractmethod
    def watch_liveliness(self, key_expr: str, callback: LivelinessCallback) -> None:
        """Call ``callback`` for tokens already alive and every later appearance or loss."""

    @abstractmethod
    def declare_queryable(self, key: str, snapshot: Snapshot) -> None:
        """Answer every query on ``key`` with the payloads ``snapshot`` returns (history
        a late joiner can still fetch, like a latched topic)."""

    @abstractmethod
    async def query(self, selector: str, timeout: float = 2.0) -> list[tuple[str, bytes]]:
        """Every reply to a query on ``selector``, within ``timeout`` s."""

    @abstractmethod
    def close(self) -> None: ...


# --- in memory ------------------------------------------------------------------------


@functools.lru_cache(maxsize=4096)
def key_matches(key_expr: str, key: str) -> bool:
    """Zenoh's own key-expression intersection, for the in-memory bus (remembered: a
    stack uses a few dozen keys, each matched on every message)."""
    return bool(zenoh.KeyExpr(key_expr).intersects(zenoh.KeyExpr(key)))


class _MemoryPublisher(Publisher):
    def __init__(self, bus: InMemoryBus, key: str) -> None:
        self._bus = bus
        self._key = key

    def put(self, payload: bytes, attachment: bytes | None = None) -> None:
        self._bus.deliver(self._key, bytes(payload), attachment)


class _MemoryLatest(Latest):
    def __init__(self, sub: Subscription) -> None:
        self._sub = sub

    def take(self) -> tuple[str, bytes] | None:
        return self._sub.take()

    def close(self) -> None:
        self._sub.close()


class _MemoryToken(Token):
    def __init__(self, bus: InMemoryBus, key: str) -> None:
        self._bus = bus
        self.key = key

    def undeclare(self) -> None:
        self._bus.set_alive(self.key, False)


class InMemoryBus(Bus):
    """A bus inside one process and one asyncio loop, for service tests.

    Several services can share one instance; ``published`` keeps every put for
    assertions (unless ``keep_published`` is false: a long run in the in-process engine).
    """

    def __init__(self, *, keep_published: bool = True) -> None:
        self.keep_published = keep_published
        self._subs: list[Subscription] = []
        self._alive: set[str] = set()
        self._watchers: list[tuple[str, LivelinessCallback]] = []
        self._queryables: list[tuple[str, Snapshot]] = []
        self.published: list[tuple[str, bytes]] = []
        self.attachments: dict[int, bytes] = {}
        """Attachments sent, by index into ``published``."""

    def deliver(self, key: str, payload: bytes, attachment: bytes | None = None) -> None:
        if self.keep_published:
            if attachment is not None:
                self.attachments[len(self.published)] = attachment
            self.published.append((key, payload))
        for sub in list(self._subs):
            if key_matches(sub.key_expr, key):
                sub.push(key, payload)

    def publisher(self, key: str, *, reliable: bool = False, urgent: bool = False) -> Publisher:
        return _MemoryPublisher(self, key)

    def subscribe(self, key_expr: str, depth: int = 1) -> Subscription:
        sub = Subscription(key_expr, depth)
        self._subs.append(sub)
        sub.on_close = lambda: self._subs.remove(sub)
        return sub

    def latest(self, key_expr: str) -> Latest:
        return _MemoryLatest(self.subscribe(key_expr, depth=1))

    def declare_token(self, key: str) -> Token:
        self.set_alive(key, True)
        return _MemoryToken(self, key)

    def set_alive(self, key: str, alive: bool) -> None:
        if alive:
            self._alive.add(key)
        else:
            self._alive.discard(key)
        for pattern, callback in self._watchers:
            if key_matches(pattern, key):
                callback(key, alive)

    def watch_liveliness(self, key_expr: str, callback: LivelinessCallback) -> None:
        self._watchers.append((key_expr, callback))
        for key in sorted(self._alive):
            if key_matches(key_expr, key):
                callback(key, True)

    def declare_queryable(self, key: str, snapshot: Snapshot) -> None:
        self._queryables.append((key, snapshot))

    def stop_watching(self) -> None:
        """Forget every liveliness watcher (a stack in one process stopping: nobody is
        left to be told who went away)."""
        self._watchers.clear()

    async def query(self, selector: str, timeout: float = 2.0) -> list[tuple[str, bytes]]:
        return [(key, payload) for key, snapshot in self._queryables
                if key_matches(selector, key) for payload in snapshot()]

    def close(self) -> None:
        for sub in list(self._subs):
            sub.close()


# --- Zenoh ---------------------------------------------------------------------------


class _ZenohPublisher(Publisher):
    def __init__(self, publisher: Any) -> None:
        self._publisher = publisher

    def put(self, payload: bytes, attachment: bytes | None = None) -> None:
        self._publisher.put(payload, attachment=attachment)


class _ZenohLatest(Latest):
    """A subscriber whose samples go into Zenoh's own one-deep ring channel: the
    middleware keeps the newest, no Python code runs when one arrives."""

    def __init__(self, subscriber: Any) -> None:
        self._subscriber = subscriber

    def take(self) -> tuple[str, bytes] | None:
        sample = self._subscriber.try_recv()
        if sample is None:
            return None
        return str(sample.key_expr), sample.payload.to_bytes()

    def close(self) -> None:
        with contextlib.suppress(Exception):  # already undeclared with the session
            self._subscriber.undeclare()


class _ZenohToken(Token):
    def __init__(self, token: Any) -> None:
        self._token = token

    def undeclare(self) -> None:
        self._token.undeclare()


class ZenohBus(Bus):
    """The bus over one Zenoh session, bridged to one asyncio loop."""

    def __init__(self, config: TransportConfig, loop: asyncio.AbstractEventLoop,
                 session: Any = None) -> None:
        """Opens a session from ``config``, or takes over ``session`` already opened from
        it (a tool opens it in a thread of its own, to stay responsive while it connects)."""
        self._loop = loop
        self._session: Any = zenoh.open(config.to_zenoh()) if session is None else session
        self._declared: list[Any] = []

    @property
    def session(self) -> Any:
        return self._session

    def session_id(self) -> str:
        return str(self._session.zid())

    def _to_loop(self, callback: Callable[..., None], *args: object) -> None:
        """Runs on a Zenoh thread: schedule ``callback`` on the loop and return at once."""
        with contextlib.suppress(RuntimeError):  # a closed loop: the process is stopping
            self._loop.call_soon_threadsafe(callback, *args)

    def publisher(self, key: str, *, reliable: bool = False, urgent: bool = False) -> Publisher:
        pub = self._session.declare_publisher(
            key,
            congestion_control=(
                zenoh.CongestionControl.BLOCK if reliable else zenoh.CongestionControl.DROP
            ),
            priority=zenoh.Priority.REAL_TIME if urgent else zenoh.Priority.DATA,
            express=True,
        )
        self._declared.append(pub)
        return _ZenohPublisher(pub)

    def subscribe(self, key_expr: str, depth: int = 1) -> Subscription:
        sub = Subscription(key_expr, depth, self._loop)

        def on_sample(sample: Any) -> None:
            try:  # buffered here, newest wins; the loop is woken once per burst
                sub.offer(str(sample.key_expr), sample.payload.to_bytes())
            except Exception:  # never let an exception reach Zenoh's thread
                log.exception("zenoh callback failed on %s", key_expr)

        handle = self._session.declare_subscriber(key_expr, on_sample)
        self._declared.append(handle)
        return sub

    def latest(self, key_expr: str) -> Latest:
        handle = self._session.declare_subscriber(key_expr, zenoh.handlers.RingChannel(1))
        self._declared.append(handle)
        return _ZenohLatest(handle)

    def declare_token(self, key: str) -> Token:
        token = self._session.liveliness().declare_token(key)
        self._declared.append(token)
        return _ZenohToken(token)

    def watch_liveliness(self, key_expr: str, callback: LivelinessCallback) -> None:
        def on_sample(sample: Any) -> None:
            alive = sample.kind == zenoh.SampleKind.PUT
            self._to_loop(callback, str(sample.key_expr), alive)

        handle = self._session.liveliness().declare_subscriber(key_expr, on_sample, history=True)
        self._declared.append(handle)

    def declare_queryable(self, key: str, snapshot: Snapshot) -> None:
        def on_query(query: Any) -> None:
            try:
                with query:  # always finished, or the asker waits for its whole timeout
                    for payload in snapshot():
                        query.reply(key, payload)
            except Exception:  # never let an exception reach Zenoh's thread
                log.exception("answering a query on %s failed", key)

        self._declared.append(self._session.declare_queryable(key, on_query))

    async def query(self, selector: str, timeout: float = 2.0) -> list[tuple[str, bytes]]:
        def ask() -> list[tuple[str, bytes]]:
            replies = []
            # No consolidation: Zenoh's default keeps only the last reply per key, and a
            # history is many replies on one key.
            for reply in self._session.get(selector, timeout=timeout,
                                           consolidation=zenoh.ConsolidationMode.NONE):
                if reply.ok is not None:
                    replies.append((str(reply.ok.key_expr), reply.ok.payload.to_bytes()))
            return replies

        return await asyncio.to_thread(ask)

    def close(self) -> None:
        for handle in reversed(self._declared):
            try:
                handle.undeclare()
            except Exception:  # already undeclared or session gone
                log.debug("undeclare failed", exc_info=True)
        self._declared.clear()
        self._session.close()
