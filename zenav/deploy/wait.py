"""Waiting for a deployment: until every program runs under supervisord, and until every
service's liveliness token is on the bus."""

from __future__ import annotations

import asyncio
import contextlib
import time
from collections.abc import Callable
from pathlib import Path

from zenav.deploy.conf import secured_transport
from zenav.deploy.model import Deployment
from zenav.deploy.rpc import Supervisor
from zenav.schemas.keys import Keys
from zenav.services.config import ConfigError
from zenav.services.transport import TransportConfig
from zenav.tooling import ConnectError, open_bus, stop_on_signals, with_connect_timeout

FAILED_STATES = ("FATAL", "BACKOFF", "EXITED")
"""supervisord states of a program that did not stay up: given up on, waiting to be
started again after an early exit, or exited."""


def _reason(log: Path) -> str:
    """The line of a program's log that says why it stopped: its last error line (a
    service prints its one-line reason on stderr, which goes to the same log), else its
    last line."""
    try:
        lines = [line.strip() for line in log.read_text(errors="replace").splitlines()
                 if line.strip()]
    except OSError:
        return "(no log)"
    for line in reversed(lines):
        if line.startswith("zenav ") or line.startswith(
                ("Traceback", "ModuleNotFoundError", "ImportError")):
            return line
        if " ERROR " in line:  # a log record: its text, without the time and level
            return line.split(" ERROR ", 1)[1]
    return lines[-1] if lines else "(empty log)"


def check_started(sup: Supervisor, programs: list[str]) -> None:
    """ConfigError naming each program that exited since it was started, with its own
    reason from its log (so a bad parameter is reported as such, not as a silent bus)."""
    infos = sup.processes()
    failed = [p for p in programs if infos.get(p, {}).get("statename") in FAILED_STATES]
    if failed:
        why = "; ".join(f"{p} {infos[p]['statename'].lower()}: "
                        f"{_reason(sup.run_dir / 'logs' / f'{p}.log')}" for p in failed)
        raise ConfigError(f"could not start {', '.join(failed)}: {why}")


def wait_running(sup: Supervisor, programs: list[str], timeout: float) -> None:
    """Until every program is RUNNING; one that exits or fails raises ConfigError. The
    ``timeout`` is for the next one: it starts again each time another runs."""
    deadline = time.monotonic() + timeout
    left_over = len(programs)
    while True:
        check_started(sup, programs)
        infos = sup.processes()
        waiting = [p for p in programs if infos.get(p, {}).get("statename") != "RUNNING"]
        if not waiting:
            return
        if len(waiting) < left_over:
            left_over, deadline = len(waiting), time.monotonic() + timeout
        if time.monotonic() > deadline:
            states = ", ".join(f"{p} {infos.get(p, {}).get('statename', '?')}" for p in waiting)
            raise ConfigError(f"not running after {timeout:.0f} s without another starting; "
                              f"still waiting on {states}")
        time.sleep(0.1)


def wait_alive(deployment: Deployment, services: set[str], timeout: float,
               check: Callable[[], None] = lambda: None) -> set[str]:
    """Services among ``services`` whose liveliness token is not on the bus after
    ``timeout`` s without another arriving (empty when all are): the wait starts again
    at each arrival. ``check`` is called every ``CHECK_EVERY`` s meanwhile and may raise
    (a program that exited)."""
    transport = deployment.transport
    if deployment.security is not None:  # zenav up watches with the monitor's certificate
        transport = secured_transport(deployment, "monitor")
    transport = with_connect_timeout(transport, timeout)
    return asyncio.run(_missing_tokens(transport, Keys(deployment.robot_id), services,
                                       timeout, check))


CHECK_EVERY = 0.25
"""s between two looks at the programs' states while waiting for their tokens."""


async def _missing_tokens(transport: TransportConfig, keys: Keys, services: set[str],
                          timeout: float, check: Callable[[], None]) -> set[str]:
    stop = asyncio.Event()
    stop_on_signals(stop)
    opening = asyncio.ensure_future(open_bus(transport, stop, timeout))
    try:
        while not opening.done():
            check()
            await asyncio.wait({opening}, timeout=CHECK_EVERY)
        bus = opening.result()
    except ConnectError:
        return set(services)
    finally:
        opening.cancel()
    if bus is None:  # SIGINT or SIGTERM
        raise KeyboardInterrupt
    missing = set(services)
    seen = asyncio.Event()

    def on_liveliness(key: str, alive: bool) -> None:
        if alive:
            missing.discard(key.rsplit("/", 1)[-1])
            seen.set()

    deadline = time.monotonic() + timeout
    left_over = len(missing)
    try:
        bus.watch_liveliness(keys.alive_any, on_liveliness)
        while missing and (left := deadline - time.monotonic()) > 0:
            if len(missing) < left_over:  # another one arrived: wait for the next afresh
                left_over, deadline = len(missing), time.monotonic() + timeout
                continue
            if stop.is_set():
                raise KeyboardInterrupt
            check()
            seen.clear()
            with contextlib.suppress(TimeoutError):
                await asyncio.wait_for(seen.wait(), timeout=min(left, CHECK_EVERY))
    finally:
        bus.close()
    return missing


def expected_alive(deployment: Deployment) -> set[str]:
    names = {deployment.service_of(p) for p, s in deployment.services.items() if s.autostart}
    if deployment.router is not None:
        names.add("router")
    return names

