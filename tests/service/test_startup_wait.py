"""The simulator's start-up wait scales with what it waits for: its timeout is for the
next service to arrive, so a slow but steady start on a busy machine goes through, and a
service that never comes is named."""

from __future__ import annotations

import asyncio
from pathlib import Path

import pytest

from zenav.schemas.keys import Keys
from zenav.services.node import Node
from zenav.services.transport import InMemoryBus
from zenav.sim.node import Service, StackSilentError
from zenav.sim.params import Params

SCENARIO = Path(__file__).resolve().parents[2] / "sim" / "scenarios" / "a-no-obstacle.yaml"
WAIT_FOR = ["laser_driver", "perception", "tracking", "planner"]


def simulator(bus: InMemoryBus, timeout: float) -> Service:
    params = Params(scenario=str(SCENARIO), wait_for=WAIT_FOR, startup_timeout=timeout)
    return Service(Node("simulator", bus, Keys("test")), params)


async def test_services_arriving_slowly_but_steadily_are_waited_for() -> None:
    bus = InMemoryBus()
    sim = simulator(bus, timeout=0.4)
    waiting = asyncio.create_task(sim.wait_for_stack())
    for service in WAIT_FOR:  # 4 x 0.25 s: longer than the timeout in all
        await asyncio.sleep(0.25)
        bus.declare_token(Keys("test").alive(service))
    await asyncio.wait_for(waiting, timeout=5)


async def test_a_service_that_never_comes_is_named_after_the_timeout() -> None:
    bus = InMemoryBus()
    sim = simulator(bus, timeout=0.3)
    for service in WAIT_FOR[:-1]:
        bus.declare_token(Keys("test").alive(service))
    with pytest.raises(StackSilentError, match=r"still waiting on planner$"):
        await asyncio.wait_for(sim.wait_for_stack(), timeout=5)


async def test_a_service_leaving_mid_run_warns_but_one_leaving_after_the_end_does_not(
        caplog: pytest.LogCaptureFixture) -> None:
    bus = InMemoryBus()
    sim = simulator(bus, timeout=1.0)
    tokens = {service: bus.declare_token(Keys("test").alive(service)) for service in WAIT_FOR}
    await asyncio.sleep(0)
    caplog.set_level("INFO", logger="zenav.sim.node")
    tokens["planner"].undeclare()
    await asyncio.sleep(0)
    assert [r.levelname for r in caplog.records if "went away" in r.message] == ["WARNING"]
    caplog.clear()
    sim.sim.outcome = "reached"  # the run is over: the stack is being stopped
    tokens["tracking"].undeclare()
    await asyncio.sleep(0)
    assert [r.levelname for r in caplog.records if "went away" in r.message] == ["INFO"]
