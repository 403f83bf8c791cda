"""No command hangs: every tool that opens a Zenoh session, run as a real process against
a router that is not there or a peer that is dead, ends on its own with one line saying
why, honours ``--duration``, and stops within a second of SIGINT or SIGTERM while it is
still waiting. ``zenav up`` says which service it is still waiting on, and reports a
program that exits at start with that program's own line.

Each process runs with a timeout of its own, so a hang fails the test instead of
blocking it.
"""

from __future__ import annotations

import queue
import signal
import subprocess
import threading
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from tests.integration.livestack import REPO, Deployed, copy_deployment, run, zenav
from zenav.bag.mcapfile import BagWriter
from zenav.deploy.rpc import Supervisor
from zenav.launch import free_port_block
from zenav.schemas.codec import encode
from zenav.schemas.messages import Odometry, Pose2D

pytestmark = pytest.mark.integration

SCENARIO = REPO / "sim" / "scenarios" / "a-no-obstacle.yaml"

HANG = 90.0
"""s after which a process counts as hung (imports alone take seconds on a loaded box)."""


def nobody() -> str:
    """An endpoint where nothing listens."""
    return f"tcp/127.0.0.1:{free_port_block(1)}"


def a_bag(tmp: Path) -> Path:
    path = tmp / "in.mcap"
    with path.open("wb") as stream:
        writer = BagWriter(stream, "robot0")
        for i in range(3):
            writer.add("zenav/robot0/odom", encode(Odometry(
                stamp=0.1 * i, seq=i, pose=Pose2D(x=1.0, y=2.0, heading=0.0), v=0.0,
                omega=0.0)), 1 + i * 1_000_000)
        writer.close()
    return path


TOOLS: dict[str, Callable[[Path], list[str]]] = {
    "monitor": lambda tmp: ["monitor", "--jsonl"],
    "record": lambda tmp: ["record", str(tmp / "out.mcap")],
    "replay": lambda tmp: ["replay", str(a_bag(tmp))],
    "foxglove": lambda tmp: ["foxglove", "--port", "0"],
    "rviz": lambda tmp: ["rviz"],
}


@pytest.mark.parametrize("tool", sorted(TOOLS))
def test_a_tool_without_its_router_says_so_in_one_line(tool: str, tmp_path: Path) -> None:
    endpoint = nobody()
    done = run(zenav(*TOOLS[tool](tmp_path), "--connect", endpoint, "--connect-timeout", "2"),
               timeout=HANG)
    lines = done.stderr.splitlines()
    assert done.returncode == 1, done.stderr
    assert lines[-1] == f"zenav {tool}: no Zenoh router at {endpoint} after 2 s: is it running?"
    assert "Traceback" not in done.stderr


@pytest.mark.parametrize("tool", ["monitor", "record", "rviz"])
def test_a_tool_with_a_dead_peer_honours_its_duration(tool: str, tmp_path: Path) -> None:
    started = time.monotonic()
    done = run(zenav(*TOOLS[tool](tmp_path), "--mode", "peer", "--connect", nobody(),
                     "--duration", "2"), timeout=HANG)
    assert done.returncode == 0, done.stderr
    assert time.monotonic() - started >= 2.0
    assert "Traceback" not in done.stderr


@pytest.mark.parametrize("tool", ["monitor", "record", "foxglove", "rviz"])
def test_a_tool_that_hears_nothing_says_where_to_look(tool: str, tmp_path: Path) -> None:
    # A loopback mesh no service is on: the note says that a stack started with
    # `zenav up` is reached through its router, once, and the tool keeps going.
    done = run(zenav(*TOOLS[tool](tmp_path), "--base-port", str(free_port_block(7)),
                     "--duration", "4"), timeout=HANG)
    assert done.returncode == 0, done.stderr
    notes = [line for line in done.stderr.splitlines() if "nothing heard" in line]
    assert notes == [f"zenav {tool}: nothing heard from robot0 in 3 s on the loopback mesh, "
                     "where `zenav run` puts its services; a stack started with `zenav up` "
                     "is reached through its router: --connect tcp/127.0.0.1:7447 (its "
                     "default)"], done.stderr


@pytest.mark.parametrize("tool", ["monitor", "record"])
def test_a_duration_over_before_the_router_answers_says_so(tool: str, tmp_path: Path) -> None:
    done = run(zenav(*TOOLS[tool](tmp_path), "--connect", nobody(), "--connect-timeout", "30",
                     "--duration", "1"), timeout=HANG)
    assert done.returncode == 0, done.stderr
    last = done.stderr.splitlines()[-1]
    assert last.startswith(f"zenav {tool}: stopped before the session opened; nothing "), last
    assert not (tmp_path / "out.mcap").exists()


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_replay_waiting_for_a_service_says_so_and_stops_at_once_on_a_signal(
        signum: signal.Signals, tmp_path: Path,
        measure: Callable[[str, float, str], None]) -> None:
    proc = subprocess.Popen(zenav("replay", str(a_bag(tmp_path)), "--wait-for", "planner",
                                  "--timeout", "120", "--mode", "peer", "--connect", nobody()),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            stdin=subprocess.DEVNULL)
    try:
        lines = _stderr_lines(proc)
        first = lines.get(timeout=HANG)
        assert first == "zenav replay: waiting for planner on robot robot0 (up to 120 s)"
        sent = time.monotonic()
        proc.send_signal(signum)
        code = proc.wait(timeout=10)
        took = time.monotonic() - sent
        assert proc.stdout is not None
        said = proc.stdout.read()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    measure(f"replay stops on {signum.name} while waiting for a service", took, "")
    assert code == 128 + signum
    assert took < 3.0, f"replay took {took:.2f} s to stop"
    assert said.startswith("zenav replay: 0 messages in "), said
    assert said.rstrip().endswith("; stopped by a signal"), said


def test_replay_to_a_dead_peer_publishes_and_ends(tmp_path: Path) -> None:
    done = run(zenav("replay", str(a_bag(tmp_path)), "--rate", "10", "--mode", "peer",
                     "--connect", nobody()), timeout=HANG)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("zenav replay: 3 messages in "), done.stdout


def _stderr_lines(proc: subprocess.Popen[str]) -> queue.Queue[str]:
    lines: queue.Queue[str] = queue.Queue()

    def read() -> None:
        assert proc.stderr is not None
        for line in proc.stderr:
            lines.put(line.rstrip("\n"))

    threading.Thread(target=read, daemon=True).start()
    return lines


@pytest.mark.parametrize(("tool", "signum"), [
    ("monitor", signal.SIGINT), ("monitor", signal.SIGTERM), ("record", signal.SIGINT),
    ("replay", signal.SIGTERM), ("foxglove", signal.SIGINT), ("rviz", signal.SIGTERM)])
def test_a_tool_waiting_for_its_router_stops_at_once_on_a_signal(
        tool: str, signum: signal.Signals, tmp_path: Path,
        measure: Callable[[str, float, str], None]) -> None:
    endpoint = nobody()
    proc = subprocess.Popen(zenav(*TOOLS[tool](tmp_path), "--connect", endpoint,
                                  "--connect-timeout", "120"),
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                            stdin=subprocess.DEVNULL)
    try:
        lines = _stderr_lines(proc)
        first = lines.get(timeout=HANG)
        assert first == f"zenav {tool}: waiting for the router at {endpoint} (up to 120 s)"
        sent = time.monotonic()
        proc.send_signal(signum)
        code = proc.wait(timeout=10)
        took = time.monotonic() - sent
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    measure(f"{tool} stops on {signum.name} while connecting", took, "")
    assert code == 128 + signum  # 130 for SIGINT, as a shell expects
    assert took < 1.0, f"{tool} took {took:.2f} s to stop"
    assert not (tmp_path / "out.mcap").exists()


def test_up_says_which_services_it_still_waits_on_when_the_router_is_missing(
        tmp_path: Path) -> None:
    config = copy_deployment(REPO / "deploy" / "server.yaml", tmp_path / "server.yaml",
                             scenario=str(SCENARIO))
    endpoint = nobody()
    stack = Deployed(config, tmp_path / "run")
    try:
        done = run(zenav("up", "--config", str(config), "--run-dir", str(stack.run_dir),
                         "--connect", endpoint, "--timeout", "8"), timeout=HANG)
        lines = done.stderr.splitlines()
        assert done.returncode == 2, done.stderr
        assert len(lines) == 1, done.stderr
        assert lines[0].startswith(
            "zenav up: running, but still waiting on perception, planner, tracking on the "
            f"bus after 8 s without another arriving (is the router at {endpoint} "
            "reachable?)"), lines
    finally:
        stack.cleanup()


def test_up_reports_a_program_that_exits_at_start_with_its_own_line(tmp_path: Path) -> None:
    failing = ("import sys; print('zenav laser: cannot open /dev/ttyUSB9', file=sys.stderr); "
               "sys.exit(1)")
    endpoint = nobody()
    config = copy_deployment(
        REPO / "deploy" / "stack.yaml", tmp_path / "stack.yaml", scenario=str(SCENARIO),
        router={"listen": [endpoint]}, transport={"mode": "client", "connect": [endpoint]},
        services={"laser": {"service": "laser_driver",
                            "command": ["{python}", "-c", failing]}})
    stack = Deployed(config, tmp_path / "run")
    started = time.monotonic()
    try:
        done = run(zenav("up", "--config", str(config), "--run-dir", str(stack.run_dir),
                         "--timeout", "60"), timeout=HANG)
        took = time.monotonic() - started
        assert done.returncode == 2, done.stderr
        lines = done.stderr.splitlines()
        assert len(lines) == 1, done.stderr
        assert lines[0].startswith("zenav up: could not start laser: laser "), lines
        assert lines[0].endswith(": zenav laser: cannot open /dev/ttyUSB9; stopped what it "
                                 "had started"), lines
        assert took < 45, f"{took:.1f} s to report it"
        # Nothing it started is left: the other programs would run without the laser.
        assert Supervisor(stack.run_dir).pid() is None
    finally:
        stack.cleanup()
    starts = (stack.run_dir / "logs" / "laser.log").read_text().count("cannot open")
    assert 1 <= starts <= 4  # supervisord gave up after a few tries (startretries 3)
