"""Waiting for a deployment: until every program runs under supervisord, and until every
service's liveliness token is on the bus."""

from __future__ import annotations

import asyncio
import contextlib
import time
from pathlib import Path

from zenav.deploy.conf import secured_transport
from zenav.deploy.model import Deployment
from zenav.deploy.rpc import Supervisor
from zenav.schemas.keys import Keys
from zenav.services.config import ConfigError
from zenav.services.transport import TransportConfig, ZenohBus


def _tail(path: Path, lines: int = 3) -> str:
    try:
        text = path.read_text(errors="replace").splitlines()
    except OSError:
        return ""
    return " | ".join(line.strip() for line in text[-lines:] if line.strip())


def wait_running(sup: Supervisor, programs: list[str], timeout: float) -> None:
    """Until every program is RUNNING; a FATAL or BACKOFF-looping one raises ConfigError."""
    deadline = time.monotonic() + timeout
    while True:
        infos = sup.processes()
        fatal = [p for p in programs if infos.get(p, {}).get("statename") == "FATAL"]
        if fatal:
            why = "; ".join(f"{p}: {_tail(sup.run_dir / 'logs' / f'{p}.log')}" for p in fatal)
            raise ConfigError(f"could not start {', '.join(fatal)}: {why}")
        waiting = [p for p in programs if infos.get(p, {}).get("statename") != "RUNNING"]
        if not waiting:
            return
        if time.monotonic() > deadline:
            states = ", ".join(f"{p} {infos.get(p, {}).get('statename', '?')}" for p in waiting)
            raise ConfigError(f"not running after {timeout:.0f} s: {states}")
        time.sleep(0.1)


def wait_alive(deployment: Deployment, services: set[str], timeout: float) -> set[str]:
    """Services among ``services`` whose liveliness token is not on the bus after
    ``timeout`` s (empty when all are)."""
    transport = deployment.transport
    if deployment.security is not None:  # zenav up watches with the monitor's certificate
        transport = secured_transport(deployment, "monitor")
    if transport.mode == "client":
        extra = {**transport.extra, "connect/timeout_ms": int(timeout * 1000)}
        transport = transport.model_copy(update={"extra": extra})
    return asyncio.run(_missing_tokens(transport, Keys(deployment.robot_id), services,
                                       time.monotonic() + timeout))


async def _missing_tokens(transport: TransportConfig, keys: Keys, services: set[str],
                          deadline: float) -> set[str]:
    try:
        bus = ZenohBus(transport, asyncio.get_running_loop())
    except Exception:
        return set(services)
    missing = set(services)
    seen = asyncio.Event()

    def on_liveliness(key: str, alive: bool) -> None:
        if alive:
            missing.discard(key.rsplit("/", 1)[-1])
            seen.set()

    try:
        bus.watch_liveliness(keys.alive_any, on_liveliness)
        while missing and (left := deadline - time.monotonic()) > 0:
            seen.clear()
            with contextlib.suppress(TimeoutError):
                await asyncio.wait_for(seen.wait(), timeout=left)
    finally:
        bus.close()
    return missing


def expected_alive(deployment: Deployment) -> set[str]:
    names = {deployment.service_of(p) for p, s in deployment.services.items() if s.autostart}
    if deployment.router is not None:
        names.add("router")
    return names

