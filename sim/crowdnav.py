"""CrowdNav's test protocol as scenario files (pure, seeded).

Chen, Liu, Kreiss & Alahi, "Crowd-Robot Interaction: Crowd-aware Robot Navigation with
Attention-based Deep Reinforcement Learning", ICRA 2019 (github.com/vita-epfl/CrowdNav,
``crowd_sim/envs/crowd_sim.py``). In CrowdNav's frame (origin at the centre):

- the robot goes from (0, -4) to (0, 4), facing its goal; it is done within its radius
  (0.3 m) of the goal; the episode limit is 25 s;
- **circle crossing**: each of the five humans starts on the circle of radius 4 m at a
  uniform random angle, moved by a uniform ±0.5 m in x and in y, and heads for the point
  opposite its start (the negated start). A start closer than the two radii plus the
  discomfort distance (0.2 m) to the position or the goal of the robot or of a human
  placed before is drawn again;
- **square crossing**: each human picks a side at random (x < 0 or x > 0), starts at a
  uniform point of that half of the 10 m square and ends at a uniform point of the other
  half. A start too close (same distance) to the position of the robot or an earlier
  human is drawn again, and a goal too close to the goal of the robot or an earlier human;
- humans: radius 0.3 m, preferred speed 1 m/s, moved by ORCA (``sim/agents.py``);
  ``sees_robot`` false is CrowdNav's "invisible" setting, true its "visible" one.

Random draws are CrowdNav's own: case ``k`` of the test set uses numpy's legacy generator
seeded with ``1000 + k`` (CrowdNav's test-phase offset), drawn in CrowdNav's order, so
case k here has the humans of CrowdNav's test case k.

Our scenario frame has its origin at the world's lower-left corner: every point is
shifted by half the world size (a 12 m square, which holds both layouts).
"""

from __future__ import annotations

import math
from typing import Any, Literal

import numpy as np

from zenav.sim.scenario import Scenario, parse_scenario

__all__ = ["LAYOUTS", "TEST_SEED_OFFSET", "circle_crossing", "crowdnav_scenario",
           "square_crossing"]

Layout = Literal["circle", "square"]
LAYOUTS: tuple[Layout, ...] = ("circle", "square")

TEST_SEED_OFFSET = 1000
"""CrowdNav seeds test case k with 1000 + k (the validation set's 1000 cases come first)."""
LAST_CASE = 2**32 - 1 - TEST_SEED_OFFSET
"""The last test case there is: its seed, 1000 + case, is the largest numpy's RandomState
takes (32 bits)."""

HUMANS = 5
CIRCLE_RADIUS = 4.0  # m
SQUARE_WIDTH = 10.0  # m
HUMAN_RADIUS = 0.3  # m
HUMAN_SPEED = 1.0  # m/s (v_pref)
ROBOT_RADIUS = 0.3  # m
ROBOT_SPEED = 1.0  # m/s (v_pref)
DISCOMFORT = 0.2  # m
TIME_LIMIT = 25.0  # s
WORLD = 12.0  # m, the side of our square world
ROBOT_START = (0.0, -CIRCLE_RADIUS)
ROBOT_GOAL = (0.0, CIRCLE_RADIUS)

Agent = tuple[float, float, float, float, float]  # px, py, gx, gy, radius (CrowdNav frame)


def check_cases(seed: int, cases: int) -> None:
    """ValueError with one line unless test cases ``seed`` .. ``seed + cases - 1`` exist."""
    if seed + cases - 1 > LAST_CASE:
        raise ValueError(f"--seed {seed} with --cases {cases} runs to case {seed + cases - 1}, "
                         f"beyond the last, {LAST_CASE} (a case's seed, 1000 + case, must fit "
                         "in 32 bits)")


def _far(x: float, y: float, px: float, py: float, min_dist: float) -> bool:
    return math.hypot(x - px, y - py) >= min_dist


def circle_crossing(rng: np.random.RandomState, humans: int = HUMANS) -> list[Agent]:
    """Humans of one circle-crossing case, CrowdNav frame: (px, py, gx, gy, radius)."""
    placed: list[Agent] = [(*ROBOT_START, *ROBOT_GOAL, ROBOT_RADIUS)]
    for _ in range(humans):
        while True:
            angle = rng.random_sample() * math.pi * 2
            px_noise = (rng.random_sample() - 0.5) * HUMAN_SPEED
            py_noise = (rng.random_sample() - 0.5) * HUMAN_SPEED
            px = CIRCLE_RADIUS * math.cos(angle) + px_noise
            py = CIRCLE_RADIUS * math.sin(angle) + py_noise
            if all(_far(px, py, a[0], a[1], HUMAN_RADIUS + a[4] + DISCOMFORT)
                   and _far(px, py, a[2], a[3], HUMAN_RADIUS + a[4] + DISCOMFORT)
                   for a in placed):
                break
        placed.append((px, py, -px, -py, HUMAN_RADIUS))
    return placed[1:]


def square_crossing(rng: np.random.RandomState, humans: int = HUMANS) -> list[Agent]:
    """Humans of one square-crossing case, CrowdNav frame: (px, py, gx, gy, radius)."""
    placed: list[Agent] = [(*ROBOT_START, *ROBOT_GOAL, ROBOT_RADIUS)]
    for _ in range(humans):
        sign = -1.0 if rng.random_sample() > 0.5 else 1.0
        while True:
            px = rng.random_sample() * SQUARE_WIDTH * 0.5 * sign
            py = (rng.random_sample() - 0.5) * SQUARE_WIDTH
            if all(_far(px, py, a[0], a[1], HUMAN_RADIUS + a[4] + DISCOMFORT) for a in placed):
                break
        while True:
            gx = rng.random_sample() * SQUARE_WIDTH * 0.5 * -sign
            gy = (rng.random_sample() - 0.5) * SQUARE_WIDTH
            if all(_far(gx, gy, a[2], a[3], HUMAN_RADIUS + a[4] + DISCOMFORT) for a in placed):
                break
        placed.append((px, py, gx, gy, HUMAN_RADIUS))
    return placed[1:]


def crowdnav_scenario(layout: Layout, case: int, *, visible: bool = False,
                      fov_deg: float = 180.0) -> Scenario:
    """CrowdNav's test case ``case`` (0, 1, ...) of ``layout`` as a scenario.

    ``visible``: the humans see the robot. ``fov_deg``: the laser's field of view (180,
    the paper's, or 360); 0.5° resolution, 8 m range, 10 Hz, no noise.
    """
    if layout not in LAYOUTS:
        raise ValueError(f"unknown layout {layout!r}; choose from {', '.join(LAYOUTS)}")
    if not 0 <= case <= LAST_CASE:
        raise ValueError(f"case must be in 0..{LAST_CASE} (got {case})")
    rng = np.random.RandomState(TEST_SEED_OFFSET + case)
    humans = (circle_crossing if layout == "circle" else square_crossing)(rng)
    shift = WORLD / 2

    def at(x: float, y: float) -> list[float]:
        return [round(x + shift, 6), round(y + shift, 6)]

    obstacles: list[dict[str, Any]] = [
        {"shape": "disc", "behavior": "orca", "center": at(px, py), "radius": radius,
         "goals": [at(gx, gy)], "preferred_speed": HUMAN_SPEED, "sees_robot": visible}
        for px, py, gx, gy, radius in humans
    ]
    setting = "visible" if visible else "invisible"
    data = {
        "name": f"{layout}-crossing-{setting}-{round(fov_deg)}-{case}",
        "description": f"CrowdNav {layout} crossing, test case {case}, {setting} humans, "
                       f"laser {fov_deg:g} degrees",
        "world": {"size": [WORLD, WORLD], "cell": 0.5},
        "robot": {"start": at(*ROBOT_START), "heading_deg": 90.0, "goal": at(*ROBOT_GOAL),
                  "goal_tolerance": ROBOT_RADIUS, "speed": ROBOT_SPEED,
                  "max_speed": ROBOT_SPEED, "radius": ROBOT_RADIUS},
        "laser": {"fov_deg": fov_deg, "resolution_deg": 0.5, "max_range": 8.0,
                  "rate_hz": 10.0, "noise_std": 0.0},
        "obstacles": obstacles,
        "duration": TIME_LIMIT,
        "seed": case,
    }
    return parse_scenario(data, f"crowdnav {layout} case {case}")
