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
            marker = receiver.latest("zenav/robot0/marker")
            pub = sender.publisher("zenav/robot0/odom")
            after = sender.publisher("zenav/robot0/marker")
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
        finally:
            sender.close()
            receiver.close()

    asyncio.run(scenario())
