"""``Bus.latest``: the newest sample of a key, taken when the consumer looks (the run
tool's progress check), on the in-memory bus."""

from __future__ import annotations

import asyncio

from zenav.services.transport import InMemoryBus


def test_latest_keeps_only_the_newest_and_is_taken_once():
    async def scenario() -> None:
        bus = InMemoryBus()
        newest = bus.latest("zenav/robot0/odom")
        assert newest.take() is None
        pub = bus.publisher("zenav/robot0/odom")
        for payload in (b"1", b"2", b"3"):
            pub.put(payload)
        bus.publisher("zenav/robot0/scan").put(b"other key")
        assert newest.take() == ("zenav/robot0/odom", b"3")
        assert newest.take() is None
        newest.close()
        pub.put(b"4")  # closed: nothing kept, nothing raised
        assert newest.take() is None

    asyncio.run(scenario())
