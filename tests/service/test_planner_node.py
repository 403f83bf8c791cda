"""The planner on the in-memory bus: a decision per stamp once its track list and its
scan are both in (whatever the order), a bounded wait for a scan that does not come,
the global path on change and the map at a low rate; and the motor bridge letting a
bounded reverse through when allowed."""

from __future__ import annotations

import asyncio
import math

import numpy as np

from tests.planner.scans import scan_of
from tests.service.harness import running
from zenav.schemas import keys
from zenav.schemas.messages import (
    BaseCommand,
    GlobalPath,
    LaserScan,
    OccupancyMap,
    Pose2D,
    TrackList,
    VelocityCommand,
)
from zenav.services.motor_bridge.params import Params as BridgeParams
from zenav.services.planner.params import Params

POSE = (2.0, 3.0, 0.0)
WALL = [(6.0, -1.0, 6.2, 4.5), (6.0, 5.5, 6.2, 9.0)]


def params(**changes: object) -> Params:
    return Params.model_validate({"goal": (8.0, 3.0), "start": (2.0, 3.0),
                                  "window_radius": 2.0, **changes})


def tracks(t: float) -> TrackList:
    return TrackList(stamp=t, seq=0, pose=Pose2D(x=POSE[0], y=POSE[1], heading=POSE[2]),
                     tracks=[])


def scan(t: float) -> LaserScan:
    data = scan_of(POSE, boxes=WALL)
    return LaserScan(stamp=t, seq=0, frame="laser", angle_min=data.angle_min,
                     angle_max=-data.angle_min, angle_increment=data.angle_increment,
                     range_min=0.0, range_max=data.range_max,
                     ranges=data.ranges.astype(np.float32))


async def test_one_command_per_stamp_once_both_halves_are_in_whatever_the_order():
    async with running("planner", params()) as h:
        h.send(keys.SCAN, scan(0.0))
        h.send(keys.TRACKS, tracks(0.0))  # scan first
        await h.settle()
        h.send(keys.TRACKS, tracks(0.1))  # track list first: held for its scan
        await h.settle()
        assert [c.stamp for c in h.received(keys.CMD_VEL, VelocityCommand)] == [0.0]
        h.send(keys.SCAN, scan(0.1))
        await h.settle()
        assert [c.stamp for c in h.received(keys.CMD_VEL, VelocityCommand)] == [0.0, 0.1]
        # Both halves of every stamp reached the map.
        assert h.service.planner.costmap is not None
        assert h.service.planner.costmap.now == 0.1


async def test_a_track_list_whose_scan_never_comes_is_decided_after_the_bound():
    async with running("planner", params(scan_wait=0.05)) as h:
        h.send(keys.TRACKS, tracks(0.0))
        await h.settle()
        assert h.received(keys.CMD_VEL, VelocityCommand) == []
        await asyncio.sleep(0.2)
        await h.settle()
        assert [c.stamp for c in h.received(keys.CMD_VEL, VelocityCommand)] == [0.0]


async def test_the_path_is_published_on_change_and_the_map_once_a_second():
    async with running("planner", params()) as h:
        for k in range(25):
            t = round(k * 0.1, 6)
            h.send(keys.SCAN, scan(t))
            h.send(keys.TRACKS, tracks(t))
            await h.settle()
        paths = h.received(keys.PATH, GlobalPath)
        maps = h.received(keys.MAP, OccupancyMap)
    assert paths[0].points.tolist() == [[2.0, 3.0], [8.0, 3.0]]  # the straight line first
    assert len(paths) >= 2 and len(paths[-1].points) > 2  # then through the wall's gap
    assert [m.stamp for m in maps] == [0.0, 1.0, 2.0]
    grid = maps[-1].grid()
    assert grid.shape == (maps[-1].width, maps[-1].height)
    ix = math.floor((6.05 - maps[-1].origin[0]) / maps[-1].resolution)
    iy = math.floor((3.0 - maps[-1].origin[1]) / maps[-1].resolution)
    assert grid[ix, iy] == 100  # the wall, where the scan saw it


async def test_the_bridge_lets_a_bounded_reverse_through_only_when_allowed():
    for allow, expected in ((False, 0.0), (True, -0.05)):
        bridge = BridgeParams(allow_reverse=allow, max_reverse_speed=0.05, accel=10.0,
                              decel=10.0)
        async with running("motor_bridge", bridge) as h:
            h.send(keys.CMD_VEL, VelocityCommand(stamp=0.0, seq=0, v=-0.3, omega=0.0))
            await h.settle()
            out = h.received(keys.BASE_CMD, BaseCommand)
        assert out[-1].v == expected


async def test_a_pose_a_bad_message_puts_1e15_m_away_does_not_hold_the_planner():
    """Schema-valid (finite) but absurd: the map and the global path look only at their
    grid, so the planner answers that stamp and the next ones as usual."""
    async with running("planner", params()) as h:
        h.send(keys.SCAN, scan(0.0))
        h.send(keys.TRACKS, tracks(0.0))
        await h.settle()
        far = TrackList(stamp=0.1, seq=1, pose=Pose2D(x=1e15, y=1e15, heading=0.0), tracks=[])
        h.send(keys.SCAN, scan(0.1))
        h.send(keys.TRACKS, far)
        await h.settle()
        h.send(keys.SCAN, scan(0.2))
        h.send(keys.TRACKS, tracks(0.2))
        await h.settle()
        assert [c.stamp for c in h.received(keys.CMD_VEL, VelocityCommand)] == [0.0, 0.1, 0.2]
