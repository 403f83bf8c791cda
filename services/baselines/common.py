"""What the three baseline planners share: the mission parameters, what one planning
cycle sees, and small geometry helpers (pure, no I/O).

A cycle sees the laser scan in the robot frame (ranges and beam angles relative to the
heading), the robot pose at scan time and its velocity, the goal, and the tracked
obstacles (positions, velocities, radii; only DWA uses the velocities): the movers, and
the standing obstacles the tracker still remembers out of the 180° field of view.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]


@dataclass(frozen=True)
class Obstacles:
    """Tracked obstacles in the world frame: (n, 2) positions and velocities, (n,) radii."""

    positions: FloatArray = field(default_factory=lambda: np.zeros((0, 2)))
    velocities: FloatArray = field(default_factory=lambda: np.zeros((0, 2)))
    radii: FloatArray = field(default_factory=lambda: np.zeros(0))

    def __len__(self) -> int:
        return int(self.radii.size)


@dataclass(frozen=True)
class Cycle:
    """Everything one planning cycle sees."""

    ranges: FloatArray  # m, one per beam
    angles: FloatArray  # rad, beam directions relative to the heading
    range_max: float  # m: a range this long is no return
    pose: tuple[float, float, float]  # x m, y m, heading rad (at scan time)
    velocity: tuple[float, float]  # v m/s, omega rad/s
    goal: tuple[float, float]  # m
    movers: Obstacles = field(default_factory=Obstacles)  # tracks that move
    remembered: Obstacles = field(default_factory=Obstacles)  # standing tracks out of view
    tracked: Obstacles = field(default_factory=Obstacles)  # every track (moving or not)


def returns(cycle: Cycle, reach: float) -> BoolArray:
    """Beams with a return within ``reach`` m."""
    return (cycle.ranges < cycle.range_max * 0.999) & (cycle.ranges <= reach)


def world_points(cycle: Cycle, mask: BoolArray) -> FloatArray:
    """The (n, 2) world points of the beams in ``mask``."""
    x, y, heading = cycle.pose
    r = cycle.ranges[mask]
    a = cycle.angles[mask] + heading
    return np.column_stack((x + r * np.cos(a), y + r * np.sin(a)))


def disc_points(obstacles: Obstacles, count: int = 16) -> FloatArray:
    """(n * count, 2) points on the rims of the obstacles' discs."""
    if len(obstacles) == 0:
        return np.zeros((0, 2))
    a = np.linspace(0.0, 2 * math.pi, count, endpoint=False)
    rim = np.column_stack((np.cos(a), np.sin(a)))
    points: FloatArray = (obstacles.positions[:, None, :]
                          + obstacles.radii[:, None, None] * rim[None]).reshape(-1, 2)
    return points


def goal_reached(cycle: Cycle, tolerance: float) -> bool:
    """Within half the goal tolerance: stop (the simulator ends the run at the tolerance)."""
    x, y, _ = cycle.pose
    return math.hypot(cycle.goal[0] - x, cycle.goal[1] - y) <= tolerance / 2
