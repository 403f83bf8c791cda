"""``ZenohBus.query`` over real Zenoh sessions: every reply of a queryable comes back, in
order, though all of them are on one key (the planner's event history is)."""

from __future__ import annotations

import asyncio
import time

import pytest

from zenav.launch import free_port_block
from zenav.services.transport import TransportConfig, ZenohBus

pytestmark = pytest.mark.integration

KEY = "zenav/robot0/planner/history"


def test_a_query_returns_every_reply_on_one_key():
    async def scenario() -> None:
        loop = asyncio.get_running_loop()
        endpoint = f"tcp/127.0.0.1:{free_port_block(1)}"
        answering = ZenohBus(TransportConfig(listen=[endpoint]), loop)
        asking = ZenohBus(TransportConfig(connect=[endpoint]), loop)
        history = [bytes([i]) for i in range(5)]
        try:
            answering.declare_queryable(KEY, lambda: list(history))
            replies: list[tuple[str, bytes]] = []
            deadline = time.monotonic() + 20
            while not replies and time.monotonic() < deadline:  # until the link is up
                replies = await asking.query(KEY, timeout=1.0)
            assert replies == [(KEY, payload) for payload in history]
        finally:
            asking.close()
            answering.close()

    asyncio.run(scenario())
