"""The monitor's model (no terminal, no bus) and its screen, rendered headless."""

from __future__ import annotations

import io
import math
from typing import Any

import numpy as np
import pytest
from rich.console import Console

from zenav.monitor.model import LatencyMeter, MonitorModel, RateMeter
from zenav.monitor.screen import render
from zenav.schemas.codec import encode
from zenav.schemas.messages import (
    BaseCommand,
    GroundTruth,
    LaserScan,
    Message,
    Odometry,
    PlannerState,
    Pose2D,
    RunResult,
    ServiceStatus,
    Track,
    TrackList,
    VelocityCommand,
)

T0 = 1_000_000.0


def pose(x: float = 2.0, y: float = 3.0, heading: float = 0.0) -> Pose2D:
    return Pose2D(x=x, y=y, heading=heading)


def scan(stamp: float) -> LaserScan:
    return LaserScan(stamp=stamp, seq=0, frame="laser", angle_min=-math.pi / 2,
                     angle_max=math.pi / 2, angle_increment=math.pi / 2, range_min=0.0,
                     range_max=8.0, ranges=np.array([8.0, 8.0, 8.0], dtype=np.float32))


def track(id_: int, kind: str, speed: float, heading: float) -> Track:
    return Track(id=id_, kind=kind, x=4.0, y=5.0, vx=speed * math.cos(heading),
                 vy=speed * math.sin(heading), speed=speed, heading=heading, radius=0.2,
                 xi=0.5, varsigma=0.5, alpha_o_deg=10.0, age=3, cells=(1, 2, 3, 4), area=4)


class Feed:
    def __init__(self, model: MonitorModel) -> None:
        self.model = model

    def __call__(self, topic: str, message: Message, at: float) -> None:
        self.model.on_sample(f"zenav/r1/{topic}", encode(message), T0 + at)


@pytest.fixture
def model() -> MonitorModel:
    return MonitorModel("r1", silence_after=0.5)


def kinds(model: MonitorModel) -> list[tuple[str, dict[str, Any]]]:
    return [(e.kind, e.data) for e in model.drain_events()]


def test_rates_count_messages_over_the_window():
    meter = RateMeter(window=2.0)
    for i in range(41):
        meter.add(T0 + i * 0.05)  # 20 Hz for 2 s
    assert meter.rate(T0 + 2.0) == pytest.approx(20.5, abs=0.6)
    assert meter.typical_gap() == pytest.approx(0.05)
    assert meter.rate(T0 + 10.0) == 0.0


def test_latency_pairs_each_command_with_the_scan_of_the_same_stamp():
    meter = LatencyMeter()
    meter.scan(1.0, T0)
    meter.scan(1.0, T0 + 0.5)  # a retransmission: the first receipt counts
    meter.scan(1.1, T0 + 0.1)
    assert meter.command(1.0, T0 + 0.004) == pytest.approx(0.004)
    assert meter.command(1.0, T0 + 0.9) is None  # answered already
    assert meter.command(7.0, T0 + 0.9) is None  # no such scan
    assert meter.command(1.1, T0 + 0.106) == pytest.approx(0.006)
    stats = meter.stats()
    assert stats["n"] == 2 and stats["max"] == pytest.approx(0.006)
    assert stats["median"] == pytest.approx(0.005)


def test_liveliness_changes_are_events_and_comebacks_are_counted(model):
    model.on_liveliness("zenav/r1/alive/planner", True, T0)
    model.on_liveliness("zenav/r1/alive/planner", True, T0 + 0.1)  # no change, no event
    model.on_liveliness("zenav/r1/alive/planner", False, T0 + 1)
    model.on_liveliness("zenav/r1/alive/planner", True, T0 + 1.4)
    model.on_liveliness("zenav/r1/alive/router", True, T0 + 2)
    events = kinds(model)
    assert [(k, d["service"], d["alive"]) for k, d in events] == [
        ("alive", "planner", True), ("alive", "planner", False), ("alive", "planner", True),
        ("alive", "router", True)]
    snap = model.snapshot(T0 + 3)
    assert snap["services"]["planner"] == {"alive": True, "since": T0 + 1.4, "rejoins": 1,
                                           "received": None, "rejected": None, "dropped": None}
    assert snap["services"]["perception"]["alive"] is None  # expected, never seen
    assert snap["services"]["router"]["alive"] is True


def test_robot_planner_obstacles_and_latency_in_the_snapshot(model):
    feed = Feed(model)
    for i in range(5):
        t = i * 0.1
        feed("odom", Odometry(stamp=t, seq=i, pose=pose(2 + t, 3, 0.1), v=0.2, omega=0.0), t)
        feed("scan", scan(t), t + 0.001)
        feed("cmd_vel", VelocityCommand(stamp=t, seq=i, v=0.2, omega=0.0), t + 0.004)
    feed("tracks", TrackList(stamp=0.4, seq=4, pose=pose(), tracks=[
        track(7, "dynamic", 0.5, math.pi / 2), track(8, "static", 0.0, 0.0)]), 0.41)
    feed("planner/state", PlannerState(stamp=0.4, seq=4, scenario="f", action="morphin",
                                       target=(5.0, 5.0), speed=0.1), 0.42)
    feed("status/planner", ServiceStatus(stamp=T0, seq=0, service="planner",
                                         received={"tracks": 40}, rejected={"msgpack": 2},
                                         dropped={}), 0.43)
    snap = model.snapshot(T0 + 0.5)
    assert snap["robot"]["x"] == pytest.approx(2.4) and snap["robot"]["v"] == 0.2
    assert snap["robot"]["heading_deg"] == pytest.approx(math.degrees(0.1), abs=0.01)
    assert snap["planner"]["scenario"] == "f" and snap["planner"]["action"] == "morphin"
    assert snap["obstacles"][0] == {"id": 7, "kind": "dynamic", "x": 4.0, "y": 5.0,
                                    "speed": 0.5, "heading_deg": 90.0, "visible": True}
    assert snap["obstacles"][1]["kind"] == "static"
    assert snap["latency"]["n"] == 5 and snap["latency"]["median"] == pytest.approx(0.003)
    assert snap["rates"]["odom"] == pytest.approx(2.5)  # 5 in a 2 s window
    assert snap["services"]["planner"]["received"] == 40
    assert snap["services"]["planner"]["rejected"] == 2
    planner_events = [d for k, d in kinds(model) if k == "planner"]
    assert planner_events == [{"scenario": "f", "action": "morphin", "stamp": 0.4}]


def test_a_stale_stop_and_a_standstill_are_events_with_their_times(model):
    feed = Feed(model)
    feed("device/base_cmd", BaseCommand(stamp=1.0, seq=0, v=0.2, omega=0.0), 1.0)
    feed("device/base_cmd", BaseCommand(stamp=1.1, seq=1, v=0.2, omega=0.0), 1.1)
    feed("sim/truth", GroundTruth(stamp=1.1, seq=0, pose=pose(), v=0.2, obstacles=[]), 1.1)
    feed("device/base_cmd", BaseCommand(stamp=1.6, seq=2, v=0.0, omega=0.0, reason="stale"),
         1.61)
    feed("sim/truth", GroundTruth(stamp=1.7, seq=1, pose=pose(), v=0.0, obstacles=[]), 1.7)
    events = [(k, d) for k, d in kinds(model) if k in ("base", "motion")]
    assert [(k, d.get("reason"), d.get("moving")) for k, d in events] == [
        ("base", "command", None), ("motion", None, True), ("base", "stale", None),
        ("motion", None, False)]
    stale = next(e for e in model.recent if e.kind == "base" and e.data["reason"] == "stale")
    assert stale.wall == T0 + 1.61


def test_a_topic_that_stops_and_comes_back_gives_flow_events(model):
    feed = Feed(model)
    for i in range(10):
        feed("odom", Odometry(stamp=i * 0.1, seq=i, pose=pose(), v=0.0, omega=0.0), i * 0.1)
    model.tick(T0 + 1.0)  # 0.1 s after the last: still flowing
    model.tick(T0 + 1.5)  # 0.6 s: stopped
    feed("odom", Odometry(stamp=2.0, seq=10, pose=pose(), v=0.0, omega=0.0), 2.0)
    flows = [(e.wall - T0, e.data["flowing"]) for e in model.drain_events() if e.kind == "flow"]
    assert flows == [(0.0, True), (pytest.approx(0.9), False), (2.0, True)]
    # A gap shorter than a tick period is reported from the message that ends it.
    for i in range(5):
        feed("odom", Odometry(stamp=2.1 + i / 10, seq=11 + i, pose=pose(), v=0.0, omega=0.0),
             2.1 + i * 0.1)
    feed("odom", Odometry(stamp=9.0, seq=20, pose=pose(), v=0.0, omega=0.0), 3.3)
    flows = [(e.wall - T0, e.data) for e in model.drain_events() if e.kind == "flow"]
    assert [(round(w, 3), d["flowing"]) for w, d in flows] == [(2.5, False), (3.3, True)]


def test_the_run_result_and_undecodable_payloads(model):
    feed = Feed(model)
    result = RunResult(stamp=21.5, seq=0, scenario="s", outcome="reached", time=21.5,
                       path_length=4.3, min_clearance=math.inf,
                       trajectory=np.zeros((2, 5)))
    feed("sim/result", result, 5.0)
    feed("sim/result", result, 5.5)  # repeated (latched): one event
    model.on_sample("zenav/r1/odom", b"\xc1 not msgpack", T0 + 6)
    model.on_sample("zenav/other/odom", b"ignored", T0 + 6)
    events = [(k, d) for k, d in kinds(model) if k == "result"]
    assert events == [("result", {"outcome": "reached", "time": 21.5, "path_length": 4.3,
                                  "min_clearance": None, "collided_with": None})]
    snap = model.snapshot(T0 + 7)
    assert snap["rejected"] == {"msgpack": 1}
    assert "zenav/other/odom" not in snap["rates"]


def test_the_screen_renders_headless(model):
    feed = Feed(model)
    feed("odom", Odometry(stamp=3.0, seq=0, pose=pose(2.5, 3.0), v=0.1, omega=0.0), 3.0)
    feed("scan", scan(3.0), 3.0)
    feed("cmd_vel", VelocityCommand(stamp=3.0, seq=0, v=0.1, omega=0.0), 3.0025)
    feed("device/base_cmd", BaseCommand(stamp=3.0, seq=0, v=0.1, omega=0.0), 3.003)
    feed("tracks", TrackList(stamp=3.0, seq=0, pose=pose(), tracks=[
        track(4, "dynamic", 0.35, math.pi)]), 3.01)
    feed("planner/state", PlannerState(stamp=3.0, seq=0, scenario="c", action="slow",
                                       target=(8.0, 3.0), speed=0.05), 3.02)
    model.on_liveliness("zenav/r1/alive/planner", True, T0 + 1)
    model.on_liveliness("zenav/r1/alive/tracking", True, T0 + 1)
    model.on_liveliness("zenav/r1/alive/tracking", False, T0 + 2)
    console = Console(file=io.StringIO(), width=120, record=True, color_system=None)
    console.print(render(model, T0 + 3.5))
    text = console.export_text()
    assert "robot r1" in text
    assert "odometry" in text and "2.50" in text and "0.10 m/s (command)" in text
    assert "scenario c, action slow" in text
    assert "last 2.5 ms" in text
    for name in ("simulator", "laser_driver", "perception", "motor_bridge"):
        assert name in text
    planner_row = next(line for line in text.splitlines() if "planner" in line and "alive" in line)
    assert "2 s" in planner_row
    assert any("tracking" in line and "gone" in line for line in text.splitlines())
    assert any("dynamic" in line and "0.35" in line and "180°" in line
               for line in text.splitlines())
    assert "cmd_vel" in text
