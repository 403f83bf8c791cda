"""Endpoints (``--connect``, ``--listen``, a transport or deployment file's) are checked
when a :class:`TransportConfig` is made, before any session opens: a bad one is one line
saying what is wrong, not Zenoh's multi-line error when the session opens (or a stack left
running by ``zenav up``)."""

from __future__ import annotations

from pathlib import Path

import pytest
from pydantic import ValidationError

from tests.unit.clirun import zenav
from zenav.services.transport import TransportConfig, check_endpoint

REPO = Path(__file__).resolve().parents[2]
SERVER = REPO / "deploy" / "server.yaml"


# --- endpoints ----------------------------------------------------------------------

GOOD_ENDPOINTS = ["tcp/127.0.0.1:7447", "udp/[::1]:7447", "tls/robot.local:7447",
                  "quic/10.0.0.2:0", "ws/localhost:65535", "tcp/127.0.0.1:7447?iface=lo",
                  "tcp/0.0.0.0:7447#rx_buffer_size=65536", "unixsock-stream//tmp/zenoh.sock"]


@pytest.mark.parametrize("endpoint", GOOD_ENDPOINTS)
def test_an_endpoint_zenoh_takes_is_taken(endpoint: str) -> None:
    assert check_endpoint(endpoint) == endpoint
    config = TransportConfig(mode="client", connect=[endpoint])
    config.to_zenoh()  # Zenoh's own parser agrees


@pytest.mark.parametrize(("endpoint", "problem"), [
    ("garbage", "'garbage' is not a Zenoh endpoint: expected PROTOCOL/ADDRESS"),
    ("", "'' is not a Zenoh endpoint"),
    ("tcp/", "'tcp/' is not a Zenoh endpoint"),
    ("tcp/127.0.0.1:99999", "'tcp/127.0.0.1:99999': port 99999 is not from 0 to 65535"),
    ("tcp/127.0.0.1", "'tcp/127.0.0.1': expected tcp/HOST:PORT"),
    ("tcp/:7447", "'tcp/:7447': expected tcp/HOST:PORT"),
    ("tcp/host:-1", "'tcp/host:-1': expected tcp/HOST:PORT"),
    ("tcp/[::1:7447", "'tcp/[::1:7447': '[::1' is not a host name or address"),
    ("http/host:80", "'http/host:80': unknown protocol 'http'"),
])
def test_a_bad_endpoint_is_one_line_saying_why(endpoint: str, problem: str) -> None:
    with pytest.raises(ValueError) as caught:
        check_endpoint(endpoint)
    assert str(caught.value).startswith(problem)
    assert "\n" not in str(caught.value)
    with pytest.raises(ValidationError):
        TransportConfig(connect=[endpoint])
    with pytest.raises(ValidationError):
        TransportConfig.model_validate({"listen": [endpoint]})


# --- zenav up -------------------------------------------------------------------------

@pytest.mark.parametrize("printing", [[], ["--print"]])
def test_up_refuses_a_bad_endpoint_before_anything_starts(
        printing: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, err = zenav(["up", "--config", str(SERVER), "--run-dir", str(tmp_path / "run"),
                       "--connect", "garbage", *printing], capsys)
    assert (code, err) == (2, ["zenav up: --connect: 'garbage' is not a Zenoh endpoint: "
                               "expected PROTOCOL/ADDRESS, e.g. tcp/127.0.0.1:7447"])
    assert not (tmp_path / "run").exists()


def test_up_refuses_a_bad_endpoint_in_the_deployment_file(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "d.yaml"
    path.write_text("name: t\ntransport: {mode: client, connect: [tcpx/127.0.0.1:7447]}\n"
                    "services: {}\n")
    code, err = zenav(["up", "--config", str(path), "--run-dir", str(tmp_path / "run"),
                       "--print"], capsys)
    assert code == 2
    assert err == [f"zenav up: {path}: transport.connect.0: 'tcpx/127.0.0.1:7447': unknown "
                   "protocol 'tcpx' (one of tcp, udp, tls, quic, ws, unixsock-stream, "
                   "unixpipe, serial, vsock), e.g. tcp/127.0.0.1:7447"]


@pytest.mark.parametrize(("option", "line"), [
    (["--listen", "garbage"], "argument --listen: 'garbage' is not a Zenoh endpoint: expected "
     "PROTOCOL/ADDRESS, e.g. tcp/127.0.0.1:7447"),
    (["--connect", "tcp/127.0.0.1:99999"],
     "argument --connect: 'tcp/127.0.0.1:99999': port 99999 is not from 0 to 65535"),
])
def test_the_router_refuses_a_bad_endpoint_in_one_line(
        option: list[str], line: str, capsys: pytest.CaptureFixture[str]) -> None:
    code, err = zenav(["router", *option], capsys)
    assert (code, err) == (2, [f"zenav router: {line}"])


def test_the_router_names_the_field_of_a_bad_transport_file(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "t.yaml"
    path.write_text("listen: [tcp/0.0.0.0:7447]\nconnect: [garbage]\n")
    code, err = zenav(["router", "--transport", str(path)], capsys)
    assert (code, err) == (2, [f"zenav router: {path}: connect.0: 'garbage' is not a Zenoh "
                               "endpoint: expected PROTOCOL/ADDRESS, e.g. tcp/127.0.0.1:7447"])


def test_only_a_client_with_no_way_to_find_a_router_finds_none() -> None:
    assert TransportConfig(mode="client").finds_no_router()
    assert not TransportConfig(mode="client", connect=["tcp/127.0.0.1:7447"]).finds_no_router()
    assert not TransportConfig(mode="client", multicast_scouting=True).finds_no_router()
    assert not TransportConfig(mode="client", extra={"connect/endpoints": ["tcp/10.0.0.1:7447"]}
                               ).finds_no_router()
    assert not TransportConfig(mode="peer").finds_no_router()  # a peer may wait to be found


def test_a_zenoh_error_is_shown_without_the_places_in_zenohs_source() -> None:
    from zenav.services.transport import zenoh_problem

    text = ("Can not create a new TCP listener bound to tcp/127.0.0.1:7447: [127.0.0.1:7447: "
            "Address already in use (os error 98) at /root/.cargo/git/checkouts/zenoh-9c5/"
            "cc83980/io/zenoh-links/zenoh-link-tcp/src/unicast.rs:61.] at /root/.cargo/git/"
            "checkouts/zenoh-9c5/cc83980/zenoh/src/net/runtime/orchestrator.rs:338.")
    assert zenoh_problem(RuntimeError(text)) == (
        "Can not create a new TCP listener bound to tcp/127.0.0.1:7447: [127.0.0.1:7447: "
        "Address already in use (os error 98)]")
    assert zenoh_problem(RuntimeError("Unable to connect to any of [tcp/1.2.3.4:7447]!  at "
                                      "/x/orchestrator.rs:447.")) == (
        "Unable to connect to any of [tcp/1.2.3.4:7447]!")
