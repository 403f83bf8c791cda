"""A mover that leaves the laser's view while the robot turns away, and comes back
where its walk has taken it, is the same mover: its id, velocity and type come back."""

from __future__ import annotations

import math

import numpy as np
import pytest

from zenav.schemas.messages import LaserScan
from zenav.services.perception.params import PerceptionParams
from zenav.services.perception.perceive import Perceiver
from zenav.services.tracking.params import TrackingParams
from zenav.services.tracking.tracker import Track, Tracker
from zenav.sim.raycast import simulate_scan
from zenav.sim.world import WorldSnapshot

ANGLES = -math.pi / 2 + math.radians(0.5) * np.arange(361)
DT = 0.1


def walker_tracks(params: TrackingParams, away: tuple[float, float],
                  seconds: float = 9.0) -> list[tuple[float, Track | None]]:
    """The robot stands at the origin facing +x, except between ``away`` (s), when it
    faces -x; a 0.25 m disc walks from (2.5, -1.5) along +y at 0.3 m/s. (t, the track
    at the walker, if any) per scan through perception and tracking."""
    perceiver = Perceiver(PerceptionParams())
    tracker = Tracker(params)
    rng = np.random.default_rng(5)
    out: list[tuple[float, Track | None]] = []
    for i in range(round(seconds / DT)):
        t = i * DT
        heading = math.pi if away[0] <= t < away[1] else 0.0
        pose = (0.0, 0.0, heading)
        walker = (2.5, -1.5 + 0.3 * t)
        ranges = simulate_scan(pose[:2], heading, ANGLES,
                               WorldSnapshot.build(discs=[(*walker, 0.25)]), 8.0, 0.01, rng)
        scan = LaserScan(stamp=t, seq=i, frame="laser", angle_min=-math.pi / 2,
                         angle_max=math.pi / 2, angle_increment=math.radians(0.5),
                         range_min=0.0, range_max=8.0, ranges=ranges)
        tracks = tracker.update(t, pose, perceiver.process(scan, pose))
        near = [tr for tr in tracks if tr.visible
                and math.hypot(tr.x - walker[0], tr.y - walker[1]) < 0.5]
        out.append((t, near[0] if near else None))
    return out


@pytest.mark.parametrize("reacquire", [6.0, 0.0])
def test_a_walker_back_in_view_is_the_same_mover_at_once(reacquire: float) -> None:
    frames = walker_tracks(TrackingParams(reacquire=reacquire), away=(3.0, 6.0))
    before = [tr for t, tr in frames if 2.0 <= t < 3.0]
    assert before and all(tr is not None and tr.kind == "dynamic" for tr in before)
    assert all(tr is None for t, tr in frames if 4.5 <= t < 6.0)  # behind the robot
    back = next(tr for t, tr in frames if t >= 6.0 and tr is not None)
    first = before[-1]
    assert first is not None
    if reacquire:
        assert back.id == first.id
        assert back.kind == "dynamic"
        assert math.hypot(back.vx - 0.0, back.vy - 0.3) < 0.15
    else:  # the paper's way: an obstacle first seen is new
        assert back.id != first.id
        assert back.kind == "new"


def test_a_mover_lost_too_long_ago_is_not_taken_back() -> None:
    frames = walker_tracks(TrackingParams(reacquire=2.0), away=(3.0, 6.5), seconds=8.0)
    first = next(tr for t, tr in frames if 2.0 <= t < 3.0 and tr is not None)
    back = next(tr for t, tr in frames if t >= 6.5 and tr is not None)
    assert back.id != first.id and back.kind == "new"
