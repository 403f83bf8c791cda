"""zenav rviz on the in-memory bus: a track list in, a MarkerArray on the ROS 2 wire out,
with the planner's latest state as a text marker and the view's liveliness tokens."""

from __future__ import annotations

import asyncio
import math

import numpy as np
import pytest

from tests.ros2 import samples
from zenav.rviz import RvizView
from zenav.schemas import keys
from zenav.schemas.codec import encode
from zenav.schemas.keys import Keys
from zenav.schemas.messages import GlobalPath, OccupancyMap
from zenav.services.ros2 import wire
from zenav.services.transport import InMemoryBus


async def test_tracks_become_markers_for_rviz():
    bus = InMemoryBus()
    view = RvizView(bus, "robot0", domain_id=3, topic="/zenav/markers")
    task = asyncio.create_task(view.run())
    k = Keys("robot0")
    try:
        bus.deliver(k.of(keys.PLANNER_STATE), encode(samples.state()))
        await asyncio.sleep(0.01)
        bus.deliver(k.of(keys.TRACKS), b"garbage")  # ignored, not fatal
        await asyncio.sleep(0.01)
        bus.deliver(k.of(keys.TRACKS), encode(samples.tracks()))
        await asyncio.sleep(0.01)
        key = wire.topic_key(3, "/zenav/markers", wire.MARKER_ARRAY)
        sent = [p for kk, p in bus.published if kk == key]
        tokens = [wire.parse_token(t) for t in view.ros.tokens]
    finally:
        task.cancel()
        view.close()
    assert len(sent) == 1 and view.sent == 1
    assert view.heard.anything  # no "nothing heard" note for this robot
    markers = wire.deserialize(sent[0], wire.MARKER_ARRAY).markers
    assert {m.ns for m in markers} == {"", "tracks", "velocity", "planner"}
    assert next(m for m in markers if m.ns == "planner").text.startswith("(c) slow")
    assert {(t.kind, t.topic) for t in tokens} == {("NN", None), ("MP", "/zenav/markers"),
                                                 ("MP", "/zenav/plan"), ("MP", "/zenav/map")}


async def test_the_view_has_heard_nothing_until_a_message_comes():
    bus = InMemoryBus()
    view = RvizView(bus, "robot0", domain_id=3)
    task = asyncio.create_task(view.run())
    try:
        bus.deliver(Keys("robot1").of(keys.TRACKS), encode(samples.tracks()))  # not ours
        await asyncio.sleep(0.01)
        before = view.heard.anything
        bus.deliver(Keys("robot0").of(keys.PLANNER_STATE), encode(samples.state()))
        await asyncio.sleep(0.01)
    finally:
        task.cancel()
        view.close()
    assert not before and view.heard.anything


async def test_global_path_becomes_a_ros_path():
    bus = InMemoryBus()
    view = RvizView(bus, "robot0", domain_id=3, frame="odom")
    task = asyncio.create_task(view.run())
    k = Keys("robot0")
    try:
        bus.deliver(k.of(keys.PATH), b"garbage")  # ignored, not fatal
        await asyncio.sleep(0.01)
        points = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 2.0]])
        bus.deliver(k.of(keys.PATH), encode(GlobalPath(stamp=7.25, seq=0, points=points,
                                                       reason="start")))
        await asyncio.sleep(0.01)
        key = wire.topic_key(3, "/zenav/plan", wire.PATH)
        sent = [p for kk, p in bus.published if kk == key]
        tokens = [wire.parse_token(t) for t in view.ros.tokens]
    finally:
        task.cancel()
        view.close()
    assert len(sent) == 1 and view.paths_sent == 1
    path = wire.deserialize(sent[0], wire.PATH)
    assert path.header.frame_id == "odom"
    assert (path.header.stamp.sec, path.header.stamp.nanosec) == (7, 250_000_000)
    assert [(p.pose.position.x, p.pose.position.y) for p in path.poses] == [
        (0.0, 0.0), (1.0, 0.0), (1.0, 2.0)]
    assert all(p.header.frame_id == "odom" for p in path.poses)
    second = path.poses[1].pose.orientation  # facing the next point: +90 degrees
    assert 2 * math.atan2(second.z, second.w) == pytest.approx(math.pi / 2)
    assert ("MP", "/zenav/plan") in {(t.kind, t.topic) for t in tokens}


async def test_the_map_becomes_a_ros_occupancy_grid():
    bus = InMemoryBus()
    view = RvizView(bus, "robot0", domain_id=3, frame="odom")
    task = asyncio.create_task(view.run())
    k = Keys("robot0")
    grid = np.full((4, 3), -1, dtype=np.int8)  # [ix, iy]: 4 cells along x, 3 along y
    grid[:2, :] = 0
    grid[1, 2] = 100
    cells = np.ascontiguousarray(grid.T).ravel()  # row by row, as the message holds them
    try:
        bus.deliver(k.of(keys.MAP), b"garbage")  # ignored, not fatal
        await asyncio.sleep(0.01)
        bus.deliver(k.of(keys.MAP), encode(OccupancyMap(
            stamp=3.5, seq=0, origin=(-1.0, 2.0), resolution=0.1, width=4, height=3,
            cells=cells)))
        await asyncio.sleep(0.01)
        key = wire.topic_key(3, "/zenav/map", wire.OCCUPANCY_GRID)
        sent = [p for kk, p in bus.published if kk == key]
        tokens = [wire.parse_token(t) for t in view.ros.tokens]
    finally:
        task.cancel()
        view.close()
    assert len(sent) == 1 and view.maps_sent == 1
    ros_map = wire.deserialize(sent[0], wire.OCCUPANCY_GRID)
    assert ros_map.header.frame_id == "odom"
    assert (ros_map.header.stamp.sec, ros_map.header.stamp.nanosec) == (3, 500_000_000)
    info = ros_map.info
    assert (info.width, info.height) == (4, 3)
    assert info.resolution == pytest.approx(0.1)
    assert (info.origin.position.x, info.origin.position.y) == (-1.0, 2.0)
    assert info.origin.orientation.w == 1.0
    # ROS's order: row by row from the origin; cell (ix=1, iy=2) is data[2 * 4 + 1].
    assert ros_map.data.tolist() == cells.tolist()
    assert ros_map.data[2 * 4 + 1] == 100 and ros_map.data[3] == -1
    assert ("MP", "/zenav/map") in {(t.kind, t.topic) for t in tokens}
