"""Collision prediction and the paper's eight scenarios (Section 3.4), pure geometry.

The robot is assumed to go on straight toward its current target at its cruise speed;
each obstacle at its tracked velocity. For every obstacle in the window this finds
whether their footprints (robot radius + obstacle radius + a safety margin) would
meet, where the two paths cross (the potential collision point, PCP), when each would
get there, and which of the paper's scenarios it is:

- (b) a static obstacle on the path;
- (c) a crosser that passes the PCP before the robot arrives;
- (d) a crosser that arrives after the robot has passed;
- (e) a crosser that would meet the robot at the PCP (by ``meet_rule``, below);
- (f) a mover coming head-on along the path;
- (g) a slower mover ahead going the same way.

(a) is the absence of all of these and (h) more than one threat at once; both are
decided by the caller, which sees every obstacle.

When a crosser is a threat (e) is the planner's ``meet_rule``:

- ``closest`` (zenav's default, beyond the paper): the two footprints would come within
  the clearance of each other within the horizon, wherever that happens;
- ``same_time`` (the paper's): "the robot and the obstacle arrive at the crossing point
  at the same time". The paper gives no width to "the same time"; here each of the two
  is *at* the PCP while its centre is within the clearance (robot radius + obstacle
  radius + margin) of it, which takes 2 clearance / speed, and they arrive at the same
  time when those two intervals overlap from now on (:func:`at_the_pcp_together`). The
  width thus follows from the footprints and the speeds, with no constant of its own:
  a slow robot holds the crossing longer. The paper bounds the prediction by its window
  only, so this rule has no horizon: a crosser in the window that will be at the PCP
  with the robot is (e) however far ahead that is.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
import numpy.typing as npt

from zenav.schemas.messages import ObstacleKind, ScenarioLetter
from zenav.services.planner._loops import box_gaps, c_hypot, fused_dot, mover_numbers

MeetRule = Literal["closest", "same_time"]
"""How a crosser is found to meet the robot (e); see the module notes."""

Vec = npt.NDArray[np.float64]
Point = tuple[float, float]


@dataclass(frozen=True)
class Obstacle:
    """What the planner knows of one tracked obstacle (global frame, m and m/s)."""

    id: int
    kind: ObstacleKind
    position: tuple[float, float]
    velocity: tuple[float, float]
    radius: float
    cells: tuple[int, int, int, int]  # grid box ix_min, ix_max, iy_min, iy_max (Eq. 6)


@dataclass(frozen=True)
class Assessment:
    """How one obstacle relates to the robot's intended motion."""

    obstacle: Obstacle
    letter: ScenarioLetter  # "b".."g"
    threat: bool  # the footprints would meet if nothing changes
    pcp: tuple[float, float]  # potential collision point (b: nearest point of the path)
    robot_distance: float  # along the robot's path to the PCP, m
    robot_time: float  # robot at the PCP at cruise speed, s
    obstacle_time: float  # obstacle at the PCP, s (inf for a static one)
    min_gap: float  # smallest predicted distance between centres minus clearance, m
    along: float  # obstacle centre ahead of the robot along its path, m
    along_speed: float  # obstacle velocity along the robot's path, m/s
    direction: tuple[float, float]  # the robot's path, unit vector


def closest_approach(rel_pos: Sequence[float], rel_vel: Sequence[float], speed2: float,
                     toward: float, t_max: float) -> tuple[float, float]:
    """(time, distance) of the smallest |rel_pos + rel_vel t| for t in [0, t_max], from
    the two vectors as numbers and the dot products ``speed2`` = rel_vel . rel_vel and
    ``toward`` = rel_pos . rel_vel."""
    t = 0.0 if speed2 < 1e-12 else min(max(-toward / speed2, 0.0), t_max)
    return t, c_hypot(rel_pos[0] + rel_vel[0] * t, rel_pos[1] + rel_vel[1] * t)


def at_the_pcp_together(robot_distance: float, obstacle_distance: float, robot_speed: float,
                        obstacle_speed: float, clearance: float, path_length: float) -> bool:
    """The paper's (e): robot and obstacle at the PCP at the same time.

    ``robot_distance`` and ``obstacle_distance``: how far each centre has to go along its
    own path to the PCP (m, negative once past it). Each is at the PCP while within
    ``clearance`` of it: the robot from (s - c) / v_R to (s + c) / v_R, the obstacle from
    (q - c) / v_O to (q + c) / v_O (s from now). They meet when the two intervals overlap
    after now, and the robot's path (``path_length`` m) reaches within the clearance of
    the PCP. Touching intervals do not overlap (as the footprints that only touch do not
    meet under ``closest``)."""
    if robot_speed <= 0.0 or obstacle_speed <= 0.0 or robot_distance - clearance >= path_length:
        return False
    start = max((robot_distance - clearance) / robot_speed,
                (obstacle_distance - clearance) / obstacle_speed, 0.0)
    end = min((robot_distance + clearance) / robot_speed,
              (obstacle_distance + clearance) / obstacle_speed)
    return start < end


def cell_squares(cells: tuple[int, int, int, int], cell: float) -> tuple[Vec, Vec]:
    """Lower-left and upper-right corners (m) of a grid box; cell i spans
    [(i - 1/2) r, (i + 1/2) r] because Eq. 2 rounds x / r to the nearest integer."""
    ix0, ix1, iy0, iy1 = cells
    lo = np.array([(ix0 - 0.5) * cell, (iy0 - 0.5) * cell])
    hi = np.array([(ix1 + 0.5) * cell, (iy1 + 0.5) * cell])
    return lo, hi


def gap_to_boxes(points: Vec, lows: Vec, highs: Vec) -> Vec:
    """(n,) distance from each point (n, 2) to the nearest of the boxes (m, 2)+(m, 2)."""
    if len(lows) == 0:
        return np.full(len(points), np.inf)
    below = lows[None, :, :] - points[:, None, :]
    above = points[:, None, :] - highs[None, :, :]
    outside = np.maximum(np.maximum(below, above), 0.0)
    return np.asarray(np.hypot(outside[..., 0], outside[..., 1]).min(axis=1), dtype=np.float64)


def path_count(length: float, step: float) -> int:
    """How many points :func:`path_points` puts along ``length`` m every ``step`` m."""
    return max(2, math.ceil(length / step) + 1)


def path_points(start: Vec, direction: Vec, length: float, step: float) -> Vec:
    """Points every ``step`` m along a straight path, both ends included. (The compiled
    loops ``_loops.box_gaps`` and ``_loops.line_any`` make the same points themselves.)"""
    s = np.linspace(0.0, length, path_count(length, step))
    return start[None, :] + s[:, None] * direction[None, :]


def line_crossing(d: Point, rel: Point, u: Point) -> tuple[float, float] | None:
    """(s, q) with d s = rel + u q for unit directions d, u: where the line from a point
    along ``d`` crosses the line along ``u`` from ``rel`` (relative to that point); None
    when parallel."""
    det = d[0] * (-u[1]) + u[0] * d[1]
    if abs(det) < 1e-9:
        return None
    s = (rel[0] * (-u[1]) + u[0] * rel[1]) / det
    q = (d[0] * rel[1] - d[1] * rel[0]) / det
    return s, q


def _on_the_path(robot: Point, direction: Point, speed: float, path_length: float,
                 obstacle: Obstacle, first: int, least: float, count: int) -> Assessment:
    """(b) for a standing obstacle on the path, from the gaps (m, clearance taken off)
    between its grid area and each of the ``count`` points along the path: ``first``,
    the index of the first negative one, and ``least``, the smallest."""
    (rx, ry), (dx, dy) = robot, direction
    along = fused_dot(obstacle.position[0] - rx, obstacle.position[1] - ry, dx, dy)
    s_hit = first * path_length / (count - 1)
    centre_s = min(max(along, 0.0), path_length)
    return Assessment(obstacle, "b", True, (rx + dx * centre_s, ry + dy * centre_s), s_hit,
                      s_hit / speed if speed > 0 else math.inf, math.inf, least, along, 0.0,
                      (dx, dy))


def _mover(robot: Point, heading: Point, speed: float, path_length: float,
           obstacle: Obstacle, rel: Point, along: float, along_speed: float,
           obstacle_speed: float, closest: tuple[float, float], clearance: float, *,
           head_on_cos: float, same_way_cos: float, meet_rule: MeetRule,
           following: bool) -> Assessment | None:
    """(c) to (g) for a moving obstacle, from its numbers: ``rel`` its centre from the
    robot, ``along`` and ``along_speed`` the components of that and of its velocity
    along the robot's path (``heading``, unit), its speed, and the (time, distance) of
    the closest approach of the two centres; see :func:`assess`."""
    t_min, d_min = closest
    threat = d_min < clearance
    gap = d_min - clearance
    cos_phi = along_speed / obstacle_speed
    (rx, ry), (dx, dy) = robot, heading

    if following and cos_phi >= same_way_cos and along > 0:
        threat = threat or abs(rel[0] * dy - rel[1] * dx) < clearance
    if cos_phi <= head_on_cos or cos_phi >= same_way_cos:
        if not threat or along <= 0:
            return None
        letter: ScenarioLetter = "f" if cos_phi <= head_on_cos else "g"
        return Assessment(obstacle, letter, True,
                          (rx + dx * speed * t_min, ry + dy * speed * t_min),
                          speed * t_min, t_min, t_min, gap, along, along_speed, heading)

    vx, vy = obstacle.velocity
    crossing = line_crossing(heading, rel, (vx / obstacle_speed, vy / obstacle_speed))
    if crossing is None:
        return None
    s, q = crossing
    robot_time = s / speed if speed > 0 else math.inf
    obstacle_time = q / obstacle_speed
    pcp_xy = (rx + dx * s, ry + dy * s)
    if meet_rule == "same_time":
        threat = at_the_pcp_together(s, q, speed, obstacle_speed, clearance, path_length)
    if threat:
        return Assessment(obstacle, "e", True, pcp_xy, s, robot_time, obstacle_time, gap, along,
                          along_speed, heading)
    if s <= 0 or s > path_length + clearance or q < -clearance:
        return None  # the paths cross behind the robot, beyond its path, or already behind
    passing: ScenarioLetter = "c" if obstacle_time < robot_time else "d"
    return Assessment(obstacle, passing, False, pcp_xy, s, robot_time, obstacle_time, gap, along,
                      along_speed, heading)


def assess_all(
    robot: Vec,
    direction: Vec,
    speed: float,
    path_length: float,
    obstacles: list[Obstacle],
    margins: list[float],
    horizons: list[float],
    following: list[bool],
    *,
    robot_radius: float,
    cell: float,
    moving_speed: float,
    head_on_cos: float,
    same_way_cos: float,
    meet_rule: MeetRule,
) -> list[Assessment]:
    """:func:`assess` for every obstacle (``margins``, ``horizons`` and ``following`` one
    per obstacle), the ones with something to do with the path, in order (``assess`` is
    this for one obstacle; each answer is the one it gets alone, to the last bit). The standing
    obstacles are measured against the path all at once: the path's points
    (:func:`path_points`) and every grid area's gaps in one compiled loop
    (``_loops.box_gaps``). Each mover's vectors and dot products are one compiled
    call (``_loops.mover_numbers``); the rest is arithmetic on plain numbers."""
    speeds = [c_hypot(*ob.velocity) for ob in obstacles]
    standing = [i for i, ob in enumerate(obstacles)
                if ob.kind != "dynamic" or speeds[i] < moving_speed]
    found: list[Assessment | None] = [None] * len(obstacles)
    rx, ry = float(robot[0]), float(robot[1])
    dx, dy = float(direction[0]), float(direction[1])
    if standing:
        count = path_count(path_length, cell / 4)
        first = np.empty(len(standing), dtype=np.int64)
        least = np.empty(len(standing), dtype=np.float64)
        box_gaps(rx, ry, dx, dy, path_length, count,
                 np.array([obstacles[i].cells for i in standing], dtype=np.int64), cell,
                 np.array([robot_radius + margins[i] for i in standing], dtype=np.float64),
                 first, least)
        for i, hit, smallest in zip(standing, first.tolist(), least.tolist(), strict=True):
            if hit >= 0:
                found[i] = _on_the_path((rx, ry), (dx, dy), speed, path_length, obstacles[i],
                                        hit, smallest, count)
    if len(standing) < len(obstacles):
        still = set(standing)
        for i, ob in enumerate(obstacles):
            if i in still:
                continue
            (px, py), (vx, vy) = ob.position, ob.velocity
            relx, rely, wx, wy, along, along_speed, speed2, toward = mover_numbers(
                px, py, vx, vy, rx, ry, dx, dy, speed)
            t_path = min(horizons[i], path_length / speed) if speed > 0 else horizons[i]
            found[i] = _mover(
                (rx, ry), (dx, dy), speed, path_length, ob, (relx, rely), along,
                along_speed, speeds[i],
                closest_approach((relx, rely), (wx, wy), speed2, toward, t_path),
                robot_radius + ob.radius + margins[i], head_on_cos=head_on_cos,
                same_way_cos=same_way_cos, meet_rule=meet_rule, following=following[i])
    return [a for a in found if a is not None]


def assess(
    robot: Vec,
    direction: Vec,
    speed: float,
    path_length: float,
    obstacle: Obstacle,
    *,
    robot_radius: float,
    margin: float,
    cell: float,
    horizon: float,
    moving_speed: float,
    head_on_cos: float,
    same_way_cos: float,
    meet_rule: MeetRule,
    following: bool = False,
) -> Assessment | None:
    """Classify one obstacle against the robot going ``direction`` (unit) at ``speed``
    for ``path_length`` m; None when it has nothing to do with the robot's path.

    ``meet_rule``: what makes a crosser a threat (e), see the module notes; the head-on
    (f) and same-way (g) movers are threats by the closest approach under both rules.

    ``following``: the robot already follows this obstacle (g); it stays a threat while
    it is ahead in the robot's lane, however slowly the robot now closes in."""
    found = assess_all(robot, direction, speed, path_length, [obstacle], [margin], [horizon],
                       [following], robot_radius=robot_radius, cell=cell,
                       moving_speed=moving_speed, head_on_cos=head_on_cos,
                       same_way_cos=same_way_cos, meet_rule=meet_rule)
    return found[0] if found else None
