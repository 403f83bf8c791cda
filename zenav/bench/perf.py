"""``zenav bench perf``: compute per scan, latency over Zenoh, lockstep speed, sustained
scan rate and memory of the service stack.

Five measurements, each printed as a Markdown table with the issue's target beside the
measured figure (targets are reported, never asserted):

- **compute**: the pure cores timed in one process on simulated 361-beam scans with 0,
  5 and 20 obstacles in view, the robot standing, one box on its path and half the
  others moving (clustering = ``Perceiver.process``, tracking = ``Tracker.update`` and
  the track messages, collision prediction and Morphin inside ``Planner.step``, and the
  baselines' steps on the same scans);
- **latency**: a real stack over Zenoh in real time; a tool process takes the wall time
  (in Zenoh's callback, one clock) at which it receives the scan stamped *s* (the laser
  driver's publish) and the base command stamped *s* (the motor bridge's publish right
  after it received the velocity command): the interval is the laser driver's publish to
  the motor bridge's publish, both seen one hop away;
- **lockstep**: ``zenav run`` on the eight paper scenarios, simulated seconds per wall
  second of the simulator's loop (from its log) and of the whole command;
- **rate**: the real-time simulator with the laser rate raised; the highest rate at which
  no service drops an input (the ``status/<service>`` counters) and every scan gets its
  base command;
- **memory**: resident set size of each service process (psutil), during the latency run.
"""

from __future__ import annotations

import contextlib
import json
import math
import re
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path
from typing import Any

import msgpack
import numpy as np
import psutil
import yaml

from zenav.launch import Stack
from zenav.run import stack_params
from zenav.schemas import keys
from zenav.schemas.keys import Keys
from zenav.schemas.messages import Pose2D, RawLaserFrame, TrackList
from zenav.services.config import loopback_mesh
from zenav.sim import SCENARIO_DIR
from zenav.sim.scenario import Scenario, load_scenario, parse_scenario

SCENARIOS = SCENARIO_DIR
PAPER_SCENARIOS = tuple(sorted(SCENARIOS.glob("[a-h]-*.yaml")))

TARGET_PIPELINE_MEDIAN_US = 500.0  # whole pipeline, 5 obstacles in view
NAV2_ANCHOR_MS = 4.45  # Nav2's collision monitor per 360-point scan
TARGET_LATENCY_MEDIAN_MS = 2.0
TARGET_LATENCY_P99_MS = 5.0
TARGET_LOCKSTEP_FACTOR = 50.0
TARGET_RATE_HZ = 200.0


def percentile(values: list[float], q: float) -> float:
    return float(np.percentile(np.asarray(values, dtype=np.float64), q)) if values else math.nan


def verdict(ok: bool) -> str:
    return "met" if ok else "NOT met"


def fmt(value: float, digits: int = 0) -> str:
    return "—" if math.isnan(value) else f"{value:.{digits}f}"


# --- compute per scan ---------------------------------------------------------------


def perf_scenario(count: int, seed: int = 0) -> Scenario:
    """A world with ``count`` obstacles 1.0–3.6 m in front of the robot (inside the
    perception window): a box on its path 2 m ahead, then every other one moving slowly
    across the view."""
    rng = np.random.default_rng([count, seed])
    robot = np.array([3.0, 10.0])
    obstacles: list[dict[str, Any]] = []
    centres: list[np.ndarray] = []
    if count:
        centres.append(robot + np.array([2.0, 0.0]))
        obstacles.append({"shape": "box", "center": centres[0].tolist(), "size": [0.5, 0.5]})
    for _ in range(5000):
        if len(obstacles) == count:
            break
        r, a = rng.uniform(1.0, 3.6), rng.uniform(-1.35, 1.35)
        c = robot + r * np.array([math.cos(a), math.sin(a)])
        if any(float(np.hypot(*(c - o))) < 0.75 for o in centres):
            continue
        centres.append(c)
        centre = [round(float(c[0]), 3), round(float(c[1]), 3)]
        if len(obstacles) % 2:
            speed = rng.uniform(0.05, 0.2)
            direction = a + math.pi / 2 * rng.choice([-1.0, 1.0])
            obstacles.append({"shape": "disc", "center": centre,
                              "radius": round(float(rng.uniform(0.15, 0.25)), 2),
                              "velocity": [round(speed * math.cos(direction), 3),
                                           round(speed * math.sin(direction), 3)]})
        elif rng.random() < 0.5:
            obstacles.append({"shape": "disc", "center": centre,
                              "radius": round(float(rng.uniform(0.15, 0.3)), 2)})
        else:
            obstacles.append({"shape": "box", "center": centre,
                              "size": [round(float(rng.uniform(0.3, 0.5)), 2)] * 2})
    if len(obstacles) < count:
        raise RuntimeError(f"could not place {count} obstacles in view")
    data = {"name": f"perf-{count}", "world": {"size": [22.0, 20.0], "cell": 0.5},
            "robot": {"start": robot.tolist(), "heading_deg": 0.0, "goal": [19.0, 10.0],
                      "speed": 0.1, "radius": 0.2},
            "laser": {"noise_std": 0.01}, "obstacles": obstacles, "duration": 1000, "seed": seed}
    return parse_scenario(data, f"<perf-{count}>")


class _Stopwatch:
    """Wraps methods of an object so that the time spent in them adds up per label."""

    def __init__(self, target: object, methods: dict[str, str]) -> None:
        self.spent: dict[str, float] = dict.fromkeys(methods.values(), 0.0)
        self.calls: dict[str, int] = dict.fromkeys(methods.values(), 0)
        self.missing = [name for name in methods if not hasattr(target, name)]
        for name, label in methods.items():
            if hasattr(target, name):
                setattr(target, name, self._wrap(getattr(target, name), label))

    def _wrap(self, method: Callable[..., Any], label: str) -> Callable[..., Any]:
        def timed(*args: Any, **kwargs: Any) -> Any:
            start = time.perf_counter()
            try:
                return method(*args, **kwargs)
            finally:
                self.spent[label] += time.perf_counter() - start
                self.calls[label] += 1

        return timed

    def reset(self) -> None:
        for label in self.spent:
            self.spent[label] = 0.0


PLANNER_PARTS = {"_assess_all": "prediction", "safe_speed": "prediction",
                 "plan_detour": "morphin"}
"""Planner methods timed as collision prediction and as Morphin."""

STAGES = ("clustering", "tracking", "prediction", "morphin", "planner", "pipeline")
BASELINES = ("vfh", "dwa", "apf")


@dataclass
class ComputeResult:
    obstacles: int
    scans: int
    clusters: float  # mean per scan
    tracks: float
    morphin_calls: int
    micros: dict[str, list[float]] = field(default_factory=dict)


def time_compute(count: int, scans: int = 200, warmup: int = 10,
                 seed: int = 0) -> ComputeResult:
    """Each stage's compute per scan, µs, on ``scans`` scans of a world with ``count``
    obstacles in view. The robot stands (so that what is in view stays in view) while the
    planner plans as if it drove; every other obstacle moves at 0.05–0.2 m/s."""
    from zenav.services.baselines import apf, dwa, vfh
    from zenav.services.baselines.common import Cycle
    from zenav.services.baselines.node import movers_of
    from zenav.services.laser_driver.node import Params as DriverParams
    from zenav.services.laser_driver.node import frame_to_scan
    from zenav.services.perception.params import PerceptionParams
    from zenav.services.perception.perceive import Perceiver
    from zenav.services.planner.decide import Planner
    from zenav.services.planner.node import obstacles_of
    from zenav.services.planner.params import Params as PlannerParams
    from zenav.services.tracking.node import track_message
    from zenav.services.tracking.params import TrackingParams
    from zenav.services.tracking.tracker import Tracker
    from zenav.sim.node import Params as SimParams
    from zenav.sim.node import Simulation

    scenario = perf_scenario(count, seed)
    params = stack_params(scenario, Path("perf.yaml"), "paper")
    sim = Simulation(scenario, SimParams.model_validate(params["simulator"]))
    driver = DriverParams.model_validate(params["laser_driver"])
    perceiver = Perceiver(PerceptionParams.model_validate(params["perception"]))
    tracker = Tracker(TrackingParams.model_validate(params["tracking"]))
    planner = Planner(PlannerParams.model_validate(params["planner"]))
    watch = _Stopwatch(planner, PLANNER_PARTS)
    # A second planner on the same inputs whose detour is dropped before every scan, so
    # that it plans one whenever a threat asks for it: Morphin's cost per call.
    shadow = Planner(PlannerParams.model_validate(params["planner"]))
    shadow_watch = _Stopwatch(shadow, {"plan_detour": "morphin"})
    baselines: dict[str, vfh.VFH | dwa.DWA | apf.APF] = {
        "vfh": vfh.VFH(vfh.Params.model_validate(params["planner"])),
        "dwa": dwa.DWA(dwa.Params.model_validate(params["planner"])),
        "apf": apf.APF(apf.Params.model_validate(params["planner"])),
    }
    result = ComputeResult(count, 0, 0.0, 0.0, 0,
                           {k: [] for k in (*STAGES, "morphin_call", *BASELINES)})
    n_clusters = n_tracks = 0
    for i in range(warmup + scans):
        if sim.outcome is not None:
            break
        t = sim.t
        frame = RawLaserFrame(stamp=t, seq=i, ranges=sim.scan())
        scan = frame_to_scan(frame, driver, i)
        s = sim.state
        pose = (s.x, s.y, s.heading)
        watch.reset()
        t0 = time.perf_counter()
        clusters = perceiver.process(scan, pose)
        t1 = time.perf_counter()
        tracks = [track_message(tr) for tr in tracker.update(t, pose, clusters)]
        t2 = time.perf_counter()
        track_list = TrackList(stamp=t, seq=i, pose=Pose2D(x=s.x, y=s.y, heading=s.heading),
                               tracks=tracks)
        obstacles = obstacles_of(track_list)
        t3 = time.perf_counter()
        planner.step(pose, obstacles, t)
        t4 = time.perf_counter()
        if hasattr(shadow, "detour"):
            shadow.detour = None
        shadow_watch.reset()
        shadow_watch.calls["morphin"] = 0
        shadow.step(pose, obstacles, t)
        movers, remembered = movers_of(track_list, 0.03)
        cycle = Cycle(ranges=scan.ranges.astype(np.float64), angles=scan.angles(),
                      range_max=scan.range_max, pose=pose, velocity=(s.v, s.omega),
                      goal=scenario.robot.goal, movers=movers, remembered=remembered)
        spent: dict[str, float] = {}
        for name, baseline in baselines.items():
            b0 = time.perf_counter()
            baseline.step(cycle)
            spent[name] = time.perf_counter() - b0
        if i >= warmup:
            us = 1e6
            row = {"clustering": t1 - t0, "tracking": t2 - t1,
                   "prediction": watch.spent["prediction"], "morphin": watch.spent["morphin"],
                   "planner": t4 - t3, "pipeline": (t2 - t0) + (t4 - t3), **spent}
            for key, value in row.items():
                result.micros[key].append(value * us)
            result.scans += 1
            n_clusters += len(clusters.beams) if hasattr(clusters, "beams") else 0
            n_tracks += len(tracks)
            result.morphin_calls += watch.calls["morphin"] > 0
            if shadow_watch.calls["morphin"]:
                result.micros["morphin_call"].append(
                    shadow_watch.spent["morphin"] / shadow_watch.calls["morphin"] * us)
        watch.calls["morphin"] = 0
        for _ in range(sim.ticks_per_scan):
            if sim.outcome is None:
                sim.step(0.0, 0.0)
    result.clusters = n_clusters / max(result.scans, 1)
    result.tracks = n_tracks / max(result.scans, 1)
    return result


def compute_table(results: list[ComputeResult]) -> str:
    head = "| stage, µs per scan | " + " | ".join(
        f"{r.obstacles} obstacles: median / p99" for r in results) + " |"
    rule = "|---|" + "---|" * len(results)
    names = {"clustering": "clustering (perception)", "tracking": "tracking",
             "prediction": "collision prediction", "morphin": "Morphin",
             "morphin_call": "Morphin, per detour planned (shadow planner, see below)",
             "planner": "planner step (all of it)", "pipeline": "**whole pipeline**",
             "vfh": "VFH step (baseline)", "dwa": "DWA step (baseline)",
             "apf": "APF step (baseline)"}
    lines = [head, rule]
    for key in (*STAGES[:4], "morphin_call", *STAGES[4:], *BASELINES):
        cells = []
        for r in results:
            values = r.micros[key]
            cells.append(f"{fmt(statistics.median(values) if values else math.nan)} / "
                         f"{fmt(percentile(values, 99))}")
        lines.append(f"| {names[key]} | " + " | ".join(cells) + " |")
    lines.append("| scans timed; clusters, tracks per scan; scans with Morphin; detours "
                 "planned by the shadow | " + " | ".join(
                     f"{r.scans}; {r.clusters:.1f}, {r.tracks:.1f}; {r.morphin_calls}; "
                     f"{len(r.micros['morphin_call'])}" for r in results) + " |")
    lines.append("")
    lines.append("Stages are timed inside the pipeline as the services run it; Morphin runs "
                 "only on the scans where a detour is (re)planned. The shadow is a second "
                 "paper planner on the same inputs whose detour is dropped before each scan, "
                 "so that it plans one on every scan with a threat: the cost of one Morphin "
                 "planning. Pipeline = clustering + tracking + planner step.")
    five = next((r for r in results if r.obstacles == 5), None)
    if five is not None and five.micros["pipeline"]:
        median = statistics.median(five.micros["pipeline"])
        verdict = "met" if median <= TARGET_PIPELINE_MEDIAN_US else "NOT met"
        lines.append("")
        lines.append(f"Target: whole pipeline ≤ {TARGET_PIPELINE_MEDIAN_US:.0f} µs median with "
                     f"5 obstacles — measured {median:.0f} µs ({verdict}). Anchor: Nav2's "
                     f"collision monitor, {NAV2_ANCHOR_MS} ms per 360-point scan "
                     f"({NAV2_ANCHOR_MS * 1000 / median:.1f}× the measured pipeline).")
    return "\n".join(lines)


# --- a live stack and a tool that listens to it --------------------------------------


class Listener:
    """A Zenoh session of the bench's own that notes the wall receive time (in Zenoh's
    callback) of every scan and base command, and keeps the latest status per service."""

    def __init__(self, stack: Stack) -> None:
        import zenoh

        self.k = Keys(stack.robot_id)
        conf = loopback_mesh(None, stack.base_port, tool_listens=True).to_zenoh()
        self.session: Any = zenoh.open(conf)
        self.lock = threading.Lock()
        self.scans: dict[float, float] = {}
        self.commands: dict[float, float] = {}
        self.base: dict[float, float] = {}
        self.status: dict[str, dict[str, Any]] = {}
        self.alive: set[str] = set()
        self.handles: list[Any] = []
        self.token = self.session.liveliness().declare_token(self.k.alive("bench"))
        for topic, into in ((keys.SCAN, self.scans), (keys.CMD_VEL, self.commands),
                            (keys.BASE_CMD, self.base)):
            self.handles.append(self.session.declare_subscriber(
                self.k.of(topic), self._stamped(into, topic.name == "device/base_cmd")))
        self.handles.append(self.session.declare_subscriber(self.k.status_any, self._status))
        self.handles.append(self.session.liveliness().declare_subscriber(
            self.k.alive_any, self._liveliness, history=True))

    def _stamped(self, into: dict[float, float], commands_only: bool) -> Callable[[Any], None]:
        def on_sample(sample: Any) -> None:
            now = time.perf_counter()
            data = msgpack.unpackb(sample.payload.to_bytes())
            if commands_only and data.get("reason", "command") != "command":
                return
            with self.lock:
                into.setdefault(float(data["stamp"]), now)

        return on_sample

    def _status(self, sample: Any) -> None:
        data = msgpack.unpackb(sample.payload.to_bytes())
        with self.lock:
            self.status[str(data["service"])] = data

    def _liveliness(self, sample: Any) -> None:
        import zenoh

        name = str(sample.key_expr).rsplit("/", 1)[-1]
        with self.lock:
            if sample.kind == zenoh.SampleKind.PUT:
                self.alive.add(name)
            else:
                self.alive.discard(name)

    def drops(self) -> dict[str, int]:
        with self.lock:
            return {s: int(sum(d.get("dropped", {}).values())) for s, d in self.status.items()}

    def close(self) -> None:
        with contextlib.suppress(Exception):
            self.token.undeclare()  # type: ignore[no-untyped-call]
        for handle in self.handles:
            with contextlib.suppress(Exception):
                handle.undeclare()
        self.session.close()


@contextlib.contextmanager
def live_stack(scenario_path: Path, out_dir: Path, overrides: dict[str, dict[str, Any]]
               ) -> Iterator[tuple[Stack, Listener]]:
    """A real-time stack on ``scenario_path`` with the bench listening; the simulator's
    clock starts once the bench's liveliness token is up."""
    scenario = load_scenario(scenario_path)
    params = stack_params(scenario, scenario_path, "paper")
    params["simulator"].update(clock="realtime",
                               wait_for=["laser_driver", "perception", "tracking", "planner",
                                         "motor_bridge", "bench"])
    params["motor_bridge"]["clock"] = "realtime"
    for service, values in overrides.items():
        params.setdefault(service, {}).update(values)
    stack = Stack(out_dir=out_dir, params=params, log_level="WARNING")
    stack.start()
    listener: Listener | None = None
    try:
        listener = Listener(stack)
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            failure = stack.failure()
            if failure:
                raise RuntimeError(failure)
            with listener.lock:
                if listener.scans:
                    break
            time.sleep(0.05)
        else:
            raise RuntimeError(f"no scan within 60 s; see {out_dir / 'logs'}")
        yield stack, listener
    finally:
        if listener is not None:
            listener.close()
        stack.stop()


@dataclass
class LatencyResult:
    samples: int
    scan_to_base_ms: list[float]
    scan_to_cmd_ms: list[float]
    rss_mb: dict[str, float]


def measure_latency(seconds: float, work: Path,
                    scenario: Path = SCENARIOS / "h-mixed.yaml") -> LatencyResult:
    with live_stack(scenario, work / "latency", {}) as (stack, listener):
        time.sleep(1.0)  # let the links settle
        with listener.lock:
            listener.scans.clear()
            listener.commands.clear()
            listener.base.clear()
        time.sleep(seconds)
        rss = {name: psutil.Process(proc.pid).memory_info().rss / 2**20
               for name, proc in stack.processes.items() if proc.poll() is None}
        with listener.lock:
            scans, commands, base = dict(listener.scans), dict(listener.commands), dict(
                listener.base)
    to_base = [(base[s] - t) * 1e3 for s, t in scans.items() if s in base]
    to_cmd = [(commands[s] - t) * 1e3 for s, t in scans.items() if s in commands]
    return LatencyResult(len(to_base), to_base, to_cmd, rss)


def latency_table(r: LatencyResult) -> str:
    med = statistics.median(r.scan_to_base_ms) if r.scan_to_base_ms else math.nan
    p99 = percentile(r.scan_to_base_ms, 99)
    cmd_med = statistics.median(r.scan_to_cmd_ms) if r.scan_to_cmd_ms else math.nan
    lines = [
        "| interval (wall clock, one receiving process) | samples | median ms | p99 ms | "
        "max ms | target |",
        "|---|---|---|---|---|---|",
        f"| scan → base command (laser driver's publish → motor bridge's publish) | "
        f"{r.samples} | {fmt(med, 2)} | {fmt(p99, 2)} | "
        f"{fmt(max(r.scan_to_base_ms) if r.scan_to_base_ms else math.nan, 2)} | median ≤ "
        f"{TARGET_LATENCY_MEDIAN_MS:g} ms ({verdict(med <= TARGET_LATENCY_MEDIAN_MS)}), "
        f"p99 ≤ {TARGET_LATENCY_P99_MS:g} ms ({verdict(p99 <= TARGET_LATENCY_P99_MS)}) |",
        f"| scan → velocity command (… → planner's publish) | {len(r.scan_to_cmd_ms)} | "
        f"{fmt(cmd_med, 2)} | {fmt(percentile(r.scan_to_cmd_ms, 99), 2)} | "
        f"{fmt(max(r.scan_to_cmd_ms) if r.scan_to_cmd_ms else math.nan, 2)} | |",
    ]
    return "\n".join(lines)


def memory_table(r: LatencyResult) -> str:
    lines = ["| service | resident memory, MiB |", "|---|---|"]
    lines += [f"| {name} | {mb:.0f} |" for name, mb in r.rss_mb.items()]
    lines.append(f"| total | {sum(r.rss_mb.values()):.0f} |")
    return "\n".join(lines)


# --- lockstep speed -----------------------------------------------------------------

_LOG_TIME = re.compile(r"^(\d{4}-\d\d-\d\d \d\d:\d\d:\d\d,\d{3}) ")


def _log_seconds(log: Path) -> float | None:
    """Wall seconds between the simulator's 'run ... starts' and 'run ... ended' lines."""
    start = end = None
    for line in log.read_text(errors="replace").splitlines():
        match = _LOG_TIME.match(line)
        if match is None:
            continue
        when = datetime.strptime(match.group(1), "%Y-%m-%d %H:%M:%S,%f").timestamp()
        if " starts (" in line:
            start = when
        elif " ended: " in line:
            end = when
    return None if start is None or end is None else end - start


@dataclass
class LockstepRow:
    scenario: str
    outcome: str
    sim_time: float
    loop_wall: float | None
    command_wall: float


def measure_lockstep(work: Path, scenarios: tuple[Path, ...] = PAPER_SCENARIOS,
                     planner: str = "paper") -> list[LockstepRow]:
    rows = []
    for path in scenarios:
        out = work / "lockstep" / path.stem
        done = subprocess.run(
            [sys.executable, "-m", "zenav", "run", str(path), "--out", str(out),
             "--planner", planner], capture_output=True, text=True, check=False, timeout=1800)
        if done.returncode != 0:
            raise RuntimeError(f"zenav run {path.name} failed: {done.stderr.strip()}")
        record = json.loads((out / "run.json").read_text())
        rows.append(LockstepRow(path.stem, record["outcome"], record["time"],
                                _log_seconds(out / "logs" / "simulator.log"),
                                record["wall_time"]))
    return rows


def lockstep_table(rows: list[LockstepRow]) -> str:
    lines = ["| scenario | outcome | simulated s | simulator loop wall s | × real time (loop) | "
             "zenav run wall s | × real time (whole command) |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        loop = r.loop_wall if r.loop_wall else math.nan
        lines.append(f"| {r.scenario} | {r.outcome} | {r.sim_time:.1f} | {fmt(loop, 1)} | "
                     f"{fmt(r.sim_time / loop, 1)} | {r.command_wall:.1f} | "
                     f"{r.sim_time / r.command_wall:.1f} |")
    sim = sum(r.sim_time for r in rows)
    loop_total = sum(r.loop_wall or math.nan for r in rows)
    wall = sum(r.command_wall for r in rows)
    factor = sim / loop_total
    lines.append(f"| **all** | | {sim:.1f} | {fmt(loop_total, 1)} | **{fmt(factor, 1)}** | "
                 f"{wall:.1f} | {sim / wall:.1f} |")
    lines.append("")
    lines.append(f"Target: ≥ {TARGET_LOCKSTEP_FACTOR:g}× real time — measured {fmt(factor, 1)}× "
                 f"in the simulator's loop, {sim / wall:.1f}× for the whole command with the "
                 f"processes' start and stop ({verdict(factor >= TARGET_LOCKSTEP_FACTOR)}).")
    return "\n".join(lines)


# --- sustained scan rate ------------------------------------------------------------


@dataclass
class RateRow:
    rate_hz: float
    scans_hz: float  # scans seen per wall second
    answered: float  # share of scans with their base command
    drops: dict[str, int]
    latency_p99_ms: float

    @property
    def keeps_up(self) -> bool:
        return (not any(self.drops.values()) and self.answered >= 0.99
                and self.scans_hz >= 0.95 * self.rate_hz)


def measure_rate(rate: float, seconds: float, work: Path,
                 scenario: Path = SCENARIOS / "h-mixed.yaml") -> RateRow:
    data = yaml.safe_load(scenario.read_text())
    data.setdefault("laser", {})["rate_hz"] = rate
    data["duration"] = 3600
    copy = work / f"rate-{rate:g}.yaml"
    copy.parent.mkdir(parents=True, exist_ok=True)
    copy.write_text(yaml.safe_dump(data))
    with live_stack(copy, work / f"rate-{rate:g}", {}) as (_, listener):
        time.sleep(2.0)  # links settled, first status messages in
        before = listener.drops()
        with listener.lock:
            listener.scans.clear()
            listener.base.clear()
        started = time.perf_counter()
        time.sleep(seconds)
        with listener.lock:
            scans, base = dict(listener.scans), dict(listener.base)
        elapsed = time.perf_counter() - started
        time.sleep(1.2)  # one more status period
        after = listener.drops()
    # Scans in the last 0.2 s may still be on their way through the stack.
    horizon = max(scans.values(), default=0.0) - 0.2
    counted = [s for s, t in scans.items() if t <= horizon]
    answered = sum(1 for s in counted if s in base) / max(len(counted), 1)
    latency = [(base[s] - scans[s]) * 1e3 for s in counted if s in base]
    drops = {name: after.get(name, 0) - before.get(name, 0) for name in after}
    return RateRow(rate, len(scans) / elapsed, answered, drops, percentile(latency, 99))


def rate_table(rows: list[RateRow]) -> str:
    lines = ["| laser rate Hz | scans seen per s | scans answered | inputs dropped (service: n) "
             "| scan→base p99 ms | keeps up |", "|---|---|---|---|---|---|"]
    for r in rows:
        drops = ", ".join(f"{k}: {v}" for k, v in sorted(r.drops.items()) if v) or "none"
        lines.append(f"| {r.rate_hz:g} | {r.scans_hz:.1f} | {100 * r.answered:.1f} % | {drops} "
                     f"| {fmt(r.latency_p99_ms, 1)} | {'yes' if r.keeps_up else 'no'} |")
    best = max((r.rate_hz for r in rows if r.keeps_up), default=math.nan)
    lines.append("")
    verdict = "met" if best >= TARGET_RATE_HZ else "NOT met"
    lines.append(f"Target: ≥ {TARGET_RATE_HZ:g} Hz — highest rate tried with no drop and every "
                 f"scan answered: {fmt(best)} Hz ({verdict}).")
    return "\n".join(lines)


# --- the command --------------------------------------------------------------------

SECTIONS = ("compute", "latency", "lockstep", "rate")


def machine() -> str:
    cpu = "unknown CPU"
    with contextlib.suppress(OSError):
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    return f"{psutil.cpu_count()} cores, {cpu}, {psutil.virtual_memory().total / 2**30:.0f} GiB"


def run_perf(sections: tuple[str, ...], out: Path | None, scans: int = 200,
             obstacle_counts: tuple[int, ...] = (0, 5, 20), latency_seconds: float = 30.0,
             rates: tuple[float, ...] = (10, 50, 100, 200, 300, 400, 600),
             rate_seconds: float = 6.0, echo: Callable[[str], None] = print) -> str:
    """Run the chosen sections; print and return the report (Markdown)."""
    parts = [f"# zenav bench perf\n\n{datetime.now().astimezone():%Y-%m-%d %H:%M %Z}, "
             f"{machine()}, Python {sys.version.split()[0]}\n"]
    echo(parts[0])
    with tempfile.TemporaryDirectory(prefix="zenav-bench-") as tmp:
        work = out if out is not None else Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        for section in sections:
            if section == "compute":
                results = [time_compute(n, scans) for n in obstacle_counts]
                text = ("## Compute per scan, in process (361 beams)\n\n"
                        + compute_table(results))
            elif section == "latency":
                lat = measure_latency(latency_seconds, work)
                text = (f"## Scan-to-command latency over Zenoh (real time, 10 Hz, "
                        f"h-mixed, {latency_seconds:g} s)\n\n{latency_table(lat)}\n\n"
                        f"## Resident memory per service process (during that run)\n\n"
                        f"{memory_table(lat)}")
            elif section == "lockstep":
                text = ("## Lockstep simulation speed (zenav run, paper planner)\n\n"
                        + lockstep_table(measure_lockstep(work)))
            elif section == "rate":
                rows = []
                for rate in rates:
                    rows.append(measure_rate(rate, rate_seconds, work))
                text = (f"## Sustained scan rate in real time (h-mixed, {rate_seconds:g} s "
                        f"per rate)\n\n{rate_table(rows)}")
            else:
                raise ValueError(f"unknown section {section!r}; choose from {', '.join(SECTIONS)}")
            parts.append(text)
            echo(text + "\n")
    report = "\n\n".join(parts) + "\n"
    if out is not None:
        (out / "perf.md").write_text(report)
    return report
