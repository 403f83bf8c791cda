"""The tools' bad input (``monitor``, ``record``, ``replay``, ``rviz``, ``foxglove``,
``up``): each mistake is one line naming it and exit status 2, found before any session
opens or anything starts (a transport file, a transport option, a number or a name the
parser refuses, ``up``'s run directory); and the status a tool ends with after a signal.

Every CLI row runs the real ``zenav`` entry point in this process; none gets as far as
opening a Zenoh session.
"""

from __future__ import annotations

import argparse
import asyncio
import math
import os
import signal
from pathlib import Path

import pytest

from tests.unit.clirun import zenav
from tests.unit.test_bad_input_table import a_bag
from zenav import argtypes, tooling
from zenav.services.config import ConfigError, read_transport

REPO = Path(__file__).resolve().parents[2]
NOBODY = "tcp/127.0.0.1:9"


# --- transport files ----------------------------------------------------------------


def test_a_transport_file_problem_is_one_line_each_naming_file_and_field(
        tmp_path: Path) -> None:
    path = tmp_path / "t.yaml"
    path.write_text("mode: bogus\nlisten: 5\nconnect: [garbage]\nfoo: 1\n")
    with pytest.raises(ConfigError) as caught:
        read_transport(path)
    assert str(caught.value).splitlines() == [
        f"{path}: mode: Input should be 'peer', 'client' or 'router' (got 'bogus')",
        f"{path}: listen: Input should be a valid list (got 5)",
        f"{path}: connect.0: 'garbage' is not a Zenoh endpoint: expected PROTOCOL/ADDRESS, "
        "e.g. tcp/127.0.0.1:7447",
        f"{path}: foo: Extra inputs are not permitted (got 1)",
    ]


@pytest.mark.parametrize(("text", "problem"), [
    (None, "cannot read (No such file or directory)"),
    ("listen: [a\nmode: x: y\n", "not valid YAML (expected ',' or ']', but got ':' (line 2, "
     "column 5))"),
    (b"mode: \xff\xfe", "not a text file"),
    ("- a\n- b\n", "expected a mapping of transport settings (mode, listen, connect, "
     "multicast_scouting, lease_ms, extra)"),
])
def test_an_unreadable_transport_file_is_one_line(tmp_path: Path, text: str | bytes | None,
                                                  problem: str) -> None:
    path = tmp_path / "t.yaml"
    if isinstance(text, bytes):
        path.write_bytes(text)
    elif text is not None:
        path.write_text(text)
    with pytest.raises(ConfigError) as caught:
        read_transport(path)
    assert str(caught.value) == f"{path}: {problem}"


def test_a_good_transport_file_is_read_with_the_mode_override(tmp_path: Path) -> None:
    path = tmp_path / "t.yaml"
    path.write_text("mode: client\nconnect: [tcp/127.0.0.1:7447]\n")
    assert read_transport(path).connect == ["tcp/127.0.0.1:7447"]


# --- the commands' bad input: one line, status 2 --------------------------------------

TOOLS = {
    "monitor": lambda t: ["monitor", "--jsonl"],
    "record": lambda t: ["record", str(t / "out.mcap")],
    "replay": lambda t: ["replay", str(a_bag(t))],
    "rviz": lambda t: ["rviz"],
    "foxglove": lambda t: ["foxglove", "--port", "0"],
}


@pytest.mark.parametrize("tool", sorted(TOOLS))
@pytest.mark.parametrize(("option", "line"), [
    (["--connect", "garbage"], "argument --connect: 'garbage' is not a Zenoh endpoint: expected "
     "PROTOCOL/ADDRESS, e.g. tcp/127.0.0.1:7447"),
    (["--listen", "tcp/127.0.0.1:99999"],
     "argument --listen: 'tcp/127.0.0.1:99999': port 99999 is not from 0 to 65535"),
    (["--transport", "/nonexistent/t.yaml"],
     "/nonexistent/t.yaml: cannot read (No such file or directory)"),
    (["--base-port", "70000"],
     "argument --base-port: must be in 1..65529: the mesh takes 7 ports from it (got 70000)"),
    (["--base-port", "-5"],
     "argument --base-port: must be in 1..65529: the mesh takes 7 ports from it (got -5)"),
])
def test_a_tool_refuses_a_bad_transport_option_in_one_line(
        tool: str, option: list[str], line: str, tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    code, err = zenav([*TOOLS[tool](tmp_path), *option], capsys)
    assert (code, err) == (2, [f"zenav {tool}: {line}"])
    assert not (tmp_path / "out.mcap").exists()


@pytest.mark.parametrize(("argv", "line"), [
    (["monitor", "--period", "0"], "--period: must be >= 0.01 (got 0)"),
    (["monitor", "--jsonl", "--period", "-1"], "--period: must be >= 0.01 (got -1)"),
    (["monitor", "--duration", "nan"], "--duration: must be a finite number (got nan)"),
    (["monitor", "--duration", "0"], "--duration: must be > 0 (got 0)"),
    (["monitor", "--silence", "-1"], "--silence: must be > 0 (got -1)"),
    (["monitor", "--map-scale", "inf"], "--map-scale: must be a finite number (got inf)"),
    (["monitor", "--connect-timeout", "-1"], "--connect-timeout: must be > 0 (got -1)"),
    (["record", "x.mcap", "--duration", "-1"], "--duration: must be > 0 (got -1)"),
    (["record", "x.mcap", "--exclude", "bogus"], "--exclude: no topic 'bogus'; the "
     "topics are device/laser, device/base_cmd, scan, odom, obstacles, tracks, cmd_vel, "
     "planner/events, planner/state, planner/path, planner/map, sim/truth, sim/result and "
     "status/SERVICE"),
    (["foxglove", "--duration", "-1"], "--duration: must be > 0 (got -1)"),
    (["foxglove", "--port", "70000"], "--port: must be in 0..65535 (got 70000)"),
    (["rviz", "--domain-id", "-1"], "--domain-id: must be in 0..232 (got -1)"),
    (["rviz", "--domain-id", "99999"], "--domain-id: must be in 0..232 (got 99999)"),
    (["rviz", "--frame", ""], "--frame: must not be empty"),
    (["up", "--timeout", "nan"], "--timeout: must be a finite number (got nan)"),
    (["up", "--timeout", "-1"], "--timeout: must be > 0 (got -1)"),
])
def test_a_bad_number_or_name_is_refused_by_the_parser(
        argv: list[str], line: str, capsys: pytest.CaptureFixture[str]) -> None:
    code, err = zenav(argv, capsys)
    assert (code, err) == (2, [f"zenav {argv[0]}: argument {line}"])


def test_record_excludes_a_status_topic(tmp_path: Path) -> None:
    from zenav.bag.record import recordable_topic

    assert recordable_topic("status/planner") == "status/planner"
    assert recordable_topic("sim/truth") == "sim/truth"


def test_foxglove_refuses_a_host_that_does_not_resolve(
        capsys: pytest.CaptureFixture[str]) -> None:
    code, err = zenav(["foxglove", "--host", "no such host", "--connect", NOBODY], capsys)
    assert code == 2
    assert len(err) == 1
    assert err[0].startswith("zenav foxglove: --host 'no such host': not an address or a "
                             "host name that resolves")


# --- zenav up: its run directory ----------------------------------------

SERVER = REPO / "deploy" / "server.yaml"


@pytest.mark.parametrize(("run_dir", "line"), [
    (lambda t: Path("/proc/zenav"), "/proc/zenav: under /proc, which is not a place for "
     "output"),
    (lambda t: t / "afile", "{t}/afile: exists and is not a folder"),
    (lambda t: t / "afile" / "run", "{t}/afile/run: {t}/afile is a file, not a folder"),
])
def test_up_refuses_a_run_dir_it_cannot_make(
        run_dir: object, line: str, tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "afile").write_text("x")
    assert callable(run_dir)
    code, err = zenav(["up", "--config", str(SERVER), "--run-dir", str(run_dir(tmp_path)),
                       "--print"], capsys)
    assert (code, err) == (2, [f"zenav up: --run-dir {line.format(t=tmp_path)}"])


def test_up_says_in_one_line_when_it_cannot_write_its_run_dir(
        tmp_path: Path, capsys: pytest.CaptureFixture[str],
        monkeypatch: pytest.MonkeyPatch) -> None:
    from zenav.deploy import commands

    def refused(deployment: object, run_dir: Path) -> Path:
        raise PermissionError(1, "Operation not permitted", str(run_dir / "transport.yaml"))

    monkeypatch.setattr(commands, "prepare", refused)
    run = tmp_path / "run"
    code, err = zenav(["up", "--config", str(SERVER), "--run-dir", str(run)], capsys)
    assert (code, err) == (2, [f"zenav up: --run-dir {run}: cannot write "
                               f"{run}/transport.yaml (Operation not permitted)"])


# --- argument types -------------------------------------------------------------------


def test_the_argument_types_take_good_values() -> None:
    assert argtypes.positive_float("0.5") == 0.5
    assert argtypes.float_at_least(0.01)("0.01") == 0.01
    assert argtypes.port("0") == 0 and argtypes.port("65535") == 65535
    assert argtypes.nonempty("odom") == "odom"
    for bad in ("0", "-1", "nan", "inf", "x"):
        with pytest.raises(argparse.ArgumentTypeError):
            argtypes.positive_float(bad)
    assert math.isfinite(argtypes.positive_float("1e300"))


GUARD = 30.0
"""s after which a wait that should have ended counts as hung (not a speed target)."""


# --- the exit status after a signal -------------------------------------------------


@pytest.mark.parametrize(("signum", "status"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_tool_stopped_by_a_signal_ends_with_128_plus_its_number(
        signum: signal.Signals, status: int, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(tooling, "_SIGNALLED", [])

    async def tool() -> None:
        stop = asyncio.Event()
        tooling.stop_on_signals(stop)
        os.kill(os.getpid(), signum)
        await asyncio.wait_for(stop.wait(), GUARD)

    assert tooling.run_tool("test", tool()) == status


def test_a_tool_that_ends_by_itself_ends_with_0(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(tooling, "_SIGNALLED", [])

    async def tool() -> None:
        tooling.stop_on_signals(asyncio.Event())

    assert tooling.run_tool("test", tool()) == 0
