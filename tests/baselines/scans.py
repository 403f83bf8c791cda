"""Scans for the baselines' tests: the simulator's ray casting on small worlds."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from zenav.services.baselines.common import Cycle, Obstacles
from zenav.sim.raycast import simulate_scan
from zenav.sim.scenario import parse_scenario
from zenav.sim.world import World

ANGLES = np.radians(np.linspace(-90.0, 90.0, 361))
RANGE_MAX = 8.0


def world(*obstacles: dict[str, Any]) -> World:
    data = {"name": "test", "world": {"size": [20.0, 20.0], "cell": 0.5},
            "robot": {"start": [1.0, 1.0], "goal": [2.0, 2.0], "speed": 0.1, "radius": 0.2},
            "obstacles": list(obstacles)}
    return World.from_scenario(parse_scenario(data, "<test>"))


def cycle(w: World, pose: tuple[float, float, float], goal: tuple[float, float],
          velocity: tuple[float, float] = (0.0, 0.0), t: float = 0.0,
          movers: Obstacles | None = None) -> Cycle:
    ranges = simulate_scan(pose[:2], pose[2], ANGLES, w.snapshot(t), RANGE_MAX, 0.0,
                           np.random.default_rng(0))
    return Cycle(ranges=np.asarray(ranges, dtype=np.float64), angles=ANGLES, range_max=RANGE_MAX,
                 pose=pose, velocity=velocity, goal=goal,
                 movers=movers if movers is not None else Obstacles())


def drive(pose: tuple[float, float, float], v: float, omega: float,
          dt: float = 0.1) -> tuple[float, float, float]:
    x, y, heading = pose
    return (x + v * math.cos(heading) * dt, y + v * math.sin(heading) * dt, heading + omega * dt)
