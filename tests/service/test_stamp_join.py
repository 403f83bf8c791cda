"""Every planner service (the paper's and the baselines') joins a track list with the
scan of its stamp through :class:`StampJoin`: decided at once when the scan is in,
else held (one at most) until its scan comes, until ``scan_wait`` has passed, or until
a newer track list overtakes it; only the latest few scans are kept."""

from __future__ import annotations

import asyncio
import math

import numpy as np
import pytest

from tests.service.harness import Harness, planner
from zenav.schemas import keys
from zenav.schemas.messages import LaserScan, Odometry, Pose2D, TrackList, VelocityCommand
from zenav.services.node import StampJoin
from zenav.services.runner import PLANNERS

POSE = Pose2D(x=2.0, y=5.0, heading=0.0)


def scan(t: float) -> LaserScan:
    return LaserScan(stamp=t, seq=0, frame="laser", angle_min=-math.pi / 2,
                     angle_max=math.pi / 2, angle_increment=math.radians(0.5), range_min=0.05,
                     range_max=8.0, ranges=np.full(361, 8.0, dtype=np.float32))


def send_scan(h: Harness, t: float) -> None:
    """The scan of ``t`` and the odometry of that tick, as the simulator sends them (a
    baseline's instant needs both; the paper planner's join takes the scan alone)."""
    h.send(keys.ODOM, Odometry(stamp=t, seq=0, pose=POSE, v=0.0, omega=0.0))
    h.send(keys.SCAN, scan(t))


def tracks(t: float) -> TrackList:
    return TrackList(stamp=t, seq=0, pose=POSE, tracks=[])


def answered(h: Harness) -> list[float]:
    return [c.stamp for c in h.received(keys.CMD_VEL, VelocityCommand)]


@pytest.mark.parametrize("name", sorted(PLANNERS))
async def test_every_planner_joins_a_track_list_with_the_scan_of_its_stamp(name: str) -> None:
    async with planner(name) as h:
        assert isinstance(h.service.join, StampJoin)
        send_scan(h, 0.0)
        await h.settle()
        h.send(keys.TRACKS, tracks(0.0))  # its scan is in: decided at once
        await h.settle()
        assert answered(h) == [0.0]
        h.send(keys.TRACKS, tracks(0.1))  # its scan is not: held
        await h.settle()
        assert answered(h) == [0.0]
        assert h.service.join.pending is not None and h.service.join.pending.stamp == 0.1
        send_scan(h, 0.1)  # and decided the moment it comes
        await h.settle()
        assert answered(h) == [0.0, 0.1]
        assert h.service.join.pending is None


@pytest.mark.parametrize("name", sorted(PLANNERS))
async def test_a_held_track_list_is_decided_when_overtaken_or_after_the_wait(
        name: str) -> None:
    async with planner(name, scan_wait=0.05) as h:
        h.send(keys.TRACKS, tracks(0.1))
        await h.settle()
        h.send(keys.TRACKS, tracks(0.2))  # overtakes 0.1, whose scan never came
        await h.settle()
        assert answered(h) == [0.1]
        await asyncio.sleep(0.15)  # 0.2's scan does not come within scan_wait either
        await h.settle()
        assert answered(h) == [0.1, 0.2]
        send_scan(h, 0.2)  # too late: nothing more to decide
        await h.settle()
        assert answered(h) == [0.1, 0.2]


@pytest.mark.parametrize("name", sorted(PLANNERS))
async def test_only_the_latest_scans_are_kept(name: str) -> None:
    async with planner(name) as h:
        for k in range(12):
            send_scan(h, round(0.1 * k, 6))
            await h.settle()
        kept = sorted(h.service.join.companions)
        assert kept == [round(0.1 * k, 6) for k in range(12 - h.service.join.kept, 12)]
        h.send(keys.TRACKS, tracks(0.0))  # its scan is no longer kept: held for it
        await h.settle()
        assert answered(h) == []
        h.send(keys.TRACKS, tracks(1.1))  # overtaken; 1.1's scan is kept: both decided
        await h.settle()
        assert answered(h) == [0.0, 1.1]
