"""Artificial potential field (Khatib 1986): pull, push, and the turn they ask for."""

from __future__ import annotations

import math

import numpy as np

from tests.baselines.scans import cycle, drive, world
from zenav.services.baselines.apf import APF, closest_points, forces
from zenav.services.baselines.params import APFParams


def test_pull_is_proportional_to_the_distance_then_bounded():
    p = APFParams(goal=(8.0, 5.0))
    near, _, _ = forces(cycle(world(), (7.5, 5.0, 0.0), (8.0, 5.0)), p)
    far, _, _ = forces(cycle(world(), (2.0, 5.0, 0.0), (8.0, 5.0)), p)
    assert np.allclose(near, [0.5, 0.0])
    assert np.allclose(far, [p.k_att * p.d_star, 0.0])


def test_turns_away_from_an_obstacle_ahead_on_the_left():
    w = world({"shape": "disc", "center": [2.8, 5.3], "radius": 0.25})
    d = APF(APFParams(goal=(8.0, 5.0))).step(cycle(w, (2.0, 5.0, 0.0), (8.0, 5.0)))
    assert d.repulsive[1] < 0 and d.repulsive[0] < 0  # pushed back and to the right
    assert d.omega < 0


def test_turns_away_from_an_obstacle_ahead_on_the_right():
    w = world({"shape": "disc", "center": [2.8, 4.7], "radius": 0.25})
    d = APF(APFParams(goal=(8.0, 5.0))).step(cycle(w, (2.0, 5.0, 0.0), (8.0, 5.0)))
    assert d.omega > 0


def test_obstacles_beyond_the_influence_distance_do_not_push():
    w = world({"shape": "disc", "center": [4.0, 5.0], "radius": 0.25})
    d = APF(APFParams(goal=(8.0, 5.0), d0=1.0)).step(cycle(w, (2.0, 5.0, 0.0), (8.0, 5.0)))
    assert d.obstacles == 0 and d.repulsive == (0.0, 0.0)


def test_a_box_square_on_the_line_to_the_goal_traps_it():
    # The method's local minimum: straight ahead, the push comes to cancel the pull.
    w = world({"shape": "box", "center": [3.5, 5.0], "size": [0.5, 0.5]})
    planner = APF(APFParams(goal=(8.0, 5.0), cruise_speed=0.2))
    pose = (2.0, 5.0, 0.0)
    for _ in range(600):
        d = planner.step(cycle(w, pose, (8.0, 5.0)))
        pose = drive(pose, d.v, d.omega)
    assert 2.5 < pose[0] < 3.25 - 0.2  # came closer, stopped short of the box
    assert abs(pose[1] - 5.0) < 0.05 and d.v < 0.01  # and stays there, stuck
    assert abs(d.force[0]) < 0.05


def test_closest_point_per_segment():
    points = np.array([[1.0, 0.0], [1.0, 0.1], [1.0, 0.2], [3.0, 0.0], [3.0, 0.1]])
    near = closest_points(points, np.zeros(2), gap=0.3)
    assert near.tolist() == [[1.0, 0.0], [3.0, 0.0]]
    assert math.isclose(float(np.hypot(*near[0])), 1.0)
