"""How a tool (monitor, record, replay, rviz, foxglove) joins the loopback mesh of
``zenav service`` processes when it is given no endpoint: it listens on the mesh's tool
port when that port is free, so that services started after it link to it from their
first message, and it retries services not up yet sooner than Zenoh's default. The
process-level check is the by-hand test in tests/integration/test_newcomer.py: a recorder
started first has each service's first message."""

from __future__ import annotations

import argparse
import asyncio
import socket

from zenav.launch import free_port_block, loopback_ports_free
from zenav.services.config import SERVICE_ORDER, loopback_port, tool_port
from zenav.services.runner import add_transport_arguments
from zenav.tooling import MESH_RETRY, MeshTool, add_connect_timeout, open_bus, tool_transport


def tool_args(*argv: str) -> argparse.Namespace:
    """A tool's parsed transport options, through the parser the tools use."""
    parser = argparse.ArgumentParser()
    add_transport_arguments(parser)
    add_connect_timeout(parser)
    return parser.parse_args(list(argv))


def test_the_tool_port_follows_the_services_ports() -> None:
    base = 7450
    assert [loopback_port(name, base) for name in SERVICE_ORDER] == list(range(base, base + 6))
    assert tool_port(base) == base + 6


def test_a_tool_on_a_free_mesh_listens_on_the_tool_port_and_connects_to_every_service() -> None:
    base = free_port_block()
    config = tool_transport(tool_args("--base-port", str(base)))
    assert config.mode == "peer"
    assert config.listen == [f"tcp/127.0.0.1:{base + 6}"]
    assert config.connect == [f"tcp/127.0.0.1:{port}" for port in range(base, base + 6)]
    assert config.extra["connect/retry"] == MESH_RETRY["connect/retry"]


def test_a_second_tool_finds_the_tool_port_taken_and_only_connects() -> None:
    base = free_port_block()
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as held:
        held.bind(("127.0.0.1", tool_port(base)))
        held.listen()
        assert not loopback_ports_free([tool_port(base)])
        config = tool_transport(tool_args("--base-port", str(base)))
    assert config.listen == []
    assert len(config.connect) == 6
    assert config.extra["connect/retry"] == MESH_RETRY["connect/retry"]


def test_a_tool_given_endpoints_keeps_them_as_given() -> None:
    client = tool_transport(tool_args("--connect", "tcp/127.0.0.1:7447"))
    assert (client.mode, client.listen, client.connect) == ("client", [], ["tcp/127.0.0.1:7447"])
    assert client.extra["connect/retry"] != MESH_RETRY["connect/retry"]  # the client's own
    peer = tool_transport(tool_args("--listen", "tcp/127.0.0.1:7460"))
    assert (peer.mode, peer.listen, peer.connect) == ("peer", ["tcp/127.0.0.1:7460"], [])
    assert "connect/retry" not in peer.extra


def test_a_tool_that_loses_the_tool_port_before_it_opens_joins_connecting_only() -> None:
    """The port was free as the options were read and is taken when the session opens
    (another tool started in the same instant): the session opens all the same, without
    listening."""
    base = free_port_block()
    config = tool_transport(tool_args("--base-port", str(base)))
    assert isinstance(config, MeshTool) and config.listen
    stop = asyncio.Event()

    async def open_and_close() -> bool:
        bus = await open_bus(config, stop, timeout=30.0)
        assert bus is not None
        try:
            return not bus.session.is_closed()
        finally:
            bus.close()

    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as held:
        held.bind(("127.0.0.1", tool_port(base)))
        held.listen()
        assert asyncio.run(open_and_close())
