"""``zenav monitor --jsonl`` against a real stack (``zenav up``, deploy/stack.yaml) on the
wall-with-a-gap scene: it shows the planner's global path (the straight line first, then
one planned again on the map, clear of the wall) and its occupancy map; the paths it
shows are those the planner put on the bus (recorded by ``zenav record`` beside it)."""

from __future__ import annotations

import signal
import subprocess
from pathlib import Path

import pytest

from tests.integration.livestack import (
    REPO,
    Deployed,
    Event,
    Monitor,
    copy_deployment,
    monitor_command,
    zenav,
)
from zenav.bag.mcapfile import read_bag
from zenav.engine import add_path
from zenav.launch import free_port_block
from zenav.schemas.codec import decode
from zenav.schemas.messages import GlobalPath

pytestmark = pytest.mark.integration

SCENARIO = REPO / "sim" / "scenarios" / "nav-wall-gap.yaml"  # wall at x = 5, gap y 3.8-4.8
SERVICES = ["laser_driver", "perception", "tracking", "planner", "motor_bridge"]


def planned_again(snap: Event) -> bool:
    path = snap.get("path")
    return bool(path and path["plans"] >= 2 and path["found"] and snap.get("map")
                and snap["map"]["occupied_cells"] > 0)


def test_the_monitor_shows_the_global_path_and_the_map_of_a_live_stack(tmp_path: Path) -> None:
    endpoint = f"tcp/127.0.0.1:{free_port_block(1)}"
    config = copy_deployment(
        REPO / "deploy" / "stack.yaml", tmp_path / "stack.yaml", scenario=str(SCENARIO),
        router={"listen": [endpoint]}, transport={"mode": "client", "connect": [endpoint]})
    # The simulator starts once the recorder is there, and the recorder is started once
    # the monitor sees the planner: the monitor hears the very first path.
    stack = Deployed(config, tmp_path / "run", up_args=[
        "--set", "simulator.realtime_factor=4",
        "--set", f"simulator.wait_for=[{','.join(SERVICES)},record]"])
    monitor = recorder = None
    recording = tmp_path / "run.mcap"
    try:
        stack.up()
        monitor = Monitor(monitor_command(endpoint), tmp_path / "monitor.log")
        monitor.event("alive", 30, service="planner", alive=True)
        recorder = subprocess.Popen(zenav("record", str(recording), "--connect", endpoint),
                                    stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        first = monitor.event("path", 60)
        snap = monitor.state("a second path and a map with the wall", planned_again, 90)
        recorder.send_signal(signal.SIGINT)
        said, _ = recorder.communicate(timeout=15)
    finally:
        if recorder is not None and recorder.poll() is None:
            recorder.kill()
        if monitor is not None:
            monitor.stop()
        stack.cleanup()
    assert "nothing heard" not in said, said  # it heard the stack through the router
    assert first["reason"] == "start" and first["waypoints"] == 2
    assert first["length"] == pytest.approx(6.0, abs=0.01)  # (2, 3) to (8, 3)
    path, occupancy = snap["path"], snap["map"]
    assert path["goal"] == [8.0, 3.0] and path["reason"] != "start"
    # Planned again on the map: it crosses the wall's line (x = 5) clear of the wall,
    # which stands from y = 0.5 to 3.8 and from 4.8 to 7.5.
    xs = [x for x, _ in path["points"]]
    ys = [y for _, y in path["points"]]
    crossing = next(i for i in range(1, len(xs)) if xs[i - 1] < 5.0 <= xs[i])
    t = (5.0 - xs[crossing - 1]) / (xs[crossing] - xs[crossing - 1])
    y = ys[crossing - 1] + t * (ys[crossing] - ys[crossing - 1])
    assert y < 0.5 or 3.8 < y < 4.8 or y > 7.5, path["points"]
    assert occupancy["resolution"] == pytest.approx(0.1)
    assert 0 < occupancy["occupied_fraction"] < occupancy["known_fraction"] <= 1
    events = [e for e in monitor.events if e["event"] == "path"]
    assert [e["reason"] for e in events][:1] == ["start"]
    # What the monitor showed is what the planner published: every distinct path, in
    # order (the planner also sends an unchanged path again every path_period).
    recorded = [decode(r.payload, GlobalPath) for r in read_bag(recording, {"planner/path"})]
    distinct: list[GlobalPath] = []
    for sent in recorded:
        add_path(distinct, sent)
    assert [(p.planned_at, p.reason, len(p.points)) for p in distinct][:len(events)] == [
        (e["stamp"], e["reason"], e["waypoints"]) for e in events]
    shown = next(p for p in recorded if p.planned_at == path["stamp"])
    assert [[round(float(x), 3), round(float(y), 3)] for x, y in shown.points] == path["points"]
