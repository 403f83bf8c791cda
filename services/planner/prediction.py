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
from dataclasses import dataclass
from typing import Literal

import numpy as np
import numpy.typing as npt

from zenav.schemas.messages import ObstacleKind, ScenarioLetter
from zenav.services.planner._loops import box_gaps

MeetRule = Literal["closest", "same_time"]
"""How a crosser is found to meet the robot (e); see the module notes."""

Vec = npt.NDArray[np.float64]


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


def closest_approach(rel_pos: Vec, rel_vel: Vec, t_max: float) -> tuple[float, float]:
    """(time, distance) of the smallest |rel_pos + rel_vel t| for t in [0, t_max]."""
    speed2 = float(rel_vel @ rel_vel)
    t = 0.0 if speed2 < 1e-12 else min(max(-float(rel_pos @ rel_vel) / speed2, 0.0), t_max)
    return t, float(np.hypot(*(rel_pos + rel_vel * t)))


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


def path_points(start: Vec, direction: Vec, length: float, step: float) -> Vec:
    """Points every ``step`` m along a straight path, both ends included."""
    count = max(2, math.ceil(length / step) + 1)
    s = np.linspace(0.0, length, count)
    return start[None, :] + s[:, None] * direction[None, :]


def line_crossing(p: Vec, d: Vec, c: Vec, u: Vec) -> tuple[float, float] | None:
    """(s, q) with p + d s = c + u q for unit directions d, u; None when parallel."""
    det = d[0] * (-u[1]) + u[0] * d[1]
    if abs(det) < 1e-9:
        return None
    rhs = c - p
    s = (rhs[0] * (-u[1]) + u[0] * rhs[1]) / det
    q = (d[0] * rhs[1] - d[1] * rhs[0]) / det
    return float(s), float(q)


def _on_the_path(robot: Vec, direction: Vec, speed: float, path_length: float,
                 obstacle: Obstacle, first: int, least: float, count: int) -> Assessment | None:
    """(b) for a standing obstacle, from the gaps (m, clearance taken off) between its grid
    area and each of the ``count`` points along the path: ``first``, the index of the
    first negative one (-1: none, then None), and ``least``, the smallest."""
    if first < 0:
        return None
    along = float((np.asarray(obstacle.position, dtype=np.float64) - robot) @ direction)
    s_hit = first * path_length / (count - 1)
    centre_s = min(max(along, 0.0), path_length)
    rx, ry = robot.tolist()
    dx, dy = direction.tolist()
    return Assessment(obstacle, "b", True, (rx + dx * centre_s, ry + dy * centre_s), s_hit,
                      s_hit / speed if speed > 0 else math.inf, math.inf, least, along, 0.0,
                      (dx, dy))


def _moving(obstacle: Obstacle, moving_speed: float) -> bool:
    return obstacle.kind == "dynamic" and float(np.hypot(*obstacle.velocity)) >= moving_speed


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
    per obstacle), the ones with something to do with the path, in order. The standing
    obstacles are measured against the path all at once: one set of path points, every
    grid area's gaps in one compiled loop (``_loops.box_gaps``: element by element the
    same arithmetic as :func:`assess`, so the same answers to the last bit)."""
    standing = [i for i, ob in enumerate(obstacles) if not _moving(ob, moving_speed)]
    on_path: dict[int, tuple[int, float]] = {}  # standing obstacles: (first, least) gap
    count = 0
    if standing:
        points = path_points(robot, direction, path_length, cell / 4)
        count = len(points)
        first = np.empty(len(standing), dtype=np.int64)
        least = np.empty(len(standing), dtype=np.float64)
        box_gaps(points, np.array([obstacles[i].cells for i in standing], dtype=np.int64),
                 cell, np.array([robot_radius + margins[i] for i in standing],
                                dtype=np.float64), first, least)
        on_path = dict(zip(standing, zip(first.tolist(), least.tolist(), strict=True),
                           strict=True))
    found = []
    for i, ob in enumerate(obstacles):
        if i in on_path:
            a = _on_the_path(robot, direction, speed, path_length, ob, *on_path[i], count)
        else:
            a = assess(robot, direction, speed, path_length, ob, robot_radius=robot_radius,
                       margin=margins[i], cell=cell, horizon=horizons[i],
                       moving_speed=moving_speed, head_on_cos=head_on_cos,
                       same_way_cos=same_way_cos, meet_rule=meet_rule,
                       following=following[i])
        if a is not None:
            found.append(a)
    return found


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
    c = np.asarray(obstacle.position, dtype=np.float64)
    w = np.asarray(obstacle.velocity, dtype=np.float64)
    rel = c - robot
    along = float(rel @ direction)
    heading = (float(direction[0]), float(direction[1]))
    obstacle_speed = float(np.hypot(*w))
    clearance = robot_radius + obstacle.radius + margin
    moving = obstacle.kind == "dynamic" and obstacle_speed >= moving_speed

    if not moving:
        # (b): does the path come within the clearance of the obstacle's grid area S_k?
        lo, hi = cell_squares(obstacle.cells, cell)
        points = path_points(robot, direction, path_length, cell / 4)
        gaps = gap_to_boxes(points, lo[None, :], hi[None, :]) - (robot_radius + margin)
        negative = gaps < 0
        first = int(np.argmax(negative)) if negative.any() else -1
        return _on_the_path(robot, direction, speed, path_length, obstacle, first,
                            float(gaps.min()), len(gaps))

    t_path = min(horizon, path_length / speed) if speed > 0 else horizon
    t_min, d_min = closest_approach(rel, w - direction * speed, t_path)
    threat = d_min < clearance
    gap = d_min - clearance
    along_speed = float(w @ direction)
    cos_phi = along_speed / obstacle_speed
    u = w / obstacle_speed

    if following and cos_phi >= same_way_cos and along > 0:
        threat = threat or abs(float(rel[0] * direction[1] - rel[1] * direction[0])) < clearance
    if cos_phi <= head_on_cos or cos_phi >= same_way_cos:
        if not threat or along <= 0:
            return None
        letter: ScenarioLetter = "f" if cos_phi <= head_on_cos else "g"
        meet = robot + direction * speed * t_min
        return Assessment(obstacle, letter, True, (float(meet[0]), float(meet[1])),
                          speed * t_min, t_min, t_min, gap, along, along_speed, heading)

    crossing = line_crossing(robot, direction, c, u)
    if crossing is None:
        return None
    s, q = crossing
    pcp = robot + direction * s
    robot_time = s / speed if speed > 0 else math.inf
    obstacle_time = q / obstacle_speed
    pcp_xy = (float(pcp[0]), float(pcp[1]))
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
