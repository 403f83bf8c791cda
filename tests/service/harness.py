"""Run one service on the in-memory bus and talk to it in typed messages."""

from __future__ import annotations

import asyncio
from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from typing import Any, TypeVar

from zenav.schemas.codec import decode, encode
from zenav.schemas.keys import Keys, Topic
from zenav.schemas.messages import Message
from zenav.services.node import Node
from zenav.services.runner import implementation
from zenav.services.transport import InMemoryBus

M = TypeVar("M", bound=Message)


class Harness:
    def __init__(self, bus: InMemoryBus, keys: Keys, node: Node, service: Any) -> None:
        self.bus = bus
        self.keys = keys
        self.node = node
        self.service = service

    def send(self, topic: Topic, message: Message) -> None:
        self.bus.deliver(self.keys.of(topic), encode(message))

    def send_raw(self, topic: Topic, payload: bytes) -> None:
        self.bus.deliver(self.keys.of(topic), payload)

    def received(self, topic: Topic, message_type: type[M]) -> list[M]:
        key = self.keys.of(topic)
        return [decode(p, message_type, k) for k, p in self.bus.published if k == key]

    async def settle(self) -> None:
        """Let every queued input be handled."""
        for _ in range(20):
            await asyncio.sleep(0)


@asynccontextmanager
async def running(name: str, params: Any) -> AsyncIterator[Harness]:
    bus = InMemoryBus()
    keys = Keys("test")
    node = Node(name, bus, keys)
    service = implementation(name).Service(node, params)
    task = asyncio.create_task(node.spin())
    run = getattr(service, "run", None)
    run_task = asyncio.create_task(run()) if run is not None else None
    await asyncio.sleep(0)
    try:
        yield Harness(bus, keys, node, service)
    finally:
        node.request_stop()
        if run_task is not None:
            run_task.cancel()
        await asyncio.gather(task, *( [run_task] if run_task else []), return_exceptions=True)


@asynccontextmanager
async def planner(name: str, **params: Any) -> AsyncIterator[Harness]:
    """The planner service of implementation ``name`` (paper, vfh, dwa, apf, orca) on the
    in-memory bus, going from (2, 5) to (8, 5) unless ``params`` say otherwise."""
    bus = InMemoryBus()
    keys = Keys("test")
    node = Node("planner", bus, keys)
    module = implementation("planner", name)
    service = module.Service(node, module.Params(**({"goal": (8.0, 5.0), "start": (2.0, 5.0)}
                                                     | params)))
    task = asyncio.create_task(node.spin())
    await asyncio.sleep(0)
    try:
        yield Harness(bus, keys, node, service)
    finally:
        node.request_stop()
        await asyncio.gather(task, return_exceptions=True)
