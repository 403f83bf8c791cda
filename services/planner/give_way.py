"""Giving way to a mover in a corridor (pure, no I/O).

Beyond the paper. The paper answers a head-on mover (f) with a Morphin detour round it.
Between two walls there is no way round: the detours turn back along the corridor, the
robot drives away from the mover at its own (lower) speed, turns its back on it and
loses it from the 180-degree laser, and the mover walks into it. A mover that comes up
from behind faster than the robot can go (seen with a wider laser) is the same: the
robot cannot outrun it, and no detour is planned for a mover behind. A person in a
corridor steps aside and lets it by. This module finds where:

- :func:`hemmed_in`: the map holds something within reach on both sides of the robot,
  square to the mover's way (a corridor, a doorway): the only case where the robot
  gives way instead of taking the paper's detour;
- :func:`spot_aside`: the nearest point within reach that is free on the map (its
  inflation included) and off the mover's way by the clearance (:func:`offsets`), which
  the robot can reach before the mover comes abreast of it. Between walls a mover walks
  along them: its way is taken along the walls (:func:`corridor_axis`: the heading the
  wall cells near the robot line up along), through where it is, not along its tracked
  heading, which is off by some degrees (7 degrees put a spot 0.2 m too near its line
  at 1.6 m); looked for again, on the same side, as the mover comes;
- :func:`passed`: the mover is behind the robot along its own way, clear by the
  clearance: the robot may go on.

The planner holds the spot, then keeps to that lane (on along it while the map leaves it
free, else standing facing the mover so the laser keeps it in view) until the mover has
passed (``Planner.hold_aside``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

Vec = npt.NDArray[np.float64]
BlockedAt = Callable[[Vec], npt.NDArray[np.bool_]]
"""The map's check: for each point (n, 2), whether the robot's centre may not be there."""


@dataclass
class Hold:
    """A spot aside the robot keeps while a mover goes by, and what it knows of the
    mover: a track's type and size flicker as it passes close to walls, so the mover is
    followed by where it was last seen moving, not by its track's latest word."""

    spot: tuple[float, float]
    side: int  # +1: the spot is to the left of the mover's walk, -1: to its right
    radius: float  # the mover's, the largest seen (a track of part of it is smaller), m
    mover: int  # the track given way to (taken over by a track where it is predicted)
    way: tuple[float, float]  # the way the mover walks (unit): along the corridor
    until: float  # stamp after which the hold is given up whatever happens, s
    position: tuple[float, float]  # where the mover is taken to be at ``at``, m
    velocity: tuple[float, float]  # how it was last seen moving, m/s
    at: float  # stamp of ``position``
    seen: float  # stamp it was last seen
    moving: float  # stamp it was last seen moving
    reached: bool = False  # the robot has been at the spot: it keeps to that side now
    overtaking: bool = False  # the mover comes from behind, the robot's way (else head-on)

    @property
    def lane(self) -> tuple[float, float]:
        """The way the robot goes on along its lane: against the mover's way for one
        coming head-on, with it for one overtaking."""
        sign = 1.0 if self.overtaking else -1.0
        return (sign * self.way[0], sign * self.way[1])

    def predicted(self, stamp: float) -> Vec:
        """Where the mover is now: from ``position``, along its way at the speed it was
        last seen moving."""
        step = float(np.hypot(*self.velocity)) * (stamp - self.at)
        return np.array([self.position[0] + self.way[0] * step,
                         self.position[1] + self.way[1] * step])

    def along(self, point: tuple[float, float]) -> tuple[float, float]:
        """``point`` moved square to the mover's way onto the line it was last seen
        walking: how far along it has come, where across it walks kept."""
        rel = (point[0] - self.position[0], point[1] - self.position[1])
        ahead = rel[0] * self.way[0] + rel[1] * self.way[1]
        return (self.position[0] + ahead * self.way[0], self.position[1] + ahead * self.way[1])


def corridor_axis(walls: Vec, resolution: float, ratio: float = 3.0) -> Vec | None:
    """The direction (unit, either way) the walls ``walls`` (n, 2 points, the map's cell
    centres) run along: the heading, to 2 degrees, across which their points bunch into
    the fewest bins of ``resolution`` m (straight walls seen edge on), when that bunching
    is at least ``ratio`` times the median heading's; None otherwise (a room, scattered
    posts, too few points)."""
    if len(walls) < 8:
        return None
    angles = np.radians(np.arange(0.0, 180.0, 2.0))
    across = walls @ np.stack([-np.sin(angles), np.cos(angles)])  # (n, angles)
    bins = np.floor((across - across.min(axis=0)) / resolution).astype(np.int64)
    score = np.array([float((np.bincount(bins[:, k]) ** 2).sum())
                      for k in range(len(angles))])
    best = int(np.argmax(score))
    if score[best] < ratio * float(np.median(score)):
        return None
    return np.array([math.cos(angles[best]), math.sin(angles[best])])


def hemmed_in(robot: Vec, way: Vec, blocked_at: BlockedAt, reach: float, step: float) -> bool:
    """Whether the map blocks a point within ``reach`` m of ``robot`` on each side, square
    to ``way`` (unit): the robot stands between walls and cannot go round a mover."""
    side = np.array([-way[1], way[0]])
    out = np.arange(step, reach + step / 2, step)
    left = robot[None, :] + out[:, None] * side[None, :]
    right = robot[None, :] - out[:, None] * side[None, :]
    return bool(blocked_at(left).any() and blocked_at(right).any())


def offsets(points: Vec, mover: Vec, way: Vec) -> Vec:
    """How far each point (n, 2) lies to the side of the line through ``mover`` along
    ``way`` (unit), signed: + to the left of the mover walking along ``way``."""
    rel = points - mover[None, :]
    return np.asarray(way[0] * rel[:, 1] - way[1] * rel[:, 0], dtype=np.float64)


def spot_aside(robot: Vec, mover: Vec, way: Vec, speed: float, clearance: float,
               side: int, blocked_at: BlockedAt, leg_clear: Callable[[Vec, Vec], bool],
               reach: float, step: float, robot_speed: float, lead: float,
               ahead: bool = False,
               backing: tuple[float, float] | None = None) -> Vec | None:
    """The nearest point within ``reach`` m of ``robot`` (on a ``step`` m grid) that is
    free on the map, at least ``clearance`` m to ``side`` (+1 left, -1 right) of the
    line the mover walks (through ``mover`` along ``way``, unit, at ``speed``), and
    reached in a straight line (``leg_clear``) at ``robot_speed`` ``lead`` s (time to
    turn) before the mover comes within the clearance of being abreast of it; None if
    none is, or if the mover does not come toward the robot. ``ahead``: only points at
    most 45 degrees off ``way`` from the robot (a mover overtaking it: the robot swerves
    on along its way, with no time for a square turn). ``backing``: the robot's heading
    (rad) and its reverse speed limit (m/s). A robot on the other side of the mover's
    line crosses in front of the mover to a spot on this side, and it backs to a spot
    behind it: such a spot is timed at no more than the reverse limit."""
    if speed < 1e-9 or robot_speed <= 0.0:
        return None
    if float((robot - mover) @ way) <= clearance:
        return None  # the mover is already beside the robot or past it
    ticks = np.arange(-reach, reach + step / 2, step)
    gx, gy = np.meshgrid(ticks, ticks, indexing="ij")
    grid = np.column_stack([gx.ravel(), gy.ravel()])
    distance = np.hypot(grid[:, 0], grid[:, 1])
    keep = distance <= reach + 1e-9
    points, distance = robot[None, :] + grid[keep], distance[keep]
    aside = offsets(points, mover, way) * side >= clearance
    along = (points - mover[None, :]) @ way
    speeds = np.full(len(points), robot_speed)
    if backing is not None and float(offsets(robot[None, :], mover, way)[0]) * side < 0.0:
        heading, reverse = backing
        behind = (points - robot[None, :]) @ np.array([math.cos(heading), math.sin(heading)]) < 0
        speeds[behind] = min(robot_speed, reverse)
    ok = aside & ((along - clearance) / speed >= distance / speeds + lead)
    if ahead:
        forward = (points - robot[None, :]) @ way
        ok &= forward >= np.abs(offsets(points, robot, way)) - 1e-9
    if not ok.any():
        return None
    ok[ok] = ~blocked_at(points[ok])
    for i in np.flatnonzero(ok)[np.argsort(distance[ok], kind="stable")][:40]:
        if leg_clear(robot, points[i]):
            return np.asarray(points[i], dtype=np.float64)
    return None


def passed(robot: Vec, mover: Vec, way: Vec, clearance: float) -> bool:
    """Whether the mover (at ``mover``, walking along ``way``, unit) is behind the robot
    along its way, clear by ``clearance``."""
    return float((mover - robot) @ way) > clearance
