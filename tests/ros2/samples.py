"""zenav messages used as samples by the ROS 2 tests."""

from __future__ import annotations

import math

import numpy as np

from zenav.schemas.messages import LaserScan, Odometry, PlannerState, Pose2D, Track, TrackList


def scan(stamp: float = 12.5) -> LaserScan:
    ranges = np.linspace(0.5, 8.0, 361, dtype=np.float32)
    ranges[10] = 8.0  # no return
    return LaserScan(stamp=stamp, seq=3, frame="laser", angle_min=-math.pi / 2,
                     angle_max=math.pi / 2, angle_increment=math.radians(0.5), scan_time=0.1,
                     range_min=0.0, range_max=8.0, ranges=ranges)


def odometry(stamp: float = 12.5) -> Odometry:
    return Odometry(stamp=stamp, seq=4, pose=Pose2D(x=1.25, y=-0.5, heading=2.0), v=0.3,
                    omega=-0.4)


def track(ident: int, kind: str = "dynamic", vx: float = 0.4, vy: float = 0.3) -> Track:
    speed = math.hypot(vx, vy)
    return Track(id=ident, kind=kind, x=2.0 + ident, y=1.0, vx=vx, vy=vy, speed=speed,
                 heading=math.atan2(vy, vx), radius=0.3, xi=0.5, varsigma=0.7,
                 alpha_o_deg=45.0, age=5, cells=(1, 2, 3, 4), area=4)


def tracks(stamp: float = 12.5) -> TrackList:
    return TrackList(stamp=stamp, seq=0, pose=Pose2D(x=0.0, y=0.0, heading=0.0),
                     tracks=[track(1), track(2, "static", 0.0, 0.0), track(3, "new", 0.0, 0.0)])


def state(stamp: float = 12.5) -> PlannerState:
    return PlannerState(stamp=stamp, seq=0, scenario="c", action="slow", target=(3.0, 4.0),
                        speed=0.1)
