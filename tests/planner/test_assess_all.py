"""assess_all (every obstacle at once, as the planner calls it) gives exactly what assess
gives obstacle by obstacle: the same assessments, to the last bit, in the same order."""

from __future__ import annotations

import numpy as np
import pytest

from zenav.schemas.messages import ObstacleKind
from zenav.services.planner.prediction import MeetRule, Obstacle, assess, assess_all

KINDS: tuple[ObstacleKind, ...] = ("new", "static", "dynamic")


def random_obstacles(rng: np.random.Generator, count: int, cell: float) -> list[Obstacle]:
    found = []
    for i in range(count):
        x, y = rng.uniform(-1.0, 6.0), rng.uniform(-2.0, 2.0)
        kind = KINDS[int(rng.integers(0, 3))]
        speed = rng.uniform(0.0, 1.2) if kind == "dynamic" else 0.0
        angle = rng.uniform(-np.pi, np.pi)
        ix, iy = round(x / cell), round(y / cell)
        w, h = int(rng.integers(0, 4)), int(rng.integers(0, 4))
        found.append(Obstacle(id=i, kind=kind, position=(x, y),
                              velocity=(speed * np.cos(angle), speed * np.sin(angle)),
                              radius=rng.uniform(0.1, 0.5), cells=(ix, ix + w, iy, iy + h)))
    return found


LETTERS: dict[str, set[str]] = {"closest": set(), "same_time": set()}


@pytest.mark.parametrize("meet_rule", ["closest", "same_time"])
@pytest.mark.parametrize("seed", range(20))
def test_all_at_once_is_one_by_one(seed: int, meet_rule: MeetRule) -> None:
    rng = np.random.default_rng(seed)
    cell = 0.25
    obstacles = random_obstacles(rng, 12, cell)
    robot = rng.uniform(-0.5, 0.5, 2)
    heading = rng.uniform(-0.4, 0.4)
    direction = np.array([np.cos(heading), np.sin(heading)])
    margins = list(rng.uniform(0.05, 0.3, len(obstacles)))
    horizons = list(rng.uniform(4.0, 8.0, len(obstacles)))
    following = [bool(f) for f in rng.integers(0, 2, len(obstacles))]
    common = {"robot_radius": 0.3, "cell": cell, "moving_speed": 0.1, "head_on_cos": -0.9,
              "same_way_cos": 0.9}
    one_by_one = [a for i, ob in enumerate(obstacles)
                  if (a := assess(robot, direction, 0.8, 5.0, ob, margin=margins[i],
                                  horizon=horizons[i], following=following[i],
                                  meet_rule=meet_rule, **common)) is not None]
    at_once = assess_all(robot, direction, 0.8, 5.0, obstacles, margins, horizons, following,
                         meet_rule=meet_rule, **common)
    assert at_once == one_by_one
    LETTERS[meet_rule].update(a.letter for a in at_once)


@pytest.mark.parametrize("meet_rule", ["closest", "same_time"])
def test_the_worlds_cover_standing_and_moving_cases(meet_rule: MeetRule) -> None:
    for seed in range(20):
        test_all_at_once_is_one_by_one(seed, meet_rule)
    found = LETTERS[meet_rule]
    assert {"b", "e"} <= found and found & {"c", "d", "f", "g"}
