"""The monitor watching the real planner service on the in-memory bus: what the planner
puts on the bus, handed to the monitor's model in order, gives the global path (the
straight line, then the way through a wall's gap), the occupancy map with the wall, and
a map view with both."""

from __future__ import annotations

import io

import numpy as np
from rich.console import Console

from tests.service.harness import running
from tests.service.test_planner_node import POSE, scan  # the wall with a 1 m gap
from zenav.monitor.model import MonitorModel
from zenav.monitor.screen import render
from zenav.monitor.view import GOAL, OCCUPIED, PATH
from zenav.schemas import keys
from zenav.schemas.messages import Odometry, Pose2D, TrackList
from zenav.services.planner.params import Params

T0 = 1_000_000.0


async def test_the_monitor_shows_the_planners_path_and_map():
    params = Params.model_validate({"goal": (8.0, 3.0), "start": (2.0, 3.0),
                                    "window_radius": 2.0})
    pose = Pose2D(x=POSE[0], y=POSE[1], heading=POSE[2])
    async with running("planner", params) as h:
        monitor = MonitorModel(h.keys.robot_id)
        for k in range(25):
            t = round(k * 0.1, 6)
            # The robot's odometry, as the base would publish it (the planner does not).
            h.send(keys.ODOM, Odometry(stamp=t, seq=k, pose=pose, v=0.0, omega=0.0))
            h.send(keys.SCAN, scan(t))
            h.send(keys.TRACKS, TrackList(stamp=t, seq=k, pose=pose, tracks=[]))
            await h.settle()
        published = list(h.bus.published)
    for i, (key, payload) in enumerate(published):
        monitor.on_sample(key, payload, T0 + i * 1e-3)
    now = T0 + len(published) * 1e-3
    snap = monitor.snapshot(now)
    paths = [e.data for e in monitor.drain_events() if e.kind == "path"]
    assert paths[0] == {"reason": "start", "waypoints": 2, "length": 6.0, "stamp": 0.0}
    assert len(paths) >= 2 and paths[-1]["waypoints"] > 2 and paths[-1]["length"] > 6.0
    path = snap["path"]
    assert path["plans"] == len(paths) and path["goal"] == [8.0, 3.0]
    xs, ys = zip(*path["points"], strict=True)
    assert list(xs) == sorted(xs)  # forward all the way: no doubling back
    assert 4.5 < float(np.interp(6.1, xs, ys)) < 5.5  # it crosses the wall's line in the gap
    occupancy = snap["map"]
    assert occupancy is not None and occupancy["stamp"] == 2.0
    assert 0 < occupancy["occupied_fraction"] < occupancy["known_fraction"] <= 1
    # The view: the wall ahead of the robot, the path and the goal.
    console = Console(file=io.StringIO(), width=160, record=True, color_system=None)
    console.print(render(monitor, now))
    text = console.export_text()
    assert f"global path: {path['length']:.2f} m, {path['waypoints']} waypoints" in text
    lines = text.splitlines()
    top = next(i for i, line in enumerate(lines) if line.startswith("map round the robot"))
    view = [line[:41] for line in lines[top + 1:top + 22]]
    wall_column = 20 + 16  # x = 6.0-6.25 is 16 columns right of the robot's x = 2
    assert sum(row[wall_column] == OCCUPIED for row in view) >= 8
    assert sum(row.count(PATH) for row in view) >= 12
    assert not any(GOAL in row for row in view)  # the goal, 6 m ahead, is out of view
