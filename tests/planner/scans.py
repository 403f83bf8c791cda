"""Simulated scans of hand-made worlds for the planner's map tests."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from zenav.services.planner.costmap import ScanData
from zenav.sim.raycast import simulate_scan
from zenav.sim.world import WorldSnapshot

INC = math.radians(0.5)
Box = tuple[float, float, float, float]  # xmin, ymin, xmax, ymax
Disc = tuple[float, float, float]  # cx, cy, r


def scan_of(pose: tuple[float, float, float], boxes: Sequence[Box] = (),
            discs: Sequence[Disc] = (), fov_deg: float = 180.0, range_max: float = 8.0,
            noise: float = 0.0, seed: int = 0) -> ScanData:
    n = round(fov_deg / 0.5) + 1
    angle_min = -math.radians(fov_deg) / 2
    angles = angle_min + INC * np.arange(n)
    snap = WorldSnapshot.build(discs=list(discs), boxes=list(boxes))
    ranges = simulate_scan(pose[:2], pose[2], angles, snap, range_max, noise,
                           np.random.default_rng(seed))
    return ScanData(pose, np.asarray(ranges, dtype=np.float64), angle_min, INC, range_max)


def wall_with_gap(x: float, gap_low: float, gap_high: float, y0: float = -1.0,
                  y1: float = 9.0, thickness: float = 0.2) -> list[Box]:
    """A wall along y at ``x`` from y0 to y1 with an opening [gap_low, gap_high]."""
    return [(x - thickness / 2, y0, x + thickness / 2, gap_low),
            (x - thickness / 2, gap_high, x + thickness / 2, y1)]


def cup(x_back: float, y_mid: float, width: float, depth: float,
        thickness: float = 0.2) -> list[Box]:
    """A U open toward -x: back wall at ``x_back``, ``width`` inside, ``depth`` deep."""
    h = width / 2
    return [(x_back, y_mid - h - thickness, x_back + thickness, y_mid + h + thickness),
            (x_back - depth, y_mid + h, x_back, y_mid + h + thickness),
            (x_back - depth, y_mid - h - thickness, x_back, y_mid - h)]
