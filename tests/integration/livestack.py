"""Helpers for the tests of long-running stacks: deployments under supervisord
(``zenav up``/``zenav down``), a ``zenav monitor --jsonl`` process read live, a pair of
network namespaces joined by a veth pair, and children started to be sent Ctrl-C."""

from __future__ import annotations

import contextlib
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

import pytest
import yaml

from zenav.deploy.rpc import Supervisor

REPO = Path(__file__).resolve().parents[2]
DATA = Path(__file__).resolve().parent / "data"

OFFBOARD_SCENARIO = DATA / "offpath.yaml"
"""The scenario of the off-board and partition tests. Switch to
``REPO / "sim" / "scenarios" / "mixed-case.yaml"`` once the planner avoids obstacles."""

LONG_SCENARIO = DATA / "long.yaml"
"""A longer run for the tests that stop services on the way."""

Event = dict[str, Any]


@contextlib.contextmanager
def sigint_as_usual() -> Iterator[None]:
    """Children started inside get Ctrl-C as at a terminal. A test run launched as a
    background job of a shell script inherits SIGINT ignored, its children too, and
    Python then keeps it ignored, so the Ctrl-C under test would do nothing. A signal
    this process handles is back to its default in a child (exec), so it handles
    SIGINT meanwhile."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        if previous is not None:
            signal.signal(signal.SIGINT, previous)


def zenav(*args: str) -> list[str]:
    return [sys.executable, "-m", "zenav", *args]


def run(command: list[str], timeout: float = 60) -> subprocess.CompletedProcess[str]:
    return subprocess.run(command, capture_output=True, text=True, timeout=timeout, check=False)


def copy_deployment(source: Path, target: Path, **changes: Any) -> Path:
    """A shipped deployment file, copied with its parameter files made absolute and the
    top-level fields in ``changes`` replaced (``router``, ``transport``, ``services``...)."""
    data = yaml.safe_load(source.read_text())
    for spec in data["services"].values():
        spec["config"] = [str((source.parent / p).resolve()) for p in spec.get("config", [])]
    data.update(changes)
    if "scenario" in data:
        data["scenario"] = str(Path(data["scenario"]).resolve())
    target.write_text(yaml.safe_dump(data, sort_keys=False))
    return target


@dataclass
class Deployed:
    """A deployment brought up by ``zenav up`` (optionally inside a network namespace)."""

    config: Path
    run_dir: Path
    prefix: list[str] = field(default_factory=list)  # e.g. ip netns exec NS
    up_args: list[str] = field(default_factory=list)
    is_up: bool = False

    @property
    def supervisor(self) -> Supervisor:
        return Supervisor(self.run_dir)

    def up(self, timeout: float = 240) -> subprocess.CompletedProcess[str]:
        done = run([*self.prefix, *zenav("up", "--config", str(self.config), "--run-dir",
                                         str(self.run_dir), *self.up_args)], timeout=timeout + 10)
        self.is_up = self.supervisor.pid() is not None
        assert done.returncode == 0, f"zenav up failed: {done.stderr}{self.logs_tail()}"
        return done

    def down(self) -> subprocess.CompletedProcess[str]:
        done = run(zenav("down", "--run-dir", str(self.run_dir)), timeout=60)
        self.is_up = False
        return done

    def ctl(self, *args: str) -> subprocess.CompletedProcess[str]:
        return run(zenav("ctl", "--run-dir", str(self.run_dir), *args))

    def pids(self) -> dict[str, int]:
        return {name: info["pid"] for name, info in self.supervisor.processes().items()}

    def logs_tail(self, lines: int = 5) -> str:
        out = []
        for log in sorted((self.run_dir / "logs").glob("*.log")):
            text = log.read_text(errors="replace").splitlines()[-lines:]
            out.append(f"\n--- {log.name}\n" + "\n".join(text))
        return "".join(out)

    def cleanup(self) -> None:
        """Stop it whatever happened; if supervisord does not answer, kill it and every
        program it had started."""
        if self.supervisor.pid() is None:
            return
        programs: list[int] = []
        with contextlib.suppress(Exception):
            programs = [pid for pid in self.pids().values() if pid]
        with contextlib.suppress(Exception):
            self.down()
        pid = self.supervisor.pid()
        if pid is None:
            return  # stopped: its programs are gone, and their pids may be reused already
        # supervisord still holds its children (not reaped), so these pids are still theirs.
        for leftover in [*programs, pid]:
            with contextlib.suppress(ProcessLookupError):
                os.kill(leftover, 9)


class Monitor:
    """A ``zenav monitor --jsonl`` process; its events and snapshots, read on a thread."""

    def __init__(self, command: list[str], log: Path) -> None:
        self._log: IO[str] = log.open("w")
        self._lines: IO[str] = log.with_suffix(".jsonl").open("w")  # for a post-mortem
        self.proc = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=self._log,
                                     text=True, stdin=subprocess.DEVNULL)
        self.events: list[Event] = []
        self.snapshot: Event | None = None
        self._obstacles: dict[int, Event] = {}
        self._changed = threading.Condition()
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self._lines.write(line)
            item = json.loads(line)
            with self._changed:
                if item["event"] == "snapshot":
                    self.snapshot = item
                    for obstacle in item["obstacles"]:
                        self._obstacles[obstacle["id"]] = obstacle
                else:
                    self.events.append(item)
                self._changed.notify_all()

    def seen_obstacles(self) -> list[Event]:
        """Every track the monitor showed, as last shown."""
        with self._changed:
            return list(self._obstacles.values())

    def wait(self, what: str, found: Callable[[], Any], timeout: float) -> Any:
        """Until ``found()`` (called under the lock) returns something truthy."""
        deadline = time.monotonic() + timeout
        with self._changed:
            while not (result := found()):
                left = deadline - time.monotonic()
                if left <= 0 or self.proc.poll() is not None:
                    last = json.dumps(self.snapshot)[:1500] if self.snapshot else "none"
                    raise AssertionError(f"timed out after {timeout:.0f} s waiting for {what}; "
                                         f"last snapshot: {last}")
                self._changed.wait(min(left, 0.5))
            return result

    def event(self, kind: str, timeout: float, after: float = 0.0, **match: Any) -> Event:
        """The first event of ``kind`` at or after wall time ``after`` whose fields match."""
        def find() -> Event | None:
            for e in self.events:
                if e["event"] == kind and e["wall"] >= after and \
                        all(e.get(k) == v for k, v in match.items()):
                    return e
            return None

        result: Event = self.wait(f"{kind} {match} after {after:.3f}", find, timeout)
        return result

    def state(self, what: str, predicate: Callable[[Event], bool], timeout: float) -> Event:
        """The first snapshot (from now on) for which ``predicate`` holds."""
        def find() -> Event | None:
            snap = self.snapshot
            return snap if snap is not None and predicate(snap) else None

        result: Event = self.wait(what, find, timeout)
        return result

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self._reader.join(timeout=5)
        self._log.close()
        self._lines.close()


def monitor_command(connect: str, prefix: list[str] | None = None) -> list[str]:
    return [*(prefix or []), *zenav("monitor", "--connect", connect, "--jsonl",
                                     "--period", "0.1", "--silence", "0.15")]


def moving_at(x_min: float) -> Callable[[Event], bool]:
    """A snapshot predicate: the robot (ground truth) moves and is past ``x_min``."""
    def check(snap: Event) -> bool:
        truth = snap.get("truth")
        return bool(truth and truth["v"] > 0.05 and truth["x"] >= x_min)
    return check


def reached(snap: Event) -> bool:
    return bool(snap.get("result") and snap["result"]["outcome"] is not None)


# --- network namespaces ----------------------------------------------------------------


def _ip(*args: str) -> None:
    done = run(["ip", *args], timeout=10)
    if done.returncode != 0:
        raise RuntimeError(f"ip {' '.join(args)}: {done.stderr.strip()}")


@dataclass
class NetnsPair:
    """Two network namespaces, robot and server, joined by a veth pair on a /30."""

    robot: str
    server: str
    robot_if: str
    server_if: str
    robot_ip: str
    server_ip: str

    def exec(self, namespace: str) -> list[str]:
        return ["ip", "netns", "exec", namespace]

    def link_down(self) -> None:
        _ip("-n", self.robot, "link", "set", self.robot_if, "down")
        _ip("-n", self.server, "link", "set", self.server_if, "down")

    def link_up(self) -> None:
        _ip("-n", self.robot, "link", "set", self.robot_if, "up")
        _ip("-n", self.server, "link", "set", self.server_if, "up")


def _kill_namespace_processes(namespace: str) -> None:
    done = run(["ip", "netns", "pids", namespace], timeout=10)
    for pid in done.stdout.split():
        with contextlib.suppress(ProcessLookupError, ValueError):
            os.kill(int(pid), 9)


@contextlib.contextmanager
def netns_pair() -> Iterator[NetnsPair]:
    """Create the namespaces (unique names, a random 10.213.x.y/30 inside them only) and
    delete them, and every process left in them, whatever happens."""
    if os.geteuid() != 0:
        pytest.skip(f"needs root to create network namespaces (ip netns); uid {os.geteuid()}")
    if shutil.which("ip") is None:
        pytest.skip("needs the `ip` command (iproute2) to create network namespaces")
    tag = f"{os.getpid() % 100000:05d}{random.randrange(16**3):03x}"
    third, block = random.randrange(256), 4 * random.randrange(64)
    pair = NetnsPair(robot=f"zr{tag}", server=f"zs{tag}", robot_if=f"vr{tag}",
                     server_if=f"vs{tag}", robot_ip=f"10.213.{third}.{block + 1}",
                     server_ip=f"10.213.{third}.{block + 2}")
    created: list[str] = []
    try:
        for namespace in (pair.robot, pair.server):
            _ip("netns", "add", namespace)
            created.append(namespace)
        _ip("link", "add", pair.robot_if, "type", "veth", "peer", "name", pair.server_if)
        _ip("link", "set", pair.robot_if, "netns", pair.robot)
        _ip("link", "set", pair.server_if, "netns", pair.server)
        for namespace, iface, address in ((pair.robot, pair.robot_if, pair.robot_ip),
                                          (pair.server, pair.server_if, pair.server_ip)):
            _ip("-n", namespace, "addr", "add", f"{address}/30", "dev", iface)
            _ip("-n", namespace, "link", "set", "lo", "up")
            _ip("-n", namespace, "link", "set", iface, "up")
        yield pair
    finally:
        for namespace in created:
            _kill_namespace_processes(namespace)
        for namespace in created:
            with contextlib.suppress(RuntimeError):
                _ip("netns", "del", namespace)
        with contextlib.suppress(RuntimeError):  # only if it never moved into a namespace
            if run(["ip", "link", "show", pair.robot_if]).returncode == 0:
                _ip("link", "del", pair.robot_if)
