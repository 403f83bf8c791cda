"""``zenav replay``'s options and its wait for the services it feeds (``--wait-for``):
an unknown name or a bad number is one line and status 2; the wait says what it waits
for, ends when they are all alive, names the missing ones at its timeout, and stops at
once on SIGINT or SIGTERM (the stop event)."""

from __future__ import annotations

import asyncio
from pathlib import Path

import pytest

from tests.unit.clirun import zenav
from tests.unit.test_bad_input_table import a_bag
from zenav.bag.replay import WAITABLE, parse_wait_for, wait_alive
from zenav.schemas.keys import Keys
from zenav.services.transport import InMemoryBus

NOBODY = "tcp/127.0.0.1:9"


@pytest.mark.parametrize(("argv", "line"), [
    (["replay", "x.mcap", "--rate", "nan"], "--rate: must be a finite number (got nan)"),
    (["replay", "x.mcap", "--rate", "0"], "--rate: must be > 0 (got 0)"),
    (["replay", "x.mcap", "--timeout", "-1"], "--timeout: must be > 0 (got -1)"),
])
def test_a_bad_number_is_refused_by_the_parser(
        argv: list[str], line: str, capsys: pytest.CaptureFixture[str]) -> None:
    code, err = zenav(argv, capsys)
    assert (code, err) == (2, [f"zenav {argv[0]}: argument {line}"])


def test_replay_refuses_an_unknown_service_to_wait_for(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, err = zenav(["replay", str(a_bag(tmp_path)), "--wait-for", "planner,bogus",
                       "--connect", NOBODY], capsys)
    assert (code, err) == (2, [f"zenav replay: --wait-for: no process is called bogus (the "
                               f"names are {', '.join(WAITABLE)})"])
    assert parse_wait_for(" perception, planner ,") == ["perception", "planner"]


# --- waiting for services before a replay ---------------------------------------------

GUARD = 30.0
"""s after which a wait that should have ended counts as hung (not a speed target)."""


def test_replay_waits_until_every_named_service_is_alive(
        capsys: pytest.CaptureFixture[str]) -> None:
    keys = Keys("robot0")

    async def scenario() -> bool:
        bus = InMemoryBus()
        bus.declare_token(keys.alive("perception"))
        stop = asyncio.Event()
        waiting = asyncio.ensure_future(
            wait_alive(bus, keys, ["perception", "planner"], 1e6, stop))
        await asyncio.sleep(0.01)
        assert not waiting.done()  # planner is not there yet
        bus.declare_token(keys.alive("planner"))
        return await asyncio.wait_for(waiting, GUARD)

    assert asyncio.run(scenario()) is True
    assert capsys.readouterr().err.splitlines() == [
        "zenav replay: waiting for perception, planner on robot robot0 (up to 1e+06 s)"]


def test_replay_stops_waiting_for_services_when_told_to() -> None:
    keys = Keys("robot0")

    async def scenario() -> bool:
        stop = asyncio.Event()
        waiting = asyncio.ensure_future(wait_alive(InMemoryBus(), keys, ["planner"], 1e6,
                                                   stop))
        await asyncio.sleep(0.01)
        stop.set()  # what SIGINT does
        return await asyncio.wait_for(waiting, GUARD)

    assert asyncio.run(scenario()) is False


def test_replay_names_the_services_still_missing_at_its_timeout() -> None:
    keys = Keys("robot0")
    bus = InMemoryBus()
    bus.declare_token(keys.alive("tracking"))
    with pytest.raises(TimeoutError, match=r"not alive after 0\.05 s: perception, planner"):
        asyncio.run(wait_alive(bus, keys, ["planner", "tracking", "perception"], 0.05,
                               asyncio.Event()))


def test_replay_says_nothing_when_everything_is_already_alive(
        capsys: pytest.CaptureFixture[str]) -> None:
    keys = Keys("robot0")
    bus = InMemoryBus()
    bus.declare_token(keys.alive("planner"))
    assert asyncio.run(wait_alive(bus, keys, ["planner"], 1.0, asyncio.Event())) is True
    assert capsys.readouterr().err == ""
