"""Fuzz the running stack: malformed messages on every subscribed key during a scenario.

The scenario must still complete with no collision, no service may die or restart, and
every malformed message must be counted by the services it reached (rejected, or
dropped by a newest-wins buffer before it was even decoded).

CI sends ``ZENAV_FUZZ_PER_KEY`` messages per key (default 1,500, ~30 s); the issue's bar
of 10,000 per key is::

    ZENAV_FUZZ_PER_KEY=10000 .venv/bin/pytest tests/integration/test_fuzz_stack.py -s
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import os
import queue
import subprocess
import sys
import threading
import time
from collections import Counter
from pathlib import Path
from typing import IO, Any

from tests.integration.fuzz_inject import FUZZED, SUBSCRIBERS, Generator, must_be_refused
from zenav.launch import Stack
from zenav.schemas import keys
from zenav.schemas.codec import DecodeError, decode
from zenav.schemas.keys import Keys
from zenav.schemas.messages import RunResult, ServiceStatus
from zenav.services.mission import stack_params
from zenav.services.transport import ZenohBus
from zenav.sim.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[2]
PER_KEY = int(os.environ.get("ZENAV_FUZZ_PER_KEY", "1500"))
RATE = max(3000, PER_KEY * 7 // 10)  # payloads per second: all sent in about 10 s
SCENARIO = ROOT / "sim" / "scenarios" / "b-static-obstacle.yaml"


def test_every_generated_payload_is_malformed() -> None:
    gen = Generator(seed=1)
    by_stamp_only = {"past", "future", "beam_count"}
    for topic in FUZZED:
        for kind in Generator.KINDS:
            for _ in range(20):
                payload = gen.make(topic, kind)
                assert must_be_refused(topic, payload) or kind in by_stamp_only, (topic, kind)


async def _watch(stack: Stack, fuzz_out: Path, timeout: float) -> dict[str, object]:
    k = Keys(stack.robot_id)
    bus = ZenohBus(stack.transport(driver=True), asyncio.get_running_loop())
    losses: Counter[str] = Counter()
    alive: set[str] = set()
    statuses: dict[str, ServiceStatus] = {}
    try:
        def on_alive(key: str, up: bool) -> None:
            service = key.rsplit("/", 1)[-1]
            if up:
                alive.add(service)
            elif service in alive and service in stack.services:
                losses[service] += 1
                alive.discard(service)

        bus.watch_liveliness(k.alive_any, on_alive)
        status_sub = bus.subscribe(k.status_any, depth=10_000)
        results = bus.subscribe(k.of(keys.RESULT), depth=1)
        deadline = time.monotonic() + timeout
        # The simulation waits for this test's "run" token, and this test for every
        # service and for the injector's publishers: the first tick is fuzzed.
        while not set(stack.services) | {"fuzz"} <= alive:
            assert time.monotonic() < deadline, f"stack or fuzz injector not up: {alive}"
            assert stack.failure() is None, stack.failure()
            await asyncio.sleep(0.05)
        token = bus.declare_token(k.alive("run"))
        result: RunResult | None = None
        while result is None or not fuzz_out.exists():
            assert time.monotonic() < deadline, "no result in time"
            assert stack.failure() is None, stack.failure()
            with contextlib.suppress(TimeoutError):
                _, payload = await asyncio.wait_for(results.get(), timeout=0.2)
                with contextlib.suppress(DecodeError):
                    result = decode(payload, RunResult, "r", keys.RESULT.max_bytes)
        # Every service reports its counters once a second. On a loaded machine a service
        # may still be working through the fuzz queued for it when the injector is done:
        # wait (at most COUNT_WAIT s) until its counters cover what it was sent.
        expected = _expected(json.loads(fuzz_out.read_text()))
        settle = time.monotonic() + COUNT_WAIT
        while True:
            await asyncio.sleep(1.2)
            while status_sub.pending():
                _, payload = await status_sub.get()
                status = decode(payload, ServiceStatus)
                statuses[status.service] = status
            if time.monotonic() > settle or all(
                    service in statuses and _counted(statuses[service]) >= want
                    for service, want in expected.items()):
                break
        token.undeclare()
        return {"result": result, "losses": losses, "statuses": statuses}
    finally:
        bus.close()


COUNT_WAIT = 30.0
"""s after the fuzz ends for the services' counters to cover every message sent."""


def _expected(report: dict[str, Any]) -> Counter[str]:
    """Per service, how many fuzz messages reached it (the injector's report)."""
    expected: Counter[str] = Counter()
    for topic, count in report["sent"].items():
        for service in SUBSCRIBERS[topic]:
            expected[service] += count
    return expected


def _counted(status: ServiceStatus) -> int:
    """Inputs a service refused or dropped undecoded (newest-wins buffers)."""
    return sum(status.rejected.values()) + sum(status.dropped.values())


def _first_line(stream: IO[str], timeout: float) -> str:
    """The first line of ``stream``, or what came before EOF, waiting at most ``timeout`` s."""
    lines: queue.Queue[str] = queue.Queue()
    threading.Thread(target=lambda: lines.put(stream.readline()), daemon=True).start()
    try:
        return lines.get(timeout=timeout).strip()
    except queue.Empty:
        return f"(nothing in {timeout:.0f} s)"


def test_stack_survives_fuzz_on_every_key_during_a_scenario(tmp_path: Path) -> None:
    scenario = load_scenario(SCENARIO)
    params = stack_params(scenario, SCENARIO, "paper")
    stack = Stack(out_dir=tmp_path, params=params, log_level="INFO")
    fuzz_out = tmp_path / "fuzz.json"
    injector = subprocess.Popen(
        [sys.executable, "-m", "tests.integration.fuzz_inject", "--base-port",
         str(stack.base_port), "--per-key", str(PER_KEY), "--rate", str(RATE),
         "--after", "2.0", "--out", str(fuzz_out), "--wait-go"],
        cwd=ROOT, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
        text=True,
    )
    try:
        # Arm the fuzz before the stack starts: the lockstep scenario takes ~15 s of wall
        # time, less than the injector's imports and draws can on a loaded machine.
        assert injector.stdout is not None and injector.stdin is not None
        ready = _first_line(injector.stdout, timeout=120)
        assert ready == "ready", f"the fuzz injector did not arm: {ready!r}"
        stack.start()
        pids = {name: proc.pid for name, proc in stack.processes.items()}
        injector.stdin.write("go\n")
        injector.stdin.flush()
        seen = asyncio.run(_watch(stack, fuzz_out, timeout=60 + PER_KEY * len(FUZZED) / 1500))
        assert injector.wait(timeout=30) == 0, injector.stdout.read() if injector.stdout else ""
    finally:
        if injector.poll() is None:
            injector.kill()
            injector.wait()
        alive_at_end = {name: proc.poll() is None for name, proc in stack.processes.items()}
        stack.stop()
    report = json.loads(fuzz_out.read_text())
    result = seen["result"]
    assert isinstance(result, RunResult)
    # The fuzz must begin while the scenario runs. On a loaded machine it may go on past
    # the end (odom then stops at the result's time): the scenario ran under fuzz
    # throughout, and the services, still up, count the rest.
    assert report["sim_started"] < result.time, "the fuzz must run while the scenario does"
    # no service died or restarted: same processes, liveliness never lost
    assert all(alive_at_end.values()), alive_at_end
    assert {name: proc.pid for name, proc in stack.processes.items()} == pids
    assert not seen["losses"], seen["losses"]
    # every malformed message was counted by every service it reached
    statuses = seen["statuses"]
    assert isinstance(statuses, dict)
    assert all(count == PER_KEY for count in report["sent"].values()), report["sent"]
    expected = _expected(report)
    lines = []
    for service, want in sorted(expected.items()):
        status = statuses[service]
        rejected = sum(status.rejected.values())
        dropped = sum(status.dropped.values())
        lines.append(f"{service}: sent {want}, rejected {rejected} {dict(status.rejected)}, "
                     f"dropped {dropped}, handler errors {status.handler_errors}")
    for service, want in sorted(expected.items()):
        status = statuses[service]
        rejected = sum(status.rejected.values())
        assert status.handler_errors == 0, lines
        # a dropped input was never decoded: it may have been fuzz or a genuine message
        assert want <= _counted(status), lines
        assert rejected <= want + 50, lines  # genuine refusals (e.g. late commands)
    print("\n".join(lines))
    assert result.outcome == "reached", (result.outcome, lines)
    print(f"fuzz: {sum(report['sent'].values())} messages in {report['seconds']:.1f} s "
          f"(sim t={report['sim_started']:.1f}..{report['sim_ended']:.1f} of {result.time:.1f})")
