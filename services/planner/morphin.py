"""Simplified Morphin (Section 3.5, Eq. 17): pick a straight detour on the grid.

From the robot, a centreline runs to the potential collision point (or the obstacle's
centre). Candidate paths are straight lines fanned left and right of it, each as long as
the centreline. Each candidate is scored

    y = kappa_1 |G| + kappa_2 Delta_L + kappa_3 W          (Eq. 17)

with G the angle to the centreline (rad), Delta_L the distance from the candidate's end
to the global target in cells, and W = 1 / (1 + m), m the number of grid cells the
candidate shares with the global path. A candidate that comes closer to an occupied cell
than the robot's radius plus a margin (the cell "inflated by the robot radius"), or that
would meet a moving obstacle on the way, costs infinity. The cheapest candidate's end is
the robot's sub-target.

Where the paper leaves room, the choices here are:

- "W counts grid cells both paths go through" follows the paper's worked example
  (W1 = 1/(4+1), W2 = 1/(3+1)); the cells of a segment are found by sampling it every
  cell/20 and applying Eq. 2, which finds every cell it crosses by more than that.
- Delta_L is measured to the global target (the end of the global path), so it favours
  the side that leads on.
- A robot already closer to an obstacle than the clearance (it can happen after a
  mover cut in) may still leave along a candidate that never gets closer than where it
  is; otherwise no candidate at all would be allowed.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from zenav.services.perception.clustering import grid_index
from zenav.services.planner.prediction import gap_to_boxes, path_points

Vec = npt.NDArray[np.float64]

SAMPLES_PER_CELL = 20


def cells_on_segment(a: Vec, b: Vec, cell: float) -> set[tuple[int, int]]:
    """Grid cells (Eq. 2) that the segment from ``a`` to ``b`` passes through."""
    length = float(np.hypot(*(b - a)))
    count = max(2, math.ceil(length * SAMPLES_PER_CELL / cell) + 1)
    t = np.linspace(0.0, 1.0, count)[:, None]
    points = a[None, :] + t * (b - a)[None, :]
    index = grid_index(points, cell)
    # (a set of the rows as Python ints: a tenth of the time of np.unique by rows)
    return set(zip(index[:, 0].tolist(), index[:, 1].tolist(), strict=True))


def shared_term(shared_cells: int) -> float:
    """Eq. 17's W = 1 / (1 + m), m the grid cells a candidate shares with the global path."""
    return 1.0 / (1 + shared_cells)


def morphin_cost(
    g: float, delta_l: float, w: float, kappa: tuple[float, float, float]
) -> float:
    """Eq. 17 for a candidate that crosses nothing."""
    return kappa[0] * abs(g) + kappa[1] * delta_l + kappa[2] * w


@dataclass(frozen=True)
class Mover:
    """A moving obstacle for the space-time check (m, m/s)."""

    position: Vec
    velocity: Vec
    radius: float


@dataclass(frozen=True)
class Candidate:
    g: float  # rad from the centreline, + to the left
    end: tuple[float, float]
    cost: float  # inf when blocked
    delta_l: float
    w: float
    shared_cells: int


@dataclass(frozen=True)
class Choice:
    best: Candidate | None  # None when every candidate is blocked
    candidates: list[Candidate]


def _blocked(
    points: Vec,
    times: Vec,
    boxes: tuple[Vec, Vec],
    movers: list[Mover],
    robot_radius: float,
    margin: float,
) -> bool:
    lows, highs = boxes
    need = robot_radius + margin
    if len(lows):
        gaps = gap_to_boxes(points, lows, highs)
        if (gaps < min(need, float(gaps[0]) - 1e-6)).any():
            return True
    for mover in movers:
        where = mover.position[None, :] + times[:, None] * mover.velocity[None, :]
        dist = np.hypot(*(points - where).T)
        clearance = need + mover.radius
        if (dist < min(clearance, float(dist[0]) - 1e-6)).any():
            return True
    return False


def choose_detour(
    robot: Vec,
    centre_point: Vec,
    goal: Vec,
    global_cells: set[tuple[int, int]],
    boxes: tuple[Vec, Vec],
    movers: list[Mover],
    *,
    speed: float,
    cell: float,
    robot_radius: float,
    margin: float,
    kappa: tuple[float, float, float],
    fan_step: float,
    fan_max: float,
    extra_length: float = 0.0,
    side: int = 0,
    switch_penalty: float = 0.0,
    end_cost: Callable[[Vec], float] | None = None,
    to_goal: Callable[[Vec], float] | None = None,
    crosses: Callable[[Vec], bool] | None = None,
) -> Choice:
    """Score the fan of straight candidates around the centreline robot -> centre_point.

    ``boxes`` are occupied grid areas (lower-left, upper-right corners, m); ``movers``
    are checked in space and time with the robot at ``speed`` along each candidate.
    ``side`` (+1 left, -1 right, 0 none) is the side of a detour already under way;
    candidates on the other side cost ``switch_penalty`` more, so that a re-plan does
    not swing the robot from one side of an obstacle to the other. ``end_cost`` adds a
    cost for where a candidate ends (the caller's judgement of the way on from there).
    ``to_goal`` measures Delta L (m, divided by the cell here); the paper's straight-line
    distance to ``goal`` when not given. ``crosses`` (beyond the paper): whether a
    candidate's points, the robot's position first, run through something the caller
    knows of besides ``boxes`` (the planner's map); such a candidate is blocked too.
    """
    offset = centre_point - robot
    length = float(np.hypot(*offset)) + extra_length
    heading = math.atan2(offset[1], offset[0])
    steps = round(fan_max / fan_step)
    angles = [0.0] + [sign * k * fan_step for k in range(1, steps + 1) for sign in (1, -1)]
    candidates = []
    for g in angles:
        direction = np.array([math.cos(heading + g), math.sin(heading + g)])
        end = robot + direction * length
        points = path_points(robot, direction, length, cell / 4)
        times = np.linspace(0.0, length / speed if speed > 0 else math.inf, len(points))
        shared = len(cells_on_segment(robot, end, cell) & global_cells)
        w = shared_term(shared)
        delta_l = (to_goal(end) if to_goal is not None else float(np.hypot(*(goal - end)))) / cell
        blocked = (_blocked(points, times, boxes, movers, robot_radius, margin)
                   or (crosses is not None and crosses(points)))
        cost = math.inf if blocked else morphin_cost(g, delta_l, w, kappa)
        if side and g * side < 0:
            cost += switch_penalty
        if end_cost is not None and math.isfinite(cost):
            cost += end_cost(end)
        candidates.append(Candidate(g, (float(end[0]), float(end[1])), cost, delta_l, w, shared))
    feasible = [c for c in candidates if math.isfinite(c.cost)]
    best = min(feasible, key=lambda c: (c.cost, abs(c.g), c.g)) if feasible else None
    return Choice(best, candidates)
