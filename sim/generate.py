"""Seeded random scenarios in the scenario file format, for tests and benchmarks.

Each family puts obstacles where they matter, around the straight line from start to
goal, and never on the start or the goal:

- ``static``: boxes and discs scattered along the path;
- ``crossing``: movers that cross the path at random times and speeds;
- ``head-on``: movers coming down the path toward the robot;
- ``overtaking``: slower movers ahead, going the robot's way;
- ``mixed``: some of each;
- ``crowd``: five movers on a circle round the path's middle, each crossing to the
  opposite side, all in place from the start (like CrowdNav's circle-crossing set-up).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from zenav.sim.scenario import Scenario, parse_scenario

FAMILIES = ("static", "crossing", "head-on", "overtaking", "mixed", "crowd")
WORLD = 12.0


def _path(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, float]:
    heading = rng.uniform(-math.pi, math.pi)
    length = rng.uniform(6.0, 8.5)
    middle = np.array([WORLD / 2, WORLD / 2]) + rng.uniform(-0.5, 0.5, 2)
    direction = np.array([math.cos(heading), math.sin(heading)])
    start = middle - direction * length / 2
    goal = middle + direction * length / 2
    return start, goal, heading


def _clear_of_ends(point: np.ndarray, start: np.ndarray, goal: np.ndarray, gap: float) -> bool:
    return bool(np.hypot(*(point - start)) > gap and np.hypot(*(point - goal)) > gap)


def _static(rng: np.random.Generator, start: np.ndarray, goal: np.ndarray,
            count: int) -> list[dict[str, Any]]:
    axis = goal - start
    length = float(np.hypot(*axis))
    unit = axis / length
    normal = np.array([-unit[1], unit[0]])
    found: list[dict[str, Any]] = []
    for _ in range(count * 10):
        if len(found) == count:
            break
        s = rng.uniform(1.2, length - 1.2)
        centre = start + unit * s + normal * rng.uniform(-1.2, 1.2)
        if not _clear_of_ends(centre, start, goal, 1.2):
            continue
        if any(math.dist(centre, o["center"]) < 1.3 for o in found):
            continue  # leave room to pass between obstacles
        if rng.random() < 0.5:
            size = [round(float(rng.uniform(0.3, 0.8)), 2), round(float(rng.uniform(0.3, 0.8)), 2)]
            found.append({"shape": "box", "center": [round(float(c), 2) for c in centre],
                          "size": size})
        else:
            found.append({"shape": "disc", "center": [round(float(c), 2) for c in centre],
                          "radius": round(float(rng.uniform(0.15, 0.4)), 2)})
    return found


def _mover(centre: np.ndarray, velocity: np.ndarray, radius: float,
           appear: float = 0.0) -> dict[str, Any]:
    return {"shape": "disc", "center": [round(float(c), 3) for c in centre],
            "radius": round(radius, 2), "velocity": [round(float(v), 3) for v in velocity],
            "appear": round(appear, 1)}


def _crossers(rng: np.random.Generator, start: np.ndarray, goal: np.ndarray, speed: float,
              count: int) -> list[dict[str, Any]]:
    axis = goal - start
    length = float(np.hypot(*axis))
    unit = axis / length
    found = []
    for _ in range(count):
        s = rng.uniform(2.0, length - 1.5)
        meet = start + unit * s
        angle = rng.uniform(math.radians(50), math.radians(130)) * rng.choice([-1.0, 1.0])
        direction = np.array([unit[0] * math.cos(angle) - unit[1] * math.sin(angle),
                              unit[0] * math.sin(angle) + unit[1] * math.cos(angle)])
        v = rng.uniform(0.05, 0.8)
        t_meet = s / speed + rng.uniform(-6.0, 6.0)  # around when the robot gets there
        t_meet = max(t_meet, 4.0 / v + 1.0)
        appear = max(0.0, t_meet - 4.0 / v)
        centre = meet - direction * v * (t_meet - appear)
        found.append(_mover(centre, direction * v, float(rng.uniform(0.15, 0.3)), appear))
    return found


def _head_on(rng: np.random.Generator, start: np.ndarray, goal: np.ndarray,
             count: int) -> list[dict[str, Any]]:
    axis = goal - start
    unit = axis / float(np.hypot(*axis))
    normal = np.array([-unit[1], unit[0]])
    found = []
    for k in range(count):
        v = rng.uniform(0.05, 0.8)
        centre = goal + unit * (1.0 + 2.0 * k) + normal * rng.uniform(-0.15, 0.15)
        found.append(_mover(centre, -unit * v, float(rng.uniform(0.15, 0.3)),
                            float(rng.uniform(0.0, 10.0))))
    return found


def _overtaking(rng: np.random.Generator, start: np.ndarray, goal: np.ndarray, speed: float,
                count: int) -> list[dict[str, Any]]:
    axis = goal - start
    unit = axis / float(np.hypot(*axis))
    found = []
    for k in range(count):
        v = rng.uniform(0.3, 0.8) * speed
        centre = start + unit * (1.5 + 1.5 * k)
        found.append(_mover(centre, unit * v, float(rng.uniform(0.15, 0.25))))
    return found


def _crowd(rng: np.random.Generator, start: np.ndarray, goal: np.ndarray,
           count: int = 5) -> list[dict[str, Any]]:
    middle = (start + goal) / 2
    found = []
    offset = rng.uniform(0, 2 * math.pi)
    # Every mover is there from t = 0, as CrowdNav's humans are. They used to appear at
    # random times (5-20 s) wherever their circle put them, and one world in ten or so
    # dropped one on top of the robot (0.2-0.5 m between centres): a contact no planner
    # could see coming. At t = 0 the circle lies at least 1 m from the start. Their
    # speeds (0.1-0.5 m/s) still spread their crossings of the middle over 4-20 s.
    for k in range(count):
        angle = offset + 2 * math.pi * k / count
        on_circle = middle + 2.0 * np.array([math.cos(angle), math.sin(angle)])
        v = rng.uniform(0.1, 0.5)
        toward = (middle - on_circle) / 2.0
        found.append(_mover(on_circle, toward * v, 0.2))
    return found


def random_scenario(family: str, seed: int, noise_std: float = 0.01) -> Scenario:
    """A scenario of ``family`` (see :data:`FAMILIES`), the same for the same seed."""
    if family not in FAMILIES:
        raise ValueError(f"unknown family {family!r}; choose from {', '.join(FAMILIES)}")
    rng = np.random.default_rng([FAMILIES.index(family), seed])
    start, goal, heading = _path(rng)
    speed = float(rng.choice([0.1, 0.2, 0.3, 0.5]))
    obstacles: list[dict[str, Any]] = []
    if family == "static":
        obstacles = _static(rng, start, goal, int(rng.integers(3, 7)))
    elif family == "crossing":
        obstacles = _crossers(rng, start, goal, speed, int(rng.integers(1, 4)))
    elif family == "head-on":
        obstacles = _head_on(rng, start, goal, int(rng.integers(1, 3)))
    elif family == "overtaking":
        obstacles = _overtaking(rng, start, goal, speed, 1)
    elif family == "mixed":
        obstacles = (_static(rng, start, goal, int(rng.integers(1, 4)))
                     + _crossers(rng, start, goal, speed, int(rng.integers(1, 3)))
                     + _head_on(rng, start, goal, int(rng.integers(0, 2))))
    else:
        obstacles = _crowd(rng, start, goal)
    length = float(np.hypot(*(goal - start)))
    data = {
        "name": f"{family}-{seed}",
        "description": f"random {family} world, seed {seed}",
        "world": {"size": [WORLD, WORLD], "cell": 0.5},
        "robot": {"start": [round(float(c), 3) for c in start],
                  "heading_deg": round(math.degrees(heading), 2),
                  "goal": [round(float(c), 3) for c in goal], "speed": speed, "radius": 0.2},
        "laser": {"noise_std": noise_std},
        "obstacles": obstacles,
        "duration": round(4 * length / speed + 60, 1),
        "seed": seed,
    }
    return parse_scenario(data, f"<{family}-{seed}>")
