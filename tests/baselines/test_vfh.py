"""VFH (Borenstein & Koren 1991): histogram, valleys, steering and speed."""

from __future__ import annotations

import math

import numpy as np

from tests.baselines.scans import cycle, drive, world
from zenav.services.baselines.params import VFHParams
from zenav.services.baselines.vfh import VFH, smooth, steer, valleys

SECTOR = math.radians(5.0)


def test_free_space_heads_straight_for_the_goal_at_cruise_speed():
    planner = VFH(VFHParams(goal=(8.0, 5.0), cruise_speed=0.3))
    d = planner.step(cycle(world(), (2.0, 5.0, 0.0), (8.0, 5.0)))
    assert d.direction is not None and abs(math.remainder(d.direction, 2 * math.pi)) < 1e-9
    assert d.v == 0.3 and d.omega == 0.0


def test_picks_the_free_valley_beside_a_wall_ahead():
    # A wall across the way ahead and to the left; the way round is on the right.
    w = world({"shape": "box", "center": [3.5, 5.6], "size": [0.4, 2.4]})
    planner = VFH(VFHParams(goal=(8.0, 5.0)))
    for _ in range(5):  # HIMM builds certainty over a few scans
        d = planner.step(cycle(w, (2.0, 5.0, 0.0), (8.0, 5.0)))
    assert d.direction is not None
    steering = math.remainder(d.direction, 2 * math.pi)
    assert steering < -math.radians(20)  # to the right of the wall, well clear of it
    assert d.omega < 0


def test_speed_falls_with_the_density_straight_ahead():
    w = world({"shape": "disc", "center": [3.0, 5.0], "radius": 0.3})
    planner = VFH(VFHParams(goal=(8.0, 5.0), cruise_speed=0.3))
    for _ in range(5):
        d = planner.step(cycle(w, (2.0, 5.0, 0.0), (8.0, 5.0)))
    assert d.density_ahead > 0
    assert d.v < 0.3


def test_drives_round_a_box_on_the_way_without_touching_it():
    box = {"shape": "box", "center": [4.0, 5.0], "size": [0.5, 0.5]}
    w = world(box)
    planner = VFH(VFHParams(goal=(7.0, 5.0), cruise_speed=0.2))
    pose = (2.0, 5.0, 0.0)
    closest = math.inf
    for _ in range(400):
        d = planner.step(cycle(w, pose, (7.0, 5.0)))
        pose = drive(pose, d.v, d.omega)
        gap = max(abs(pose[0] - 4.0) - 0.25, abs(pose[1] - 5.0) - 0.25)
        closest = min(closest, gap)
        if math.dist(pose[:2], (7.0, 5.0)) < 0.25:
            break
    assert math.dist(pose[:2], (7.0, 5.0)) < 0.25
    assert closest > 0.2  # never within the robot radius of the box


def test_valleys_wrap_round_the_circle():
    free = np.ones(72, dtype=bool)
    free[10:20] = False
    found = valleys(free)
    assert len(found) == 1 and found[0].start == 20 and found[0].width == 62
    assert valleys(np.zeros(72, dtype=bool)) == []


def test_a_wide_valley_is_entered_s_max_over_two_inside_its_near_border():
    free = np.ones(72, dtype=bool)
    free[66:72] = False
    free[0:6] = False  # blocked from -30 to +30 degrees, target straight ahead
    found = valleys(free)
    direction = steer(found, 0.0, SECTOR, 18, previous=None)
    assert direction is not None
    # nearest border at +30 (or -30) degrees; steer 45 degrees inside it
    assert abs(abs(math.degrees(math.remainder(direction, 2 * math.pi))) - 75.0) < 1e-6


def test_the_side_taken_is_kept_while_the_other_is_not_clearly_nearer():
    free = np.ones(72, dtype=bool)
    free[68:72] = False
    free[0:4] = False  # symmetric block round the target
    found = valleys(free)
    left = steer(found, 0.0, SECTOR, 18, previous=math.radians(60), keep_margin=0.2)
    right = steer(found, 0.0, SECTOR, 18, previous=math.radians(-60), keep_margin=0.2)
    assert left is not None and right is not None
    assert math.remainder(left, 2 * math.pi) > 0 > math.remainder(right, 2 * math.pi)


def test_smoothing_keeps_the_mass_and_spreads_a_peak():
    h = np.zeros(72)
    h[10] = 11.0
    s = smooth(h, 5)
    assert s[10] == 5.0 and s[6] == 1.0 and s[5] == 0.0
    assert math.isclose(s.sum(), h.sum() * 25 / 11)
