"""``ZenohBus.latest`` over real Zenoh sessions: the newest sample of a key is held by the
middleware's ring channel and taken when the consumer looks, without a callback into
the receiving process's loop."""

from __future__ import annotations

import asyncio
import time

from zenav.launch import free_port_block
from zenav.services.transport import TransportConfig, ZenohBus


def test_the_newest_sample_waits_in_zenoh_until_taken():
    async def scenario() -> None:
        loop = asyncio.get_running_loop()
        endpoint = f"tcp/127.0.0.1:{free_port_block(1)}"
        receiver = ZenohBus(TransportConfig(listen=[endpoint]), loop)
        sender = ZenohBus(TransportConfig(connect=[endpoint]), loop)
        try:
            newest = receiver.latest("zenav/robot0/odom")
            pub = sender.publisher("zenav/robot0/odom")
            deadline = time.monotonic() + 10
            got = None
            while got is None and time.monotonic() < deadline:  # until the link is up
                pub.put(b"probe")
                await asyncio.sleep(0.05)
                got = newest.take()
            assert got == ("zenav/robot0/odom", b"probe")
            await asyncio.sleep(0.2)
            while newest.take() is not None:  # probes still on their way
                await asyncio.sleep(0.05)
            for payload in (b"1", b"2", b"3"):
                pub.put(payload)
            await asyncio.sleep(0.3)
            assert newest.take() == ("zenav/robot0/odom", b"3")
            assert newest.take() is None
        finally:
            sender.close()
            receiver.close()

    asyncio.run(scenario())
