"""``zenav bench perf``, floor: what the hops between the services cost on this machine
with no work in them.

The latency and lockstep sections time the stack's processes, each hop between two of
them plus each service's receive, decode, compute and encode. This section runs the
same processes' transport with nothing else: relays on the stack's loopback mesh (the
same ports and peer links as ``zenav run``'s services), each taking its input as a
service does (``ZenohBus.subscribe``: Zenoh's thread buffers the sample, newest wins,
and wakes the asyncio loop, which hands it on) and putting the bytes unchanged on its
output with the services' publisher settings. What a section measures above its floor
is the services' own work.

- **chain**: the latency section's path at the laser's 10 Hz, laser driver → perception
  → tracking → planner → motor bridge, five processes. The bench stamps the scan and the
  base command in Zenoh's callback as the latency section does (both seen one hop away),
  so the interval holds the same four hops.
- **direct**: the chain again, each relay putting from Zenoh's callback itself, with no
  asyncio loop: the difference is what the loop's hand-off costs a hop.
- **ring**: the lockstep tick, simulator → laser driver → perception → tracking →
  planner → motor bridge → simulator, six processes. The simulator's stand-in sends the
  next tick as soon as the last is answered, as the lockstep simulator does; the figure
  is the ticks per second, and what that is in real time at 10 Hz.

A relay process is ``python -m zenav.bench.floor ROLE MODE BASE_PORT SECONDS``; it ends
by itself ``SECONDS`` plus :data:`LINK_TIMEOUT` after it starts, should the bench that
started it die first.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import math
import statistics
import struct
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import zenoh

from zenav.bench.common import fmt, percentile
from zenav.launch import free_port_block, release_port_block
from zenav.services.config import loopback_mesh
from zenav.services.transport import Publisher, ZenohBus

KEY = "zenav-floor/{}"
RATE_HZ = 10.0  # the laser's rate in the latency section, and the tick the ring counts in
SETTLE = 1.0  # s after the first pass through every hop before measuring (links settle)
LINK_TIMEOUT = 20.0  # s for the processes to start and link up
PAYLOAD = 200  # bytes forwarded (a scan is 1.6 KB, a command 100 B: size barely counts)

CHAIN: dict[str, tuple[str | None, str]] = {
    "laser_driver": (None, "scan"),
    "perception": ("scan", "obstacles"),
    "tracking": ("obstacles", "tracks"),
    "planner": ("tracks", "cmd_vel"),
    "motor_bridge": ("cmd_vel", "base_cmd"),
}
"""Each process of the chain: (input topic, output topic); the laser driver has no input."""
RING: dict[str, tuple[str | None, str]] = {"simulator": ("base_cmd", "raw"),
                                           "laser_driver": ("raw", "scan"),
                                           **{k: v for k, v in CHAIN.items() if v[0]}}
"""Each process of the ring: (input topic, output topic)."""
MODES = {"chain": CHAIN, "direct": CHAIN, "ring": RING}
"""The layouts: ``direct`` is the chain with each relay putting from Zenoh's callback
itself, with no asyncio loop (what the loop's hand-off costs a hop)."""


class FloorError(RuntimeError):
    """The relays did not start or link up in time (the message says which)."""


@dataclass
class RingResult:
    ticks: int
    wall: float  # s over which they were counted

    @property
    def per_tick_ms(self) -> float:
        return self.wall / self.ticks * 1e3 if self.ticks else math.nan

    @property
    def real_time(self) -> float:
        """Simulated s per wall s at one tick per :data:`RATE_HZ` period."""
        return self.ticks / RATE_HZ / self.wall if self.wall > 0 else math.nan


def chain_intervals(scans: dict[int, float], commands: dict[int, float],
                    settle: float = SETTLE) -> list[float]:
    """ms from each scan's receive time to its base command's, for the scans received
    ``settle`` s or more after the first that came out at the end of the chain (the
    links are up by then); scans whose command was dropped are left out."""
    done = [s for s in scans if s in commands]
    if not done:
        return []
    start = scans[min(done)] + settle
    return [(commands[s] - scans[s]) * 1e3 for s in sorted(done) if scans[s] >= start]


# -- the relay processes -----------------------------------------------------------------

def _seq_payload(seq: int) -> bytes:
    return struct.pack("<q", seq) + bytes(PAYLOAD - 8)


async def _scans(out: Publisher, seconds: float) -> None:
    """The chain's laser driver: a numbered payload every 1 / RATE_HZ s."""
    seq = 0
    loop = asyncio.get_running_loop()
    start = loop.time()
    while loop.time() - start < seconds + LINK_TIMEOUT:
        out.put(_seq_payload(seq))
        seq += 1
        await asyncio.sleep(start + seq / RATE_HZ - loop.time())


async def _ticks(out: Publisher, answered: asyncio.Event, seconds: float) -> dict[str, Any]:
    """The ring's simulator: a tick, then the next as soon as it is answered (again after
    1 s if the answer was lost, as the lockstep simulator resends). Probes every 0.2 s
    until the first answer, settles for :data:`SETTLE` s, then counts for ``seconds``."""
    loop = asyncio.get_running_loop()
    deadline = loop.time() + LINK_TIMEOUT
    payload = _seq_payload(0)

    async def tick(wait: float) -> bool:
        answered.clear()
        out.put(payload)
        try:
            async with asyncio.timeout(wait):
                await answered.wait()
        except TimeoutError:
            return False
        return True

    while not await tick(0.2):
        if loop.time() > deadline:
            return {"error": f"the ring did not answer within {LINK_TIMEOUT:g} s"}
    settled = loop.time() + SETTLE
    while loop.time() < settled:
        await tick(1.0)
    ticks, start = 0, loop.time()
    while loop.time() - start < seconds:
        ticks += await tick(1.0)
    return {"ticks": ticks, "wall": loop.time() - start}


async def _serve(role: str, mode: str, base_port: int, seconds: float) -> None:
    src, dst = MODES[mode][role]
    bus = ZenohBus(loopback_mesh(role, base_port), asyncio.get_running_loop())
    try:
        out = bus.publisher(KEY.format(dst))
        if src is None:
            await _scans(out, seconds)
        elif mode == "ring" and role == "simulator":
            answered = asyncio.Event()
            bus.subscribe(KEY.format(src)).consume(lambda _key, _payload: answered.set())
            print(json.dumps(await _ticks(out, answered, seconds)), flush=True)
        elif mode == "direct":
            bus.session.declare_subscriber(
                KEY.format(src), lambda sample: out.put(sample.payload.to_bytes()))
            await asyncio.sleep(seconds + LINK_TIMEOUT)  # until the bench stops it
        else:
            bus.subscribe(KEY.format(src)).consume(lambda _key, payload: out.put(payload))
            await asyncio.sleep(seconds + LINK_TIMEOUT)  # until the bench stops it
    finally:
        bus.close()


# -- the bench's side ---------------------------------------------------------------------

Processes = dict[str, "subprocess.Popen[str]"]


@contextlib.contextmanager
def _relays(mode: str, base_port: int, seconds: float) -> Iterator[Processes]:
    """The relay processes of ``mode``, stopped (then killed) on leaving."""
    roles = MODES[mode]
    procs: Processes = {}
    try:
        for role in roles:
            procs[role] = subprocess.Popen(
                [sys.executable, "-m", "zenav.bench.floor", role, mode, str(base_port),
                 f"{seconds:g}"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        yield procs
    finally:
        for p in procs.values():
            if p.poll() is None:
                p.terminate()
        for p in procs.values():
            try:
                p.communicate(timeout=5.0)
            except subprocess.TimeoutExpired:
                p.kill()
                p.communicate()


def _died(procs: Processes) -> str | None:
    for role, p in procs.items():
        if p.poll() is not None and p.returncode != 0:
            _, err = p.communicate()
            last = err.strip().splitlines()[-1] if err.strip() else "no message"
            return f"the {role} relay exited with status {p.returncode}: {last}"
    return None


def measure_chain(seconds: float, direct: bool = False) -> list[float]:
    """ms from the scan to the base command through the chain's four hops, one per scan
    over ``seconds`` s at :data:`RATE_HZ`; ``direct``: each relay forwards in Zenoh's
    callback, with no asyncio loop."""
    base = free_port_block()
    scans: dict[int, float] = {}
    commands: dict[int, float] = {}
    lock = threading.Lock()

    def stamper(into: dict[int, float]) -> Any:
        def on_sample(sample: Any) -> None:
            now = time.perf_counter()
            seq = struct.unpack_from("<q", sample.payload.to_bytes())[0]
            with lock:
                into[seq] = now
        return on_sample

    wanted = math.ceil(seconds * RATE_HZ)
    try:
        with zenoh.open(loopback_mesh(None, base, tool_listens=True).to_zenoh()) as session:
            subscribers: list[Any] = [
                session.declare_subscriber(KEY.format("scan"), stamper(scans)),
                session.declare_subscriber(KEY.format("base_cmd"), stamper(commands))]
            try:
                with _relays("direct" if direct else "chain", base, seconds) as procs:
                    limit = LINK_TIMEOUT + SETTLE + 2 * seconds
                    deadline = time.monotonic() + limit
                    while True:
                        with lock:
                            got = len(chain_intervals(dict(scans), dict(commands)))
                        if got >= wanted:
                            break
                        problem = _died(procs)
                        if problem is None and time.monotonic() > deadline:
                            problem = (f"{got} of {wanted} scans through the chain within "
                                       f"{limit:.0f} s")
                        if problem is not None:
                            raise FloorError(problem)
                        time.sleep(0.05)
            finally:
                for sub in subscribers:
                    sub.undeclare()
        with lock:
            return chain_intervals(scans, commands)[:wanted]
    finally:
        release_port_block(base)


def measure_ring(seconds: float) -> RingResult:
    """Ticks per second around the ring of six, counted for ``seconds`` s."""
    base = free_port_block()
    try:
        with _relays("ring", base, seconds) as procs:
            try:
                out, err = procs["simulator"].communicate(
                    timeout=LINK_TIMEOUT + SETTLE + seconds + 5.0)
            except subprocess.TimeoutExpired:
                raise FloorError(f"the ring's simulator did not report within "
                                 f"{LINK_TIMEOUT + SETTLE + seconds + 5.0:.0f} s") from None
            problem = _died(procs)
            lines = out.strip().splitlines()
            if problem is not None or not lines:
                raise FloorError(problem or f"the ring's simulator reported nothing: {err}")
            result = json.loads(lines[-1])
            if "error" in result:
                raise FloorError(result["error"])
            return RingResult(int(result["ticks"]), float(result["wall"]))
    finally:
        release_port_block(base)


def _left(ms: float) -> str:
    return f"{fmt(ms, 2)} ms" if not ms < 0.0 else "nothing, the hops alone take more"


def floor_table(chain_ms: list[float], direct_ms: list[float], ring: RingResult,
                latency_target_ms: float, lockstep_target: float) -> str:
    """The floors beside the targets they bound, and the chain without the loop."""
    med = statistics.median(chain_ms) if chain_ms else math.nan
    direct = statistics.median(direct_ms) if direct_ms else math.nan
    hops = len(CHAIN) - 1
    lines = [
        "| with no work in the services | measured | p99 | the target it bounds |",
        "|---|---|---|---|",
        f"| the scan's four hops at {RATE_HZ:g} Hz (laser driver's publish → motor bridge's "
        f"publish, seen one hop away), {len(chain_ms)} scans | {fmt(med, 2)} ms median | "
        f"{fmt(percentile(chain_ms, 99), 2)} ms | scan → base command, median ≤ "
        f"{latency_target_ms:g} ms |",
        f"| the same four hops, each relay putting from Zenoh's callback (no asyncio loop), "
        f"{len(direct_ms)} scans | {fmt(direct, 2)} ms median | "
        f"{fmt(percentile(direct_ms, 99), 2)} ms | – |",
        f"| the lockstep tick's six hops, back to back, {ring.ticks} ticks in "
        f"{ring.wall:.1f} s | {fmt(ring.per_tick_ms, 2)} ms a tick: "
        f"{fmt(ring.real_time, 1)}× real time at {RATE_HZ:g} Hz | – | lockstep loop ≥ "
        f"{lockstep_target:g}× |",
        "",
        f"Left for the four services' receive, decode, compute and encode within the "
        f"latency target: {_left(latency_target_ms - med)} of {latency_target_ms:g} ms "
        f"(median). Left for a lockstep tick's work (the simulator's tick and the six "
        f"services') at {lockstep_target:g}×, {fmt(1e3 / RATE_HZ / lockstep_target, 2)} ms a "
        f"tick: {_left(1e3 / RATE_HZ / lockstep_target - ring.per_tick_ms)}. The asyncio "
        f"loop's hand-off, as the services take their inputs: {fmt((med - direct) / hops, 2)} "
        f"ms a hop.",
    ]
    return "\n".join(lines)


def main(argv: list[str]) -> int:
    """A relay process: ``ROLE MODE BASE_PORT SECONDS``."""
    role, mode, base_port, seconds = argv
    if role not in MODES.get(mode, {}):
        print(f"zenav.bench.floor: no role {role!r} in the {mode!r}", file=sys.stderr)
        return 2
    with contextlib.suppress(KeyboardInterrupt):
        asyncio.run(_serve(role, mode, int(base_port), float(seconds)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
