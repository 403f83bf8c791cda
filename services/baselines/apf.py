"""Artificial potential field (APF) (pure, no I/O).

O. Khatib, "Real-Time Obstacle Avoidance for Manipulators and Mobile Robots",
The International Journal of Robotics Research 5(1), 90–98, 1986.

The robot follows the negative gradient of a potential:

- **attractive**, ``U_att = ½ k_att ρ_goal²``: a pull ``k_att · (goal − x)``,
  proportional to the distance (beyond ``d_star`` the potential is conic, so the pull
  stays at ``k_att · d_star``: the usual bound, so far goals do not swamp obstacles);
- **repulsive** from each obstacle within its influence distance ``d0`` (Khatib's ρ0),
  ``U_rep = ½ k_rep (1/ρ − 1/ρ0)²``: a push ``k_rep (1/ρ − 1/ρ0) / ρ²`` away from the
  obstacle's closest point, ρ the gap between that point and the footprint. Obstacles are
  the scan's returns cut into segments at range jumps of more than ``segment_gap``
  (Khatib's per-obstacle closest point), plus the standing obstacles the tracker
  remembers out of the 180° field of view (the closest point of each track's disc).

The force is read as a velocity: the robot turns toward it (turn rate proportional to the
angle, ``heading_gain``) and drives at ``min(V_R, |F|) · max(0, cos angle)``. Like the
original, the field knows nothing of motion: movers push as they are seen, and where the
pushes cancel the pull the robot stops (the method's local minima).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from zenav.services.baselines.common import (
    Cycle,
    FloatArray,
    returns,
    world_points,
)
from zenav.services.baselines.params import APFParams
from zenav.services.geometry import wrap_angle

Params = APFParams
"""The parameters (also read as ``apf.Params`` by zenav/bench/compute.py)."""


@dataclass(frozen=True)
class Decision:
    v: float
    omega: float
    force: tuple[float, float]  # total, m/s
    repulsive: tuple[float, float]  # sum of the pushes, m/s
    obstacles: int  # segments within d0


def closest_points(points: FloatArray, robot: FloatArray, gap: float) -> FloatArray:
    """The closest point to ``robot`` of each run of ``points`` (in beam order) whose
    neighbours are within ``gap`` of each other."""
    if len(points) == 0:
        return points
    breaks = np.hypot(*np.diff(points, axis=0).T) > gap
    segment = np.concatenate(([0], np.cumsum(breaks)))
    d = np.hypot(points[:, 0] - robot[0], points[:, 1] - robot[1])
    order = np.lexsort((d, segment))
    first = np.concatenate(([True], segment[order][1:] != segment[order][:-1]))
    return points[order[first]]


def forces(cycle: Cycle, p: Params) -> tuple[FloatArray, FloatArray, int]:
    """Attractive and total repulsive force at the robot, and the obstacles that push."""
    x, y, _ = cycle.pose
    robot = np.array([x, y])
    to_goal = np.asarray(cycle.goal, dtype=np.float64) - robot
    distance = float(np.hypot(*to_goal))
    attract = p.k_att * to_goal * (1.0 if distance <= p.d_star else p.d_star / distance)
    points = world_points(cycle, returns(cycle, p.window_radius))
    near = closest_points(points, robot, p.segment_gap)
    kept = cycle.remembered  # standing obstacles out of view, as the tracker keeps them
    if len(kept):
        off = robot - kept.positions
        centre_gap = np.maximum(np.hypot(off[:, 0], off[:, 1]), 1e-9)
        rim = kept.positions + off * (np.minimum(kept.radii, centre_gap) / centre_gap)[:, None]
        near = np.concatenate((near, rim))
    away = robot - near
    centre = np.hypot(away[:, 0], away[:, 1])
    rho = np.maximum(centre - p.robot_radius, p.min_gap)
    inside = rho < p.d0
    magnitude = p.k_rep * (1.0 / rho[inside] - 1.0 / p.d0) / rho[inside] ** 2
    unit = away[inside] / np.maximum(centre[inside], 1e-9)[:, None]
    repulse = (magnitude[:, None] * unit).sum(axis=0) if inside.any() else np.zeros(2)
    return attract, repulse, int(inside.sum())


class APF:
    """Stateless apart from its parameters: the field at the robot, each scan."""

    def __init__(self, params: Params) -> None:
        self.p = params

    def step(self, cycle: Cycle) -> Decision:
        p = self.p
        attract, repulse, count = forces(cycle, p)
        total = attract + repulse
        size = float(np.hypot(*total))
        if size < 1e-9:
            return Decision(0.0, 0.0, (0.0, 0.0), (float(repulse[0]), float(repulse[1])), count)
        angle = wrap_angle(math.atan2(total[1], total[0]) - cycle.pose[2])
        omega = max(-p.max_omega, min(p.max_omega, p.heading_gain * angle))
        v = min(p.cruise_speed, size) * max(0.0, math.cos(angle))
        return Decision(v, omega, (float(total[0]), float(total[1])),
                        (float(repulse[0]), float(repulse[1])), count)
