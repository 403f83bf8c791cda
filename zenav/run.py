"""``zenav run SCENARIO --out DIR``: one scenario through the whole service stack.

It starts the six service processes on their own loopback ports, joins them as a
read-only tool, collects the planner's events and the simulator's result, stops every
process and writes ``run.json`` and ``run.png``. A service that fails to start or dies
ends the command with a one-line reason and a non-zero status, never a hang.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import math
import os
import signal
import threading
import time
from collections.abc import Awaitable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from types import FrameType
from typing import Any, TypeVar

from zenav.engine import PATHS_KEPT, add_path
from zenav.launch import Stack
from zenav.schemas import keys
from zenav.schemas.codec import DecodeError, decode
from zenav.schemas.keys import Keys
from zenav.schemas.messages import GlobalPath, OccupancyMap, Odometry, PlannerEvent, RunResult
from zenav.services.config import (
    SERVICE_ORDER,
    ConfigError,
    Layer,
    parse_assignment,
    resolve,
)
from zenav.services.mission import stack_params
from zenav.services.profiles import DEFAULT_PROFILE, apply_profile
from zenav.services.ros2.params import ROBOT_FACES, with_ros2_robot
from zenav.services.runner import PLANNERS, service_params
from zenav.services.transport import Latest, Subscription, ZenohBus
from zenav.services.writable import check_output_dir
from zenav.sim.scenario import load_scenario

T = TypeVar("T")


class RunError(RuntimeError):
    """The run could not be made; the message is the one-line reason."""


def apply_override(params: dict[str, dict[str, Any]], text: str) -> None:
    """Apply ``SERVICE.NAME=VALUE`` (NAME may be dotted) to the per-service parameters."""
    path, value = parse_assignment(text)
    if len(path) < 2 or path[0] not in SERVICE_ORDER:
        raise ConfigError(f"--set {text!r}: expected SERVICE.NAME=VALUE with SERVICE one of "
                          f"{', '.join(SERVICE_ORDER)}")
    target = params.setdefault(path[0], {})
    for part in path[1:-1]:
        target = target.setdefault(part, {})
    target[path[-1]] = value


def check_overrides(params: dict[str, dict[str, Any]], overrides: list[str], planner: str,
                    source: str) -> None:
    """Validate each service's parameters with the ``--set`` overrides applied, before any
    process starts: ConfigError with one line per problem, naming the flag that caused it
    (not the parameter file the run would write from it)."""
    by_service: dict[str, list[Layer]] = {}
    for text in overrides:
        path, value = parse_assignment(text)
        if len(path) < 2 or path[0] not in SERVICE_ORDER:
            raise ConfigError(f"--set {text!r}: expected SERVICE.NAME=VALUE with SERVICE one "
                              f"of {', '.join(SERVICE_ORDER)}")
        nested: dict[str, Any] = {path[-1]: value}
        for part in reversed(path[1:-1]):
            nested = {part: nested}
        by_service.setdefault(path[0], []).append(Layer("--set", f"--set {text}", nested))
    problems = []
    for service, layers in by_service.items():
        base = Layer("scenario", source, params.get(service, {}))
        try:
            resolve(service_params(service, planner), [base, *layers])
        except ConfigError as exc:
            problems.append(str(exc))
    if problems:
        raise ConfigError("\n".join(problems))


RUN_OUTPUTS = ("run.json", "run.png", "run.mcap", "params/*.yaml", "logs/*.log")
"""What a run writes into its ``--out`` folder (patterns under it)."""


def clear_previous_run(out_dir: Path) -> list[Path]:
    """Remove what an earlier run left in ``out_dir`` (:data:`RUN_OUTPUTS`), so that the
    folder never mixes two runs' record, recording, parameters and logs; other files are
    left alone. The paths removed."""
    removed = [path for pattern in RUN_OUTPUTS for path in sorted(out_dir.glob(pattern))
               if path.is_file()]
    for path in removed:
        path.unlink()
    return removed


def _finite_or_none(value: float) -> float | None:
    return None if math.isinf(value) or math.isnan(value) else round(value, 6)


def make_record(result: RunResult, events: list[PlannerEvent], planner: str) -> dict[str, Any]:
    """The run record of the spec (``run.json``), from the simulator's result."""
    trajectory = [[round(float(v), 6) for v in row] for row in result.trajectory]
    record: dict[str, Any] = {
        "scenario": result.scenario,
        "planner": planner,
        "outcome": result.outcome,
        "time": round(result.time, 6),
        "path_length": round(result.path_length, 6),
        "min_clearance": _finite_or_none(result.min_clearance),
        "collided_with": result.collided_with,
        "trajectory": trajectory,
        "events": [
            {"t": round(e.stamp, 6), "obstacle": e.obstacle, "kind": e.kind,
             "scenario": e.scenario, "action": e.action, "detail": e.detail}
            for e in sorted(events, key=lambda e: (e.stamp, e.seq))
            if e.stamp <= result.time + 1e-9
        ],
    }
    if result.agents:  # the spec's optional field: only for scenarios with agents
        record["agents"] = {
            str(a.index): [[round(float(v), 6) for v in row] for row in a.rows]
            for a in result.agents
        }
    return record


@dataclass
class Heard:
    """The newest global path and map the planner published (the paper planner does;
    the baselines publish neither)."""

    path: GlobalPath | None = None
    occupancy: OccupancyMap | None = None
    paths: list[GlobalPath] = field(default_factory=list)  # each distinct path, oldest first


async def _collect(stack: Stack, progress_timeout: float, record: Path | None = None,
                   heard: Heard | None = None, stop: threading.Event | None = None
                   ) -> tuple[RunResult, list[PlannerEvent]]:
    """Join the stack, gather events until the simulator's result arrives (and the
    newest path and map into ``heard``); with ``record``, write every message of the run
    there as MCAP (zenav's msgpack channels and the Foxglove ones). ``stop`` set (Ctrl-C,
    or a batch being stopped) ends it within a tenth of a second with KeyboardInterrupt."""
    heard = heard if heard is not None else Heard()
    stop = stop if stop is not None else threading.Event()

    def check() -> None:
        if stop.is_set():
            raise KeyboardInterrupt
        failure = stack.failure()
        if failure:
            # a service stopped by the same Ctrl-C is not a failure of the run
            if stop.is_set():
                raise KeyboardInterrupt
            raise RunError(failure)

    k = Keys(stack.robot_id)
    bus = ZenohBus(stack.transport(driver=True), asyncio.get_running_loop())
    recording = _Recording(bus, record, stack.robot_id) if record is not None else None
    try:
        # Announce this run (the simulator waits for it) only once every service is
        # seen from here: peers relay nothing, so each must be linked to this process.
        alive: set[str] = set()
        everyone = asyncio.Event()

        def on_alive(key: str, up: bool) -> None:
            service = key.rsplit("/", 1)[-1]
            if up:
                alive.add(service)
            else:
                alive.discard(service)
            if set(stack.services) <= alive:
                everyone.set()

        bus.watch_liveliness(k.alive_any, on_alive)
        # The wait is for the next service: it starts again at each arrival, so a slow
        # but steady start on a busy machine is not a failure.
        deadline = time.monotonic() + progress_timeout
        arrived = 0
        while not everyone.is_set():
            check()
            if len(alive) > arrived:
                arrived, deadline = len(alive), time.monotonic() + progress_timeout
            if time.monotonic() > deadline:
                missing = ", ".join(sorted(set(stack.services) - alive))
                raise RunError(f"services not reachable after {progress_timeout:.0f} s without "
                               f"another arriving; still waiting on {missing}")
            with contextlib.suppress(TimeoutError):
                await asyncio.wait_for(everyone.wait(), timeout=0.1)
        # Subscribed before the run is announced: the first events come at once, and
        # the history query alone can miss them when it times out on a loaded machine.
        results = bus.subscribe(k.of(keys.RESULT), depth=1)
        events_sub = bus.subscribe(k.of(keys.EVENTS), depth=100_000)
        # Odometry (every tick) and the map are only looked at between two checks: Zenoh
        # keeps the newest of each, and this process is not woken for them. Paths are
        # rare and each one is kept.
        odom = bus.latest(k.of(keys.ODOM))
        paths = bus.subscribe(k.of(keys.PATH), depth=PATHS_KEPT)
        maps = bus.latest(k.of(keys.MAP))
        token = bus.declare_token(k.alive("run"))
        events: list[PlannerEvent] = []
        last_progress = time.monotonic()
        sim_time = -1.0
        result: RunResult | None = None
        while result is None:
            check()
            try:
                _, payload = await asyncio.wait_for(results.get(), timeout=0.1)
                result = decode(payload, RunResult, k.of(keys.RESULT), keys.RESULT.max_bytes)
            except (TimeoutError, DecodeError):
                pass
            await _take_paths_and_map(k, paths, maps, heard)
            newest = odom.take()
            if newest is not None:
                try:
                    stamp = decode(newest[1], Odometry, k.of(keys.ODOM)).stamp
                except DecodeError:
                    stamp = -math.inf  # not ours to judge; the services count it
                # a stamp from nowhere (an hour ahead) does not prove progress
                if sim_time < stamp <= sim_time + 3600:
                    sim_time, last_progress = stamp, time.monotonic()
            if time.monotonic() - last_progress > progress_timeout:
                where = "before the first tick" if sim_time < 0 else f"at t={sim_time:.2f} s"
                raise RunError(f"the simulation made no progress for {progress_timeout:.0f} s "
                                f"{where}; see the logs in {stack.out_dir / 'logs'}")
        await _take_paths_and_map(k, paths, maps, heard)  # those sent before the result
        # The planner keeps every event it made; asking for them all does not depend on
        # this process having been subscribed before the first one.
        check()
        history = await _unless_stopped(bus.query(k.of(keys.EVENT_HISTORY), timeout=5.0),
                                        stop)
        payloads = [payload for _, payload in history]
        while events_sub.pending():
            payloads.append((await events_sub.get())[1])
        seen: set[int] = set()
        for payload in payloads:
            try:
                event = decode(payload, PlannerEvent, k.of(keys.EVENTS))
            except DecodeError:
                continue
            if event.seq not in seen:
                seen.add(event.seq)
                events.append(event)
        token.undeclare()
        return result, events
    finally:
        if recording is not None:
            recording.close()
        bus.close()


async def _unless_stopped(work: Awaitable[T], stop: threading.Event) -> T:
    """``work``'s result, or KeyboardInterrupt within a tenth of a second of ``stop``
    being set. The event history query waits up to 5 s for a planner that a Ctrl-C of
    the same batch may be stopping: ``zenav paper`` took 5 s to stop on a loaded
    machine."""
    task = asyncio.ensure_future(work)
    try:
        while True:
            done, _ = await asyncio.wait({task}, timeout=0.1)
            if done:
                return task.result()
            if stop.is_set():
                raise KeyboardInterrupt
    finally:
        task.cancel()


async def _take_paths_and_map(k: Keys, paths: Subscription, maps: Latest,
                              heard: Heard) -> None:
    """The paths and the newest map that came since the last look, into ``heard``: each
    distinct path once (the planner repeats an unchanged one every ``path_period``)."""
    while paths.pending():
        with contextlib.suppress(DecodeError):
            heard.path = decode((await paths.get())[1], GlobalPath, k.of(keys.PATH),
                                keys.PATH.max_bytes)
            add_path(heard.paths, heard.path)
    occupancy = maps.take()
    if occupancy is not None:
        with contextlib.suppress(DecodeError):
            heard.occupancy = decode(occupancy[1], OccupancyMap, k.of(keys.MAP),
                                     keys.MAP.max_bytes)


class _Recording:
    """Every message of the run into an MCAP file, subscribed before the run starts."""

    def __init__(self, bus: ZenohBus, path: Path, robot_id: str) -> None:
        from zenav.bag.mcapfile import BagWriter
        from zenav.tooling import StampedSubscriber

        self.stream = path.open("wb")
        self.writer = BagWriter(self.stream, robot_id, foxglove=True)
        self.subscriber = StampedSubscriber(bus, self.writer.keys.everything, self.writer.add)

    def close(self) -> None:
        self.subscriber.close()
        self.writer.close()
        self.stream.close()


STOP_GRACE_INTERRUPTED = 1.5
"""Wall s a service stopped by Ctrl-C has to end before it is killed (the command is to
end within 3 s of it)."""


@contextlib.contextmanager
def sigint_held() -> Iterator[None]:
    """In the main thread: a SIGINT during the block is held until the block ends, then
    raised as KeyboardInterrupt. Matplotlib's renderer calls back into Python, and an
    interrupt raised in there comes out as another error (``ValueError: Invalid bounding
    box``), a traceback and status 1 instead of the quiet 130. Elsewhere nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    held: list[int] = []

    def on_sigint(signum: int, frame: FrameType | None) -> None:
        held.append(signum)

    previous = signal.signal(signal.SIGINT, on_sigint)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
    if held:
        raise KeyboardInterrupt


@contextlib.contextmanager
def _interrupt_sets(stop: threading.Event) -> Iterator[None]:
    """In the main thread: SIGINT or SIGTERM sets ``stop`` and raises KeyboardInterrupt
    (once; a second signal while the stack stops is ignored, so the stop is not cut
    short). After a SIGTERM (``timeout``, a supervisor, a CI job) the command then ends
    by that signal's default action, status 143 to a shell, once the block has stopped
    the services: without this, SIGTERM killed the command at once and left the six
    services running. Elsewhere (a batch's worker thread) nothing: the batch sets
    ``stop`` itself."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    received: list[int] = []

    def on_signal(signum: int, frame: FrameType | None) -> None:
        if not stop.is_set():
            received.append(signum)
            stop.set()
            raise KeyboardInterrupt

    previous = {sig: signal.signal(sig, on_signal) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        if signal.SIGTERM in received:
            signal.signal(signal.SIGTERM, signal.SIG_DFL)
            os.kill(os.getpid(), signal.SIGTERM)


def run_scenario(
    scenario_path: Path,
    out_dir: Path,
    planner: str = "paper",
    overrides: list[str] | None = None,
    progress_timeout: float = 90.0,
    log_level: str = "INFO",
    picture: bool = True,
    robot_face: str = "native",
    mcap: bool = False,
    profile: str = DEFAULT_PROFILE,
    engine: str = "stack",
    stop: threading.Event | None = None,
) -> dict[str, Any]:
    """Run one scenario; write run.json and run.png; the record.

    ``engine``: ``stack`` (the default and the acceptance path) runs the six service
    processes over Zenoh; ``inprocess`` runs the same services in this process on an
    in-memory bus (:mod:`zenav.engine`), with the same record.
    ``robot_face="ros2"`` (stack only): the simulated robot is a ROS 2 robot over
    rmw_zenoh, reached through the ros2 backends of the laser driver and motor bridge.
    ``mcap`` (stack only): also ``run.mcap``, every message of the run, openable in
    Foxglove.
    ``profile``: the named set of parameter overrides (``zenav.services.profiles``) laid
    over the defaults, under the scenario's values and ``overrides``.
    ``stop`` (stack only): set from another thread, the run ends within a tenth of a
    second, its processes stopped, with KeyboardInterrupt; in the main thread Ctrl-C
    sets it (the services stopped by the same Ctrl-C are then not a failure)."""
    scenario = load_scenario(scenario_path)  # raises ScenarioError naming file and field
    if planner not in PLANNERS:
        raise ConfigError(f"--planner {planner!r}: no such planner; choose from "
                          f"{', '.join(PLANNERS)}")
    if engine not in ("stack", "inprocess"):
        raise ConfigError(f"--engine {engine!r}: choose one of stack, inprocess")
    if engine == "inprocess" and (robot_face != "native" or mcap):
        raise ConfigError("--engine inprocess runs the native robot without recording; "
                          "--robot ros2 and --record need --engine stack")
    params = stack_params(scenario, scenario_path, planner)
    apply_profile(params, profile, planner)  # raises ConfigError for an unknown profile
    if robot_face not in ROBOT_FACES:
        raise ConfigError(f"--robot {robot_face!r}: choose one of {', '.join(ROBOT_FACES)}")
    if robot_face == "ros2":
        params = with_ros2_robot(params)
    check_overrides(params, overrides or [], planner, f"scenario {scenario_path}")
    for text in overrides or []:
        apply_override(params, text)
    check_output_dir(out_dir)  # made only now, the input known good (PathError if it cannot)
    clear_previous_run(out_dir)
    started = time.monotonic()
    codes: dict[str, int] = {}
    heard = Heard()
    if engine == "inprocess":
        from zenav.engine import EngineError, run_services

        try:
            ran = run_services(params, planner, log_path=out_dir / "logs" / "engine.log",
                               log_level=log_level)
        except (EngineError, ConfigError) as exc:
            raise RunError(str(exc)) from None
        result, events = ran.result, ran.events
        heard.path, heard.occupancy, heard.paths = ran.path, ran.occupancy, ran.paths
    else:
        stop = stop if stop is not None else threading.Event()
        stack = Stack(out_dir=out_dir, params=params, log_level=log_level, planner=planner)
        with _interrupt_sets(stop):
            try:
                stack.start()
                result, events = asyncio.run(_collect(
                    stack, progress_timeout, out_dir / "run.mcap" if mcap else None, heard,
                    stop))
            finally:  # stopped however the run ended: no service outlives it
                codes = stack.stop(grace=STOP_GRACE_INTERRUPTED if stop.is_set() else 3.0)
    record = make_record(result, events, planner)
    record["wall_time"] = round(time.monotonic() - started, 3)
    record["seed"] = scenario.seed
    if profile != DEFAULT_PROFILE:
        record["profile"] = profile
    if heard.path is not None:  # optional field: the last global path, [[x, y], ...]
        record["path"] = [[round(float(x), 4), round(float(y), 4)]
                          for x, y in heard.path.points]
    if engine != "stack":
        record["engine"] = engine
    unclean = {name: code for name, code in codes.items() if code != 0}
    if unclean:
        record["unclean_exits"] = unclean
    (out_dir / "run.json").write_text(json.dumps(record, indent=1))
    if picture:
        from zenav.plot import plot_run  # matplotlib is slow to import; only here

        with sigint_held():  # about half a second of drawing; Ctrl-C then stops it
            plot_run(scenario, record, out_dir / "run.png", occupancy=heard.occupancy,
                     paths=heard.paths)
    return record
