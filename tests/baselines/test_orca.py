"""ORCA driving the robot: the holonomic velocity from the tracks, and the unicycle command."""

from __future__ import annotations

import math

import numpy as np

from tests.baselines.scans import cycle, world
from zenav.services.baselines.common import Cycle, Obstacles
from zenav.services.baselines.orca import (
    ORCA,
    orca_velocity,
    preferred_velocity,
    unicycle_command,
)
from zenav.services.baselines.params import ORCAParams

GOAL = (8.0, 5.0)


def params(**extra: object) -> ORCAParams:
    return ORCAParams.model_validate({"goal": GOAL, "cruise_speed": 1.0, "max_speed": 1.0,
                                  "robot_radius": 0.3, "max_omega": 2.0, **extra})


def with_tracks(c: Cycle, positions, velocities, radii) -> Cycle:
    tracked = Obstacles(positions=np.array(positions, dtype=float).reshape(-1, 2),
                        velocities=np.array(velocities, dtype=float).reshape(-1, 2),
                        radii=np.array(radii, dtype=float))
    return Cycle(ranges=c.ranges, angles=c.angles, range_max=c.range_max, pose=c.pose,
                 velocity=c.velocity, goal=c.goal, tracked=tracked)


def test_open_road_goes_straight_for_the_goal_at_the_cruise_speed():
    p = params()
    d = ORCA(p).step(cycle(world(), (2.0, 5.0, 0.0), GOAL, velocity=(1.0, 0.0)))
    assert math.isclose(d.velocity[0], 1.0, abs_tol=1e-5) and abs(d.velocity[1]) < 1e-5
    assert math.isclose(d.v, 1.0, abs_tol=1e-5) and abs(d.omega) < 1e-4


def test_preferred_velocity_slows_within_a_second_of_the_goal():
    assert np.allclose(preferred_velocity((0.0, 0.0), (3.0, 4.0), 1.0, 1.0), (0.6, 0.8))
    assert np.allclose(preferred_velocity((0.0, 0.0), (0.3, 0.4), 1.0, 1.0), (0.3, 0.4))
    assert preferred_velocity((1.0, 1.0), (1.0, 1.0), 1.0, 1.0) == (0.0, 0.0)


def test_a_track_head_on_turns_the_velocity_aside():
    p = params()
    base = cycle(world(), (2.0, 5.0, 0.0), GOAL, velocity=(1.0, 0.0))
    vx, vy = orca_velocity(with_tracks(base, [[4.0, 5.02]], [[-1.0, 0.0]], [0.3]), p)
    assert abs(vy) > 0.1  # steps aside (ORCA's half of the avoidance, or more)
    assert math.hypot(vx, vy) <= 1.0 + 1e-6


def test_closed_loop_the_robot_passes_a_crosser_without_contact():
    """A mover crosses the straight path (it would meet a robot driving straight on); ORCA
    on exact tracks steers the unicycle round it."""
    p = params()
    policy = ORCA(p)
    pose, v = (2.0, 5.0, 0.0), 0.0
    mover, mover_v = np.array([5.0, 2.0]), np.array([0.0, 1.0])
    gaps = []
    for _ in range(120):
        c = cycle(world(), pose, GOAL, velocity=(v, 0.0))
        d = policy.step(with_tracks(c, [mover], [mover_v], [0.3]))
        x, y, heading = pose
        v = d.v
        heading += d.omega * 0.1
        pose = (x + v * math.cos(heading) * 0.1, y + v * math.sin(heading) * 0.1, heading)
        mover = mover + mover_v * 0.1
        gaps.append(math.dist(pose[:2], mover) - 0.6)
        if math.dist(pose[:2], GOAL) < 0.3:
            break
    assert min(gaps) > 0.0
    assert math.dist(pose[:2], GOAL) < 0.3


def test_the_unicycle_turns_in_place_for_a_velocity_behind_and_slows_in_a_turn():
    p = params()
    v, omega = unicycle_command((-1.0, 0.0), 0.0, 0.0, p)
    assert v == 0.0 and abs(omega) == p.max_omega
    v, omega = unicycle_command((math.cos(0.5), math.sin(0.5)), 0.0, 0.0, p)
    assert math.isclose(v, math.cos(0.5)) and math.isclose(omega, min(2.0, 2.0 * 0.5))
    v, omega = unicycle_command((0.0, 0.0), 0.0, 1.0, p)  # standstill: face the goal
    assert v == 0.0 and omega > 0.0
