"""A tool that hears nothing of its robot says where to look, once, after a few seconds:
on the loopback mesh (a tool's default) the usual cause is a stack started with
``zenav up``, whose services talk only through its router."""

from __future__ import annotations

import asyncio

import pytest

from zenav.services.config import loopback_mesh
from zenav.services.transport import TransportConfig
from zenav.tooling import Heard, client_transport, note_if_quiet, on_the_mesh, quiet_note


def test_on_the_loopback_mesh_the_note_points_at_the_router() -> None:
    mesh = on_the_mesh(loopback_mesh(None, 17000), 17000)
    line = quiet_note("monitor", mesh, "robot0")
    assert line.startswith("zenav monitor: nothing heard from robot0 in 3 s on the loopback mesh")
    assert "--connect tcp/127.0.0.1:7447" in line


def test_through_a_router_the_note_names_it() -> None:
    line = quiet_note("record", client_transport(["tcp/10.0.0.2:7447"]), "r2", after=5.0)
    assert line == ("zenav record: nothing heard from r2 in 5 s through the router at "
                    "tcp/10.0.0.2:7447: are the services up and joined to it, with this "
                    "--robot-id?")


def test_a_peer_of_its_own_choosing_gets_the_plain_question() -> None:
    peer = TransportConfig(mode="peer", connect=["tcp/127.0.0.1:9000"])
    assert quiet_note("foxglove", peer, "robot0").endswith(
        "in 3 s: are the services up on this transport, with this --robot-id?")


def run_note(heard: Heard, stop_after: float | None) -> None:
    async def main() -> None:
        stop = asyncio.Event()
        if stop_after is not None:
            asyncio.get_running_loop().call_later(stop_after, stop.set)
        await note_if_quiet(heard, stop, "the note", after=0.05)

    asyncio.run(main())


def test_the_note_comes_once_when_nothing_is_heard(capsys: pytest.CaptureFixture[str]) -> None:
    run_note(Heard(), None)
    assert capsys.readouterr().err == "the note\n"


def test_no_note_once_something_is_heard(capsys: pytest.CaptureFixture[str]) -> None:
    heard = Heard()
    heard.mark()
    run_note(heard, None)
    assert capsys.readouterr().err == ""


def test_no_note_when_the_tool_stops_first(capsys: pytest.CaptureFixture[str]) -> None:
    run_note(Heard(), 0.0)
    assert capsys.readouterr().err == ""
