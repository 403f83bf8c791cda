"""Start a whole service stack as separate processes and watch over it.

Used by ``zenav run`` and by the integration tests. Each service is its own process
(``python -m zenav service NAME``) with its parameters in a YAML file and its output in
a log file of its own. A stack gets its own block of loopback ports, so two stacks on
one machine never hear each other.
"""

from __future__ import annotations

import fcntl
import os
import random
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from zenav.services.config import SERVICE_ORDER, loopback_mesh

PORT_LOCKS = Path(tempfile.gettempdir()) / "zenav-ports"
"""One lock file per loopback port a stack of this machine has reserved."""

_held: dict[int, list[int]] = {}  # base port -> open, locked lock files


def free_port_block(count: int = len(SERVICE_ORDER) + 1, attempts: int = 200) -> int:
    """A base port such that base..base+count-1 are free on loopback, reserved for this
    process until ``release_port_block`` or its exit.

    Chosen below the usual ephemeral range (32768+) so outgoing connections do not take
    them meanwhile. A free port is only free until someone binds it, and a stack's
    services bind theirs a second or so after the block is chosen: two stacks started
    at once could pick overlapping blocks, and one of them then fails with "address
    already in use". So each port is also locked (``flock`` on a file in
    ``PORT_LOCKS``) and a port another process holds is not chosen; the lock goes with
    the process that holds it, even if it is killed.
    """
    rng = random.Random(os.getpid() ^ time.monotonic_ns())
    for _ in range(attempts):
        base = rng.randrange(20000, 32000 - count)
        locks = _lock_ports(range(base, base + count))
        if locks is None:
            continue
        if loopback_ports_free(range(base, base + count)):
            _held[base] = locks
            return base
        _unlock(locks)
    raise RuntimeError("no free block of loopback ports found")


def release_port_block(base: int) -> None:
    """Let other stacks on this machine choose the block at ``base`` again."""
    _unlock(_held.pop(base, []))


def _lock_ports(ports: Iterable[int]) -> list[int] | None:
    """Locks on every one of ``ports``, or None (and no lock) if another process holds
    one. Where the lock directory cannot be used the reservation is skipped: the ports
    are then only checked free, as before."""
    locks: list[int] = []
    try:
        if not PORT_LOCKS.is_dir():
            PORT_LOCKS.mkdir(exist_ok=True)
            PORT_LOCKS.chmod(0o1777)  # shared by every user's stacks, like /tmp
        for port in ports:
            fd = os.open(PORT_LOCKS / str(port), os.O_RDONLY | os.O_CREAT, 0o644)
            locks.append(fd)
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        _unlock(locks)
        return None
    except OSError:
        _unlock(locks)
        return []
    return locks


def _unlock(locks: list[int]) -> None:
    for fd in locks:
        os.close(fd)  # closing the file drops its lock


def loopback_ports_free(ports: Iterable[int]) -> bool:
    """Whether every one of ``ports`` can be bound on 127.0.0.1 now (they are released
    again at once: another process may take one before the caller does)."""
    sockets = []
    try:
        for port in ports:
            s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
            sockets.append(s)
            s.bind(("127.0.0.1", port))
        return True
    except OSError:
        return False
    finally:
        for s in sockets:
            s.close()


def write_params(directory: Path, service: str, params: Mapping[str, Any]) -> Path:
    """A service's parameter overrides as the YAML file its process reads; kept with the
    run's output so the run can be repeated service by service."""
    directory.mkdir(parents=True, exist_ok=True)
    path = directory / f"{service}.yaml"
    path.write_text(yaml.safe_dump(dict(params), sort_keys=False))
    return path


def ended(code: int) -> str:
    """How a process ended, from its ``Popen.returncode``: a negative one is the signal
    that killed it ("was killed by signal 9 (SIGKILL)"), not a status it chose."""
    if code >= 0:
        return f"exited with status {code}"
    try:
        name = f" ({signal.Signals(-code).name})"
    except ValueError:
        name = ""
    return f"was killed by signal {-code}{name}"


def last_line(path: Path) -> str:
    try:
        lines = [line for line in path.read_text(errors="replace").splitlines() if line.strip()]
    except OSError:
        return ""
    return lines[-1].strip() if lines else ""


@dataclass
class Stack:
    """The service processes of one robot."""

    out_dir: Path
    params: Mapping[str, Mapping[str, Any]]
    robot_id: str = "robot0"
    base_port: int = field(default_factory=free_port_block)
    services: tuple[str, ...] = SERVICE_ORDER
    log_level: str = "INFO"
    planner: str = "paper"
    processes: dict[str, subprocess.Popen[bytes]] = field(default_factory=dict)

    def command(self, service: str) -> list[str]:
        params_file = write_params(self.out_dir / "params", service, self.params.get(service, {}))
        return [
            sys.executable, "-m", "zenav", "service", service,
            "--config", str(params_file),
            "--robot-id", self.robot_id,
            "--base-port", str(self.base_port),
            "--log-level", self.log_level,
            *(["--planner", self.planner] if service == "planner" else []),
        ]

    def log_path(self, service: str) -> Path:
        return self.out_dir / "logs" / f"{service}.log"

    def start(self) -> None:
        (self.out_dir / "logs").mkdir(parents=True, exist_ok=True)
        for service in self.services:
            self.start_service(service)

    def start_service(self, service: str) -> None:
        with self.log_path(service).open("ab") as log:
            self.processes[service] = subprocess.Popen(
                self.command(service), stdout=log, stderr=subprocess.STDOUT,
                stdin=subprocess.DEVNULL,
            )

    def transport(self, driver: bool = False) -> Any:
        """Transport settings for a tool process joining this stack; ``driver`` for the
        one tool that runs it (it also listens on the stack's tool port)."""
        return loopback_mesh(None, self.base_port, tool_listens=driver)

    def failure(self) -> str | None:
        """A one-line reason if a service has exited, else None."""
        for service, proc in self.processes.items():
            code = proc.poll()
            if code is not None:
                why = last_line(self.log_path(service))
                return f"service {service} {ended(code)}" + (f": {why}" if why else "")
        return None

    def stop(self, grace: float = 3.0) -> dict[str, int]:
        """SIGTERM every service, SIGKILL what is left after ``grace`` s; exit codes."""
        for proc in self.processes.values():
            if proc.poll() is None:
                proc.send_signal(signal.SIGTERM)
        deadline = time.monotonic() + grace
        codes = {}
        for service, proc in self.processes.items():
            try:
                codes[service] = proc.wait(timeout=max(0.0, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                proc.kill()
                codes[service] = proc.wait()
        release_port_block(self.base_port)
        return codes
