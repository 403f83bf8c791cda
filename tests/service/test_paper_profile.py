"""Perception and tracking with the paper profile's parameters on the in-memory bus: the
decision tree over T types a mover dynamic and a standing obstacle static, and Eq. 15
gives the mover's speed."""

from __future__ import annotations

import math

import numpy as np

from tests.service.harness import running
from zenav.schemas import keys
from zenav.schemas.messages import LaserScan, ObstacleChain, Odometry, Pose2D, TrackList
from zenav.services.perception.params import PerceptionParams
from zenav.services.profiles import PAPER_COMPARE_PERIOD, profile_values
from zenav.services.tracking.params import TrackingParams

HALF_DEG = math.radians(0.5)
SPEED = 0.5  # m/s, the mover going straight away from the robot


def scan(t: float) -> LaserScan:
    """361 beams right to left; a standing arc at 2 m on the right (beams 40-60) and a
    mover straight ahead (beams 170-190) at 2 + 0.5 t m; nothing else within range."""
    r = np.full(361, 8.0, dtype=np.float32)
    r[40:61] = 2.0
    r[170:191] = 2.0 + SPEED * t
    return LaserScan(stamp=t, seq=round(t * 10), frame="laser", angle_min=-math.pi / 2,
                     angle_max=math.pi / 2, angle_increment=HALF_DEG, range_min=0.05,
                     range_max=8.0, ranges=r)


async def test_the_paper_profile_types_and_moves_by_the_tree_over_t() -> None:
    perception = PerceptionParams(**profile_values("paper", "perception"))
    tracking = TrackingParams(**profile_values("paper", "tracking"))
    frames = [round(i * 0.1, 1) for i in range(25)]
    async with running("perception", perception) as p:
        for t in frames:
            p.send(keys.ODOM, Odometry(stamp=t, seq=0, pose=Pose2D(x=0.0, y=0.0, heading=0.0),
                                       v=0.0, omega=0.0))
            p.send(keys.SCAN, scan(t))
            await p.settle()
        chains = p.received(keys.OBSTACLES, ObstacleChain)
    assert len(chains) == len(frames)
    async with running("tracking", tracking) as h:
        for chain in chains:
            h.send(keys.OBSTACLES, chain)
            await h.settle()
        lists = h.received(keys.TRACKS, TrackList)
    last = lists[-1]
    assert last.stamp >= PAPER_COMPARE_PERIOD + 1.0
    by_y = sorted(last.tracks, key=lambda tr: tr.y)  # the standing arc is on the right
    standing, mover = by_y[0], by_y[-1]
    assert standing.kind == "static"
    assert mover.kind == "dynamic"
    # Eq. 15 over T = 1 s: the Eq. 5 centre moved 0.5 m straight ahead (+x)
    assert abs(mover.speed - SPEED) < 0.02
    assert abs(mover.alpha_o_deg - 90.0) < 1.0
