"""A service opens its Zenoh session on a thread of its own while it loads its modules
(services.runner.SessionOpening): what comes out of it is an open session or the error
``zenoh.open`` raised, and a service that will not start leaves nothing opening."""

from __future__ import annotations

import asyncio
import time

import pytest

from zenav.launch import free_port_block
from zenav.services import runner
from zenav.services.transport import TransportConfig


def _lone_peer() -> TransportConfig:
    """A peer that connects to a port no one listens on: ``zenoh.open`` returns after its
    scouting delay (half a second), waiting for that link in vain."""
    return TransportConfig(mode="peer", connect=[f"tcp/127.0.0.1:{free_port_block(1)}"])


def _wait_until_opened(limit: float = 30.0) -> None:
    deadline = time.monotonic() + limit
    while runner.still_opening():
        assert time.monotonic() < deadline, "zenoh.open did not return"
        time.sleep(0.01)


def test_the_session_comes_out_open_and_is_the_callers() -> None:
    opening = runner.SessionOpening(_lone_peer())
    session = asyncio.run(opening.session())
    try:
        assert not session.is_closed()
        opening.abandon()  # handed over: no longer the opening's to close
        assert not session.is_closed()
    finally:
        session.close()
    assert not runner.still_opening()


def test_an_error_from_zenoh_open_is_raised_where_the_session_is_awaited() -> None:
    # Built unchecked: TransportConfig itself refuses an endpoint Zenoh would not take.
    broken = TransportConfig.model_construct(mode="peer", listen=["nonsense/127.0.0.1:1"])
    opening = runner.SessionOpening(broken)
    with pytest.raises(Exception, match="nonsense"):
        asyncio.run(opening.session())
    assert not runner.still_opening()


def test_an_abandoned_opening_closes_its_session_and_leaves_nothing_opening() -> None:
    opening = runner.SessionOpening(_lone_peer())
    assert runner.still_opening()
    opening.abandon()  # while zenoh.open is still in its scouting delay
    _wait_until_opened()
    assert opening._future.done() is False  # never handed to anyone
    opened = runner.SessionOpening(_lone_peer())
    _wait_until_opened()
    session = opened._future.result(timeout=1)
    opened.abandon()  # opened, then abandoned: closed here
    assert session.is_closed()


def test_a_service_given_bad_input_opens_no_session(capsys: pytest.CaptureFixture[str]) -> None:
    """The input is checked before the session starts opening: exit 2 with the reason,
    and nothing left opening (the ``zenav`` command would end such a process at once)."""
    assert runner.main("tracking", ["--set", "no_such_parameter=1", "--base-port",
                                    str(free_port_block(7))]) == 2
    assert "no_such_parameter" in capsys.readouterr().err
    assert not runner.still_opening()
    assert not runner.closed_cleanly()
