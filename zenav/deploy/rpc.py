"""Talking to a deployment's supervisord: its XML-RPC interface over the run directory's
Unix socket, ``supervisorctl``, and what its log says about how programs stopped."""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
import time
import xmlrpc.client
from pathlib import Path
from typing import Any

from zenav.deploy.conf import socket_path


class Supervisor:
    """supervisord's XML-RPC interface over the run directory's Unix socket."""

    def __init__(self, run_dir: Path) -> None:
        self.run_dir = run_dir.resolve()
        self.conf = self.run_dir / "supervisord.conf"

    def proxy(self) -> Any:
        from supervisor.xmlrpc import SupervisorTransport

        url = f"unix://{socket_path(self.run_dir)}"
        return xmlrpc.client.ServerProxy(
            "http://127.0.0.1", transport=SupervisorTransport(None, None, url))

    def pid(self) -> int | None:
        """supervisord's pid if it is running."""
        try:
            pid = int((self.run_dir / "supervisord.pid").read_text().strip())
        except (OSError, ValueError):
            return None
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return None
        except PermissionError:
            return pid
        return pid

    def ready(self) -> bool:
        try:
            return bool(self.proxy().supervisor.getState()["statename"] == "RUNNING")
        except (OSError, xmlrpc.client.Fault, xmlrpc.client.ProtocolError):
            return False

    def processes(self) -> dict[str, dict[str, Any]]:
        """Program name -> supervisord's process info (statename, pid, exitstatus, ...)."""
        return {info["name"]: info for info in self.proxy().supervisor.getAllProcessInfo()}

    def start(self, program: str) -> None:
        self.proxy().supervisor.startProcess(program, True)

    def stop(self, program: str) -> None:
        self.proxy().supervisor.stopProcess(program, True)

    def stop_in_order(self, timeout: float = 60.0) -> list[str]:
        """Stop every program that runs, highest priority number first (the planner before
        the motor bridge, the router last), each rank fully before the next; their names.
        The programs of one rank stop together: a service and its warm spare (one SIGTERM
        each), so that the spare does not take over from the one stopping."""
        proxy = self.proxy()
        priority = {c["name"]: c["process_prio"] for c in proxy.supervisor.getAllConfigInfo()}
        infos = self.processes()
        stopped: list[str] = []
        for rank in sorted({priority.get(p, 0) for p in infos}, reverse=True):
            group = [p for p in sorted(infos) if priority.get(p, 0) == rank
                     and infos[p]["statename"] in ("RUNNING", "STARTING", "BACKOFF")]
            for program in group:
                with contextlib.suppress(xmlrpc.client.Fault):  # it stopped meanwhile
                    proxy.supervisor.stopProcess(program, False)
            deadline = time.monotonic() + timeout
            while group and time.monotonic() < deadline and any(
                    info["statename"] in ("RUNNING", "STARTING", "BACKOFF", "STOPPING")
                    for name, info in self.processes().items() if name in group):
                time.sleep(0.02)
            stopped += group
        return stopped

    def ctl(self, args: list[str]) -> int:
        return subprocess.call([sys.executable, "-m", "supervisor.supervisorctl",
                                "-c", str(self.conf), *args])



def unclean_stops(log: Path, offset: int) -> list[str]:
    """Programs whose stop, as supervisord logged it after ``offset``, was not clean: a
    clean one exited with status 0, or was ended by the SIGTERM itself (a program still
    waiting for the router has no handler yet, and nothing to clean up)."""
    try:
        with log.open("rb") as stream:
            stream.seek(offset)
            lines = stream.read().decode(errors="replace").splitlines()
    except OSError:
        return []
    unclean = []
    for line in lines:
        if "stopped: " not in line:
            continue
        program, _, how = line.split("stopped: ", 1)[1].partition(" ")
        if how.strip() not in ("(exit status 0)", "(terminated by SIGTERM)"):
            unclean.append(f"{program} {how.strip()}")
    return unclean

