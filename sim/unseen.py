"""Fresh scenes of the navigation classes that outside checks try, drawn from a seed.

Our own ``sim/scenarios/nav-*.yaml`` are one scene per class, and the planner was tuned
on them. The checks that judge it run other scenes of the same classes, so this module
draws new ones with varied geometry to find out how the planner fares on scenes nobody
looked at first:

- ``appear``: an obstacle springs up 0.8–1.5 m ahead of where the robot then is;
- ``wall-gap``: a wall across the world with one gap, off the straight line, either side;
- ``cup``: a U open toward the robot, on the line;
- ``corridor``: a walled corridor on the line with a mover inside, going the robot's way
  (a follower) or coming toward it (head-on);
- ``posts``: staggered rows of thin posts with passable but tight gaps;
- ``mover-stops``: a mover that comes across (or toward the robot) and stops on the way;
- ``facing-away``: the robot starts facing away from its goal, a box on the line.

Beyond those classes, three with walkers that react (ORCA agents, ``behavior: orca``,
each seeing the robot or not at even odds, at 0.2–0.6 m/s): the issue names its crowds
only in CrowdNav's open square, and these put them where walls leave little room:

- ``walkers-corridor``: a walled corridor on the line, 1.6–2.6 m wide inside, with one
  to three walkers going along it, each the robot's way or toward it;
- ``walkers-doorway``: a wall across the world with one door, off the straight line or on
  it, and a walker coming through it from the goal's side to the robot's;
- ``walkers-across``: two to four walkers pacing to and fro across the robot's way
  between two points either side of the line.

Each scene is drawn in a frame where the robot drives toward +x, then turned by a
multiple of 90 degrees (so boxes stay axis-aligned) and maybe mirrored, so goals lie in
every direction. A draw is kept only when :func:`solvable` finds a way for the robot
disc through the static geometry (every obstacle that ever stands still, whenever it
appears) by a flood fill on a fine grid; otherwise the next draw of the same seed is
tried. Pure: the same class and seed give the same scene.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from zenav.sim.scenario import Scenario, parse_scenario

CLASSES = ("appear", "wall-gap", "cup", "corridor", "posts", "mover-stops", "facing-away")
"""The navigation classes issue 12 names (``bench nav --families unseen``)."""
WALKER_CLASSES = ("walkers-corridor", "walkers-doorway", "walkers-across")
"""Classes with ORCA walkers between walls (``bench nav --families walkers``)."""
ALL_CLASSES = CLASSES + WALKER_CLASSES
FAMILY_PREFIX = "unseen-"  # a scene's name: unseen-<class>-<seed>
RADIUS = 0.2  # the robot disc, m
WAY_CELL = 0.025  # m: fine enough to see a gap of 2.5 robot radii
DRAWS = 50  # tries per seed before giving up

Obstacle = dict[str, Any]


def _speed(rng: np.random.Generator) -> float:
    """The paper's 0.1 m/s robot half the time, else 0.3–0.5 m/s."""
    if rng.random() < 0.5:
        return 0.1
    return round(float(rng.uniform(0.3, 0.5)), 2)


def _box(cx: float, cy: float, w: float, h: float) -> Obstacle:
    return {"shape": "box", "center": [cx, cy], "size": [w, h]}


def _disc(cx: float, cy: float, r: float, **more: Any) -> Obstacle:
    return {"shape": "disc", "center": [cx, cy], "radius": r, **more}


# --- the classes, in the frame where the robot drives toward +x -----------------------
# Each returns (world width, height, start, goal, heading offset in degrees, obstacles).

Draw = tuple[float, float, list[float], list[float], float, list[Obstacle]]


def _line(rng: np.random.Generator, width: float, height: float,
          margin: float = 1.2, slant: float = 0.6) -> tuple[list[float], list[float]]:
    y0 = float(rng.uniform(-0.15, 0.15)) * height + height / 2
    y1 = y0 + float(rng.uniform(-slant, slant))
    x0 = float(rng.uniform(margin, margin + 0.8))
    x1 = width - float(rng.uniform(margin, margin + 0.8))
    return [x0, y0], [x1, min(max(y1, 1.0), height - 1.0)]


def _appear(rng: np.random.Generator, speed: float) -> Draw:
    width, height = float(rng.uniform(9.0, 14.0)), float(rng.uniform(5.0, 9.0))
    start, goal = _line(rng, width, height, slant=0.3)
    length = math.dist(start, goal)
    unit = ((goal[0] - start[0]) / length, (goal[1] - start[1]) / length)
    ahead = float(rng.uniform(0.8, 1.5))  # from the robot's centre to the obstacle's
    travelled = float(rng.uniform(1.0, max(1.2, length - ahead - 2.0)))
    appear = round(travelled / speed, 1)  # when a robot at cruise speed has come that far
    along = travelled + ahead
    side = float(rng.uniform(-0.25, 0.25))
    cx = start[0] + unit[0] * along - unit[1] * side
    cy = start[1] + unit[1] * along + unit[0] * side
    if rng.random() < 0.6:
        w, h = float(rng.uniform(0.3, 0.8)), float(rng.uniform(0.3, 1.0))
        shape = _box(cx, cy, w, h)
    else:
        shape = _disc(cx, cy, float(rng.uniform(0.15, 0.4)))
    shape["appear"] = appear
    return width, height, start, goal, 0.0, [shape]


class WallWithGap(NamedTuple):
    """A wall across a world with one gap in it (``_wall_with_gap``)."""

    width: float  # the world's
    height: float
    start: list[float]
    goal: list[float]
    x: float  # the wall's
    gap_y: float  # the gap's middle
    low: float  # the gap's ends
    high: float

    def pieces(self, thick: float) -> list[Obstacle]:
        """The two boxes of the wall, ``thick`` m thick, either side of the gap."""
        return [_box(self.x, self.low / 2, thick, self.low),
                _box(self.x, (self.high + self.height) / 2, thick, self.height - self.high)]


def _wall_with_gap(rng: np.random.Generator, width: tuple[float, float],
                   gap: tuple[float, float], offset: tuple[float, float]) -> WallWithGap:
    """A world (of a width drawn from ``width``, 7-11 m high) with a wall across the
    start-goal line and a gap in it, of a width drawn from ``gap``, its middle off the
    line by a distance drawn from ``offset``, to either side, clear of the world's edges."""
    world_w, world_h = float(rng.uniform(*width)), float(rng.uniform(7.0, 11.0))
    start, goal = _line(rng, world_w, world_h, slant=0.8)
    wall_x = float(rng.uniform(0.4, 0.6)) * (start[0] + goal[0])
    size = float(rng.uniform(*gap))
    line_y = (start[1] + goal[1]) / 2
    off = float(rng.uniform(*offset)) * float(rng.choice([-1.0, 1.0]))
    gy = min(max(line_y + off, size / 2 + 0.3), world_h - size / 2 - 0.3)
    return WallWithGap(world_w, world_h, start, goal, wall_x, gy, gy - size / 2,
                       gy + size / 2)


def _wall_gap(rng: np.random.Generator, speed: float) -> Draw:
    w = _wall_with_gap(rng, (9.0, 16.0), (0.8, 1.4), (0.8, 2.8))
    thick = float(rng.uniform(0.15, 0.4))
    return w.width, w.height, w.start, w.goal, 0.0, w.pieces(thick)


def _cup(rng: np.random.Generator, speed: float) -> Draw:
    inner_w, depth = float(rng.uniform(1.2, 2.6)), float(rng.uniform(1.0, 2.2))
    width = float(rng.uniform(10.0, 14.0))
    height = float(rng.uniform(max(7.0, inner_w + 4.0), 10.0))
    start, goal = _line(rng, width, height, slant=0.3)
    t = 0.2
    back_x = float(rng.uniform(0.45, 0.65)) * (start[0] + goal[0])
    cy = (start[1] + goal[1]) / 2 + float(rng.uniform(-0.3, 0.3))
    arm_x = back_x - t / 2 - depth / 2
    return width, height, start, goal, 0.0, [
        _box(back_x, cy, t, inner_w + 2 * t),
        _box(arm_x, cy + inner_w / 2 + t / 2, depth, t),
        _box(arm_x, cy - inner_w / 2 - t / 2, depth, t),
    ]


class Corridor(NamedTuple):
    """A walled corridor on a straight start-goal line (``_walled_corridor``)."""

    width: float  # the world's
    height: float
    start: list[float]
    goal: list[float]
    inner: float  # m between the walls
    cy: float  # the corridor's middle line (the start's y)
    entry: float  # x of its near end
    exit: float  # x of its far end
    walls: list[Obstacle]


def _walled_corridor(rng: np.random.Generator, inner: tuple[float, float],
                     length: tuple[float, float], height: tuple[float, float]) -> Corridor:
    """A world with a corridor of walls 0.2 m thick along the start-goal line (slant 0),
    its inner width, length and the world's height drawn from the ranges given."""
    inside, long = float(rng.uniform(*inner)), float(rng.uniform(*length))
    world_w = float(rng.uniform(long + 5.0, long + 8.0))
    world_h = float(rng.uniform(*height))
    start, goal = _line(rng, world_w, world_h, slant=0.0)
    t = 0.2
    cx = (start[0] + goal[0]) / 2 + float(rng.uniform(-0.5, 0.5))
    cy = start[1]
    walls = [_box(cx, cy + inside / 2 + t / 2, long, t),
             _box(cx, cy - inside / 2 - t / 2, long, t)]
    return Corridor(world_w, world_h, start, goal, inside, cy, cx - long / 2, cx + long / 2,
                    walls)


def _corridor(rng: np.random.Generator, speed: float) -> Draw:
    c = _walled_corridor(rng, (0.9, 1.6), (3.0, 6.0), (6.0, 9.0))
    width, height, start, goal, inner, cy = c.width, c.height, c.start, c.goal, c.inner, c.cy
    entry, exit_ = c.entry, c.exit
    lateral = float(rng.uniform(-1.0, 1.0)) * max(0.0, inner / 2 - 0.3)
    obstacles = list(c.walls)
    if rng.random() < 0.5:  # a follower: going the robot's way, slower than it
        v = round(speed * float(rng.uniform(0.3, 0.8)), 3)
        mx = entry + float(rng.uniform(0.3, 1.2))
        obstacles.append(_disc(mx, cy + lateral, 0.2, velocity=[v, 0.0]))
    else:  # head-on
        v = round(float(rng.uniform(0.1, 0.5)), 3)
        mx = exit_ - float(rng.uniform(0.0, 0.8))
        appear = round(float(rng.uniform(0.0, 0.5)) * (entry - start[0]) / speed, 1)
        obstacles.append(_disc(mx, cy + lateral, 0.2, velocity=[-v, 0.0], appear=appear))
    return width, height, start, goal, 0.0, obstacles


def _posts(rng: np.random.Generator, speed: float) -> Draw:
    width, height = float(rng.uniform(10.0, 14.0)), float(rng.uniform(6.0, 9.0))
    start, goal = _line(rng, width, height, slant=0.6)
    r = float(rng.uniform(0.05, 0.15))
    gap = float(rng.uniform(2.5, 4.0)) * RADIUS  # surface to surface, nearest posts
    dy = gap + 2 * r  # in a row
    dx = math.sqrt(max((gap + 2 * r) ** 2 - (dy / 2) ** 2, 0.0)) * float(rng.uniform(1.0, 1.5))
    rows = int(rng.integers(3, 6))
    x0 = float(rng.uniform(0.35, 0.5)) * (start[0] + goal[0]) - dx
    half = float(rng.uniform(1.5, 3.0))  # the field's half-height about the line
    mid = (start[1] + goal[1]) / 2 + float(rng.uniform(-0.5, 0.5))
    phase = float(rng.uniform(0.0, dy))
    obstacles: list[Obstacle] = []
    for k in range(rows):
        x = x0 + k * dx
        y = mid - half + phase + (dy / 2 if k % 2 else 0.0)
        while y <= mid + half:
            if 0.0 < y < height and math.dist((x, y), start) > 1.0 and \
                    math.dist((x, y), goal) > 1.0:
                obstacles.append(_disc(x, y, r))
            y += dy
    return width, height, start, goal, 0.0, obstacles


def _mover_stops(rng: np.random.Generator, speed: float) -> Draw:
    width, height = float(rng.uniform(9.0, 14.0)), float(rng.uniform(6.0, 9.0))
    start, goal = _line(rng, width, height, slant=0.3)
    length = math.dist(start, goal)
    unit = ((goal[0] - start[0]) / length, (goal[1] - start[1]) / length)
    s = float(rng.uniform(0.35, 0.65)) * length
    side = float(rng.uniform(-0.3, 0.3))
    px = start[0] + unit[0] * s - unit[1] * side
    py = start[1] + unit[1] * s + unit[0] * side
    v = float(rng.uniform(0.1, 0.5))
    before = float(rng.uniform(1.0, 3.0))  # the robot's distance from the stop when it stops
    stop = max(round((s - before) / speed, 1), 2.0)
    run = min(v * stop, float(rng.uniform(1.5, 3.0)))  # how far the mover comes
    if rng.random() < 0.35:  # toward the robot, down the line
        direction = (-unit[0], -unit[1])
    else:  # across, from either side
        sign = float(rng.choice([-1.0, 1.0]))
        direction = (-unit[1] * sign, unit[0] * sign)
    appear = round(stop - run / v, 1)
    run = v * (stop - appear)  # so that it is on the spot when it stops
    mx, my = px - direction[0] * run, py - direction[1] * run
    radius = float(rng.uniform(0.2, 0.3))
    return width, height, start, goal, 0.0, [
        _disc(mx, my, radius, velocity=[direction[0] * v, direction[1] * v], appear=appear,
              vanish=stop),
        _disc(px, py, radius, appear=stop),
    ]


def _facing_away(rng: np.random.Generator, speed: float) -> Draw:
    width, height = float(rng.uniform(8.0, 13.0)), float(rng.uniform(5.0, 9.0))
    start, goal = _line(rng, width, height, slant=0.6)
    obstacles: list[Obstacle] = []
    length = math.dist(start, goal)
    for _ in range(int(rng.integers(1, 3))):
        f = float(rng.uniform(0.3, 0.7))
        cx = start[0] + (goal[0] - start[0]) * f
        cy = start[1] + (goal[1] - start[1]) * f + float(rng.uniform(-0.3, 0.3))
        if all(math.dist((cx, cy), o["center"]) > 1.2 for o in obstacles) and length > 3:
            obstacles.append(_box(cx, cy, float(rng.uniform(0.3, 0.8)),
                                  float(rng.uniform(0.3, 1.0))))
    away = float(rng.uniform(120.0, 240.0))  # degrees off the goal direction
    return width, height, start, goal, away, obstacles


def _walker(rng: np.random.Generator, start: list[float], goals: list[list[float]],
            appear: float = 0.0) -> Obstacle:
    """An ORCA agent from ``start`` through ``goals``, seeing the robot or not."""
    return {"shape": "disc", "behavior": "orca", "center": start,
            "radius": round(float(rng.uniform(0.2, 0.3)), 3), "goals": goals,
            "preferred_speed": round(float(rng.uniform(0.2, 0.6)), 2),
            "sees_robot": bool(rng.random() < 0.5), "appear": appear}


def _apart(point: list[float], others: list[list[float]], distance: float) -> bool:
    return all(math.dist(point, o) >= distance for o in others)


def _walkers_corridor(rng: np.random.Generator, speed: float) -> Draw:
    c = _walled_corridor(rng, (1.6, 2.6), (4.0, 8.0), (7.0, 10.0))
    start, cy, inner, entry, exit_ = c.start, c.cy, c.inner, c.entry, c.exit
    obstacles = list(c.walls)
    starts: list[list[float]] = [start]
    for _ in range(int(rng.integers(1, 4))):
        lane = cy + float(rng.uniform(-1.0, 1.0)) * (inner / 2 - 0.35)
        x = float(rng.uniform(entry + 0.3, exit_ - 0.3))
        if not _apart([x, lane], starts, 1.5):
            continue
        # toward the robot: out past the corridor's near end, beside the line; its way:
        # out past the far end, beside the goal
        off = float(rng.choice([-1.0, 1.0])) * float(rng.uniform(1.0, 2.0))
        end = [entry - 1.0, cy + off] if rng.random() < 0.5 else [exit_ + 1.0, cy + off]
        obstacles.append(_walker(rng, [x, lane], [end]))
        starts.append([x, lane])
    return c.width, c.height, start, c.goal, 0.0, obstacles


def _walkers_doorway(rng: np.random.Generator, speed: float) -> Draw:
    w = _wall_with_gap(rng, (9.0, 14.0), (1.0, 1.6), (0.0, 2.0))  # the door: the gap
    far = [float(rng.uniform(w.x + 1.5, w.width - 0.5)),
           float(rng.uniform(0.7, w.height - 0.7))]
    near = [float(rng.uniform(0.5, max(w.x - 1.5, 0.6))),
            float(rng.uniform(0.7, w.height - 0.7))]
    # it sets off while the robot is still on its side of the wall
    appear = round(float(rng.uniform(0.0, 0.6)) * (w.x - w.start[0]) / speed, 1)
    walker = _walker(rng, far, [[w.x + 0.8, w.gap_y], [w.x - 0.8, w.gap_y], near], appear)
    return w.width, w.height, w.start, w.goal, 0.0, [*w.pieces(0.2), walker]


def _walkers_across(rng: np.random.Generator, speed: float) -> Draw:
    width, height = float(rng.uniform(9.0, 14.0)), float(rng.uniform(7.0, 10.0))
    start, goal = _line(rng, width, height, slant=0.6)
    obstacles: list[Obstacle] = []
    starts: list[list[float]] = [start, goal]
    for _ in range(int(rng.integers(2, 5))):
        x = float(rng.uniform(0.3, 0.8)) * (goal[0] - start[0]) + start[0]
        reach = float(rng.uniform(1.5, 3.0))
        line_y = start[1] + (goal[1] - start[1]) * (x - start[0]) / (goal[0] - start[0])
        a = [x + float(rng.uniform(-0.5, 0.5)), max(line_y - reach, 0.5)]
        b = [x + float(rng.uniform(-0.5, 0.5)), min(line_y + reach, height - 0.5)]
        first, second = (a, b) if rng.random() < 0.5 else (b, a)
        if not _apart(first, starts, 1.5):
            continue
        obstacles.append(_walker(rng, first, [second, first, second, first, second]))
        starts.append(first)
    return width, height, start, goal, 0.0, obstacles


_DRAWS = {"appear": _appear, "wall-gap": _wall_gap, "cup": _cup, "corridor": _corridor,
          "posts": _posts, "mover-stops": _mover_stops, "facing-away": _facing_away,
          "walkers-corridor": _walkers_corridor, "walkers-doorway": _walkers_doorway,
          "walkers-across": _walkers_across}


# --- turning the drawn frame -----------------------------------------------------------

def turn_point(point: tuple[float, float], quarter: int, width: float, height: float
               ) -> tuple[float, float]:
    """``point`` of a ``width`` x ``height`` world turned ``quarter`` times 90 degrees
    counter-clockwise about the world's centre (into the turned world's frame)."""
    x, y = point
    if quarter == 1:
        return height - y, x
    if quarter == 2:
        return width - x, height - y
    if quarter == 3:
        return y, width - x
    return x, y


def turn_vector(v: tuple[float, float], quarter: int) -> tuple[float, float]:
    """``v`` turned ``quarter`` times 90 degrees counter-clockwise."""
    x, y = v
    return [(x, y), (-y, x), (-x, -y), (y, -x)][quarter]


def _placed(draw: Draw, quarter: int, mirror: bool) -> tuple[list[float], dict[str, Any],
                                                              list[Obstacle]]:
    """The drawn scene mirrored about its middle line (maybe), then turned ``quarter``
    times 90 degrees counter-clockwise: world size, robot, obstacles."""
    width, height, start, goal, away, obstacles = draw

    def point(p: list[float]) -> list[float]:
        x, y = p
        if mirror:
            y = height - y
        return [round(c, 3) for c in turn_point((x, y), quarter, width, height)]

    def vector(v: list[float]) -> list[float]:
        x, y = v
        if mirror:
            y = -y
        return [round(c, 3) + 0.0 for c in turn_vector((x, y), quarter)]

    size = [width, height] if quarter % 2 == 0 else [height, width]
    s, g = point(start), point(goal)
    toward = math.degrees(math.atan2(g[1] - s[1], g[0] - s[0]))
    heading = (toward + (-away if mirror else away) + 180.0) % 360.0 - 180.0
    placed = []
    for drawn in obstacles:
        o = dict(drawn)
        o["center"] = point(o["center"])
        if "size" in o:
            w, h = o["size"]
            o["size"] = [round(w, 3), round(h, 3)] if quarter % 2 == 0 else \
                [round(h, 3), round(w, 3)]
        if "radius" in o:
            o["radius"] = round(o["radius"], 3)
        if "velocity" in o:
            o["velocity"] = vector(o["velocity"])
        if "goals" in o:
            o["goals"] = [point(g) for g in o["goals"]]
        placed.append(o)
    robot = {"start": s, "goal": g, "heading_deg": round(heading, 1)}
    return [round(size[0], 2), round(size[1], 2)], robot, placed


# --- is there a way? -------------------------------------------------------------------

def free_grid(scenario: Scenario, cell: float = WAY_CELL) -> NDArray[np.bool_]:
    """Cells (rows: y, columns: x) where the robot disc's centre clears every obstacle
    that ever stands still, and stays inside the world. Movers are left out: they pass."""
    width, height = scenario.world.size
    r = scenario.robot.radius
    xs = (np.arange(math.ceil(width / cell)) + 0.5) * cell
    ys = (np.arange(math.ceil(height / cell)) + 0.5) * cell
    gx, gy = np.meshgrid(xs, ys)
    free = (gx >= r) & (gx <= width - r) & (gy >= r) & (gy <= height - r)
    for o in scenario.obstacles:
        if not o.is_static or o.is_agent:
            continue
        cx, cy = o.center
        if o.shape == "disc":
            assert o.radius is not None
            free &= np.hypot(gx - cx, gy - cy) > o.radius + r
        else:
            assert o.size is not None
            dx = np.maximum(np.abs(gx - cx) - o.size[0] / 2, 0.0)
            dy = np.maximum(np.abs(gy - cy) - o.size[1] / 2, 0.0)
            free &= np.hypot(dx, dy) > r
    return np.asarray(free, dtype=bool)


def solvable(scenario: Scenario, cell: float = WAY_CELL) -> bool:
    """The start cell and a cell within the goal tolerance lie in one 4-connected region
    of :func:`free_grid` (a flood fill, as a breadth-first search would find)."""
    free = free_grid(scenario, cell)
    rows, cols = free.shape
    sx, sy = scenario.robot.start
    gx, gy = scenario.robot.goal
    start = (min(int(sy / cell), rows - 1), min(int(sx / cell), cols - 1))
    if not free[start]:
        return False
    regions, _ = ndimage.label(free)  # 4-connected by default
    ys = (np.arange(rows) + 0.5) * cell
    xs = (np.arange(cols) + 0.5) * cell
    near = np.hypot(xs[None, :] - gx, ys[:, None] - gy) <= scenario.robot.goal_tolerance
    return bool((regions[near] == regions[start]).any())


# --- the scenes ------------------------------------------------------------------------

def unseen_scenario(kind: str, seed: int) -> Scenario:
    """A scene of class ``kind`` (see :data:`ALL_CLASSES`), the same for the same seed."""
    if kind not in ALL_CLASSES:
        raise ValueError(f"unknown class {kind!r}; choose from {', '.join(ALL_CLASSES)}")
    rng = np.random.default_rng([1012, ALL_CLASSES.index(kind), seed])
    for _ in range(DRAWS):
        speed = _speed(rng)
        draw = _DRAWS[kind](rng, speed)
        quarter, mirror = int(rng.integers(0, 4)), bool(rng.random() < 0.5)
        size, robot, obstacles = _placed(draw, quarter, mirror)
        straight = math.dist(robot["start"], robot["goal"])
        data = {
            "name": f"{FAMILY_PREFIX}{kind}-{seed}",
            "description": f"unseen {kind} scene, seed {seed}",
            "world": {"size": size, "cell": 0.5},
            "robot": {**robot, "speed": speed, "radius": RADIUS},
            "laser": {"noise_std": 0.01},
            "obstacles": obstacles,
            "duration": round(max(4 * straight / speed + 60, 120.0), 1),
            "seed": seed,
        }
        try:
            scenario = parse_scenario(data, f"<{kind}-{seed}>")
        except ValueError:
            continue  # e.g. an obstacle on the start: draw again
        if solvable(scenario):
            return scenario
    raise RuntimeError(f"no solvable {kind} scene in {DRAWS} draws of seed {seed}")
