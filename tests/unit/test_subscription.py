"""The subscription buffer a service's inputs go through: bounded newest-wins whether
samples come from the loop's thread or from another (Zenoh's), one wake-up of the loop
per burst, samples handed to the consumer in order, and held back while it is paused."""

from __future__ import annotations

import asyncio
import threading

from zenav.schemas import keys
from zenav.schemas.codec import encode
from zenav.schemas.keys import Keys
from zenav.schemas.messages import VelocityCommand
from zenav.services.node import Node
from zenav.services.transport import InMemoryBus, Subscription


def _offer_from_a_thread(sub: Subscription, payloads: list[bytes]) -> None:
    def offer_all() -> None:
        for payload in payloads:
            sub.offer("k", payload)

    thread = threading.Thread(target=offer_all)
    thread.start()
    thread.join()


async def test_samples_offered_from_another_thread_are_bounded_newest_wins() -> None:
    loop = asyncio.get_running_loop()
    sub = Subscription("k", depth=2, loop=loop)
    seen: list[bytes] = []
    sub.consume(lambda key, payload: seen.append(payload))
    wakes = 0
    wake = sub._wake

    def counted() -> None:
        nonlocal wakes
        wakes += 1
        wake()

    sub._wake = counted  # type: ignore[method-assign]
    _offer_from_a_thread(sub, [b"1", b"2", b"3", b"4", b"5"])  # the loop has not run yet
    for _ in range(3):
        await asyncio.sleep(0)
    assert seen == [b"4", b"5"]
    assert sub.dropped == 3
    # One wake-up from the other thread for the burst (not one per sample), then one turn
    # of the loop per sample.
    assert wakes == 2
    _offer_from_a_thread(sub, [b"6"])
    for _ in range(3):
        await asyncio.sleep(0)
    assert seen == [b"4", b"5", b"6"] and wakes == 3 and sub.dropped == 3


async def test_a_paused_consumer_gets_the_newest_samples_on_resume() -> None:
    sub = Subscription("k", depth=2)
    seen: list[bytes] = []
    sub.consume(lambda key, payload: seen.append(payload))
    sub.pause()
    for p in (b"1", b"2", b"3"):
        sub.push("k", p)
    await asyncio.sleep(0)
    assert seen == [] and sub.pending() == 2
    sub.resume()
    for _ in range(3):
        await asyncio.sleep(0)
    assert seen == [b"2", b"3"] and sub.dropped == 1


async def test_inputs_take_turns_a_sample_each_as_their_samples_came() -> None:
    """Two inputs with samples waiting (the loop was busy): handled a, b, a, b as they came,
    not all of one input first (a scan that waits for its odometry must get it before the
    next scan comes)."""
    loop = asyncio.get_running_loop()
    scans, odometry = Subscription("scan", 4, loop), Subscription("odom", 4, loop)
    handled: list[bytes] = []
    scans.consume(lambda key, payload: handled.append(payload))
    odometry.consume(lambda key, payload: handled.append(payload))
    for sub, payload in ((scans, b"scan 0.2"), (odometry, b"odom 0.2"),
                         (scans, b"scan 0.3"), (odometry, b"odom 0.3")):
        _offer_from_a_thread(sub, [payload])
    for _ in range(6):
        await asyncio.sleep(0)
    assert handled == [b"scan 0.2", b"odom 0.2", b"scan 0.3", b"odom 0.3"]


async def test_get_still_serves_a_task_when_samples_come_from_another_thread() -> None:
    sub = Subscription("k", depth=4, loop=asyncio.get_running_loop())
    waiter = asyncio.create_task(sub.get())
    await asyncio.sleep(0)
    _offer_from_a_thread(sub, [b"1", b"2"])
    assert await asyncio.wait_for(waiter, 1.0) == ("k", b"1")
    assert await sub.get() == ("k", b"2")


async def test_a_handler_awaiting_holds_back_its_input_until_done() -> None:
    bus = InMemoryBus()
    k = Keys("test")
    node = Node("probe", bus, k)
    release = asyncio.Event()
    handled: list[tuple[str, float]] = []

    async def slow(command: VelocityCommand) -> None:
        handled.append(("start", command.stamp))
        await release.wait()
        handled.append(("end", command.stamp))

    node.subscribe(keys.CMD_VEL, VelocityCommand, slow, depth=1)
    spin = asyncio.create_task(node.spin())
    await asyncio.sleep(0)

    def send(t: float) -> None:
        bus.deliver(k.of(keys.CMD_VEL), encode(VelocityCommand(stamp=t, seq=0, v=0.0,
                                                               omega=0.0)))

    send(1.0)
    for _ in range(5):
        await asyncio.sleep(0)
    send(2.0)
    send(3.0)  # 2.0 is dropped: depth 1, newest wins, while 1.0 is still being handled
    for _ in range(5):
        await asyncio.sleep(0)
    assert handled == [("start", 1.0)]
    release.set()
    for _ in range(10):
        await asyncio.sleep(0)
    assert handled == [("start", 1.0), ("end", 1.0), ("start", 3.0), ("end", 3.0)]
    assert node.received["cmd_vel"] == 2 and node.status().dropped == {k.of(keys.CMD_VEL): 1}
    node.request_stop()
    await spin
