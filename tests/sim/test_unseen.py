"""The unseen-scene generator: the same seed gives the same scene, every scene loads
through the scenario loader, every scene has a way through, and the way check itself
tells a blocked scene from an open one."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from zenav.sim.scenario import (
    ObstacleSpec,
    Scenario,
    dump_scenario,
    load_scenario,
    parse_scenario,
)
from zenav.sim.unseen import (
    ALL_CLASSES,
    CLASSES,
    RADIUS,
    WALKER_CLASSES,
    free_grid,
    solvable,
    unseen_scenario,
)

SEEDS = range(5)


@pytest.mark.parametrize("kind", ALL_CLASSES)
def test_same_seed_same_scene_other_seed_other_scene(kind: str) -> None:
    first = unseen_scenario(kind, 3)
    assert unseen_scenario(kind, 3) == first
    assert unseen_scenario(kind, 4) != first


@pytest.mark.parametrize("kind", ALL_CLASSES)
def test_scenes_load_from_file_and_have_a_way(kind: str, tmp_path: Path) -> None:
    for seed in SEEDS:
        scene = unseen_scenario(kind, seed)
        path = dump_scenario(scene, tmp_path / f"{scene.name}.yaml")
        loaded = load_scenario(path)
        assert loaded.name == f"unseen-{kind}-{seed}"
        assert loaded.robot.radius == RADIUS
        assert solvable(loaded), loaded.name


def test_scenes_vary_in_direction_size_and_speed() -> None:
    scenes = [unseen_scenario(kind, seed) for kind in CLASSES for seed in SEEDS]
    directions = {round(math.degrees(math.atan2(s.robot.goal[1] - s.robot.start[1],
                                                s.robot.goal[0] - s.robot.start[0])) / 90)
                  % 4 for s in scenes}
    assert directions == {0, 1, 2, 3}  # toward +x, +y, -x and -y
    assert len({s.world.size for s in scenes}) == len(scenes)
    speeds = {s.robot.speed for s in scenes}
    assert 0.1 in speeds and any(0.3 <= v <= 0.5 for v in speeds)


def test_facing_away_starts_facing_away() -> None:
    for seed in SEEDS:
        s = unseen_scenario("facing-away", seed)
        toward = math.degrees(math.atan2(s.robot.goal[1] - s.robot.start[1],
                                         s.robot.goal[0] - s.robot.start[0]))
        off = abs((s.robot.heading_deg - toward + 180.0) % 360.0 - 180.0)
        assert off >= 119.9, (s.name, off)


def test_posts_leave_gaps_of_two_and_a_half_radii() -> None:
    for seed in SEEDS:
        posts = [o for o in unseen_scenario("posts", seed).obstacles if o.shape == "disc"]
        assert len(posts) >= 6
        for i, a in enumerate(posts):
            for b in posts[i + 1:]:
                assert a.radius is not None and b.radius is not None
                gap = math.dist(a.center, b.center) - a.radius - b.radius
                assert gap >= 2.5 * RADIUS - 1e-3


def test_mover_stops_leaves_a_standing_disc_where_the_mover_went() -> None:
    for seed in SEEDS:
        mover, standing = unseen_scenario("mover-stops", seed).obstacles
        assert mover.vanish is not None and standing.is_static
        assert standing.appear == pytest.approx(mover.vanish)
        assert mover.center_at(mover.vanish - 1e-9) == pytest.approx(standing.center, abs=0.01)


def _walled(gap: float) -> Scenario:
    """A wall across a 6 x 6 world with a gap of ``gap`` m at y = 4."""
    low, high = 4.0 - gap / 2, 4.0 + gap / 2
    return parse_scenario({
        "name": "walled", "world": {"size": [6.0, 6.0], "cell": 0.5},
        "robot": {"start": [1.0, 1.0], "goal": [5.0, 1.0], "speed": 0.1, "radius": 0.2},
        "obstacles": [
            {"shape": "box", "center": [3.0, low / 2], "size": [0.2, low]},
            {"shape": "box", "center": [3.0, (high + 6.0) / 2], "size": [0.2, 6.0 - high]},
        ]}, "<walled>")


def test_way_check_needs_a_gap_wider_than_the_robot() -> None:
    assert solvable(_walled(0.5))
    assert not solvable(_walled(0.35))  # narrower than the 0.4 m disc


def test_way_check_ignores_movers_and_counts_what_stops() -> None:
    wall = _walled(0.6)
    plug = {"shape": "disc", "center": [3.0, 4.0], "radius": 0.3}
    passing = wall.model_dump() | {"obstacles": [
        *[o.model_dump() for o in wall.obstacles], plug | {"velocity": [0.1, 0.0]}]}
    stopping = wall.model_dump() | {"obstacles": [
        *[o.model_dump() for o in wall.obstacles], plug | {"appear": 30.0}]}
    assert solvable(parse_scenario(passing, "<passing>"))
    assert not solvable(parse_scenario(stopping, "<stopping>"))


def test_free_grid_keeps_the_disc_inside_the_world() -> None:
    free = free_grid(_walled(1.0), cell=0.1)
    assert not free[:, 0].any() and not free[0, :].any()
    assert free[10, 10]


@pytest.mark.parametrize("kind", WALKER_CLASSES)
def test_walkers_start_clear_of_the_robot_and_walk_inside_the_world(kind: str) -> None:
    for seed in range(20):
        scene = unseen_scenario(kind, seed)
        width, height = scene.world.size
        walkers = [o for o in scene.obstacles if o.is_agent]
        assert walkers, scene.name
        for w in walkers:
            assert w.goals and w.preferred_speed is not None and 0.2 <= w.preferred_speed <= 0.6
            assert math.dist(w.center, scene.robot.start) >= 1.5, scene.name
            for gx, gy in [w.center, *w.goals]:
                assert 0.0 <= gx <= width and 0.0 <= gy <= height, scene.name


def test_a_doorway_walker_goes_through_its_door_however_the_scene_is_turned() -> None:
    for seed in range(20):
        scene = unseen_scenario("walkers-doorway", seed)
        walker = next(o for o in scene.obstacles if o.is_agent)
        assert walker.goals is not None
        (ax, ay), (bx, by) = walker.goals[0], walker.goals[1]
        door = ((ax + bx) / 2, (ay + by) / 2)  # its first two goals face each other
        walls = [o for o in scene.obstacles if o.shape == "box"]
        assert len(walls) == 2
        assert not any(inside(box, door) for box in walls), scene.name
        # and they lie 0.8 m either side of the wall, square to it
        assert math.isclose(math.dist((ax, ay), (bx, by)), 1.6, abs_tol=1e-2)
        thin = 0 if walls[0].size is not None and walls[0].size[0] < walls[0].size[1] else 1
        assert math.isclose(abs((bx - ax, by - ay)[thin]), 1.6, abs_tol=1e-2), scene.name


def inside(box: ObstacleSpec, point: tuple[float, float]) -> bool:
    """Whether ``point`` lies inside the axis-aligned ``box``."""
    assert box.size is not None
    (cx, cy), (w, h) = box.center, box.size
    return abs(point[0] - cx) <= w / 2 and abs(point[1] - cy) <= h / 2


def test_the_issue_classes_keep_their_scenes_beside_the_walker_classes() -> None:
    assert ALL_CLASSES[: len(CLASSES)] == CLASSES
    assert not set(CLASSES) & set(WALKER_CLASSES)
