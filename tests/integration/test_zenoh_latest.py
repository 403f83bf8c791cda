"""``ZenohBus`` over real Zenoh sessions: ``latest`` (the newest sample of a key is held
by the middleware's ring channel and taken when the consumer looks, without a callback
into the receiving process's loop) and ``query`` (every reply comes back, in order,
though all are on one key, as the planner's event history is)."""

from __future__ import annotations

import asyncio
import contextlib
import time
from collections.abc import Iterator

import pytest

from zenav.launch import free_port_block
from zenav.services.transport import TransportConfig, ZenohBus

pytestmark = pytest.mark.integration


@contextlib.contextmanager
def linked(loop: asyncio.AbstractEventLoop) -> Iterator[tuple[ZenohBus, ZenohBus]]:
    """Two sessions on this machine, the first listening and the second connecting."""
    endpoint = f"tcp/127.0.0.1:{free_port_block(1)}"
    listening = ZenohBus(TransportConfig(listen=[endpoint]), loop)
    connecting = ZenohBus(TransportConfig(connect=[endpoint]), loop)
    try:
        yield listening, connecting
    finally:
        connecting.close()
        listening.close()


def test_the_newest_sample_waits_in_zenoh_until_taken():
    async def scenario() -> None:
        with linked(asyncio.get_running_loop()) as (receiver, sender):
            newest = receiver.latest("zenav/robot0/odom")
            marker = receiver.latest("zenav/robot0/marker")
            # Reliable: the sender blocks rather than drops under congestion. With the
            # services' dropping publishers a loaded machine once lost the marker, and
            # this test is of the receiving side.
            pub = sender.publisher("zenav/robot0/odom", reliable=True)
            after = sender.publisher("zenav/robot0/marker", reliable=True)
            # Until the link is up and the sender knows both subscriptions.
            seen = {"odom": False, "marker": False}
            deadline = time.monotonic() + 20
            while not all(seen.values()) and time.monotonic() < deadline:
                pub.put(b"probe")
                after.put(b"probe")
                await asyncio.sleep(0.05)
                seen["odom"] |= newest.take() is not None
                seen["marker"] |= marker.take() is not None
            assert all(seen.values()), seen
            await asyncio.sleep(0.5)  # probes still on their way
            newest.take()
            marker.take()
            # The marker, sent after the three on the same link and priority, arrives
            # after them: once it is in, all three have been received.
            for payload in (b"1", b"2", b"3"):
                pub.put(payload)
            after.put(b"after")
            deadline = time.monotonic() + 20
            got = None
            while got is None and time.monotonic() < deadline:
                await asyncio.sleep(0.02)
                got = marker.take()
            assert got == ("zenav/robot0/marker", b"after")
            assert newest.take() == ("zenav/robot0/odom", b"3")  # 1 and 2 were overwritten
            assert newest.take() is None

    asyncio.run(scenario())


def test_a_query_returns_every_reply_on_one_key():
    key = "zenav/robot0/planner/history"
    history = [bytes([i]) for i in range(5)]

    async def scenario() -> None:
        with linked(asyncio.get_running_loop()) as (answering, asking):
            answering.declare_queryable(key, lambda: list(history))
            replies: list[tuple[str, bytes]] = []
            deadline = time.monotonic() + 20
            while not replies and time.monotonic() < deadline:  # until the link is up
                replies = await asking.query(key, timeout=1.0)
            assert replies == [(key, payload) for payload in history]

    asyncio.run(scenario())
