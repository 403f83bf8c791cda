"""The speed and safety stage when every candidate touches some mover's growing
clearance: a contact costs more the deeper it goes, so the robot holds back out of the
mover's predicted way rather than cutting across it for progress (safety.py)."""

from __future__ import annotations

import math

import numpy as np

from zenav.services.planner import safety

SETTINGS = safety.Settings(horizon=6.0, step=0.2, margin=0.1, growth=0.2, comfort=0.6,
                           tau=1.5, fan_step=math.radians(15.0),
                           speeds=(0.0, 0.25, 0.5, 0.75, 1.0), turn_cost=0.3)


def test_a_contact_on_the_movers_centre_costs_more_than_one_at_its_clearance_edge() -> None:
    # One sample at 0.2 s, growth 0: a standing mover of radius 0.3 at (2, 0); clearance
    # 0.3 + 0.3 + 0.1 / 2 = 0.65 m. Roll-out A is 0.5 m from its centre (0.15 m deep),
    # roll-out B on it (0.65 m deep, all the way). Both touch at the same time.
    s = SETTINGS.__class__(**{**SETTINGS.__dict__, "growth": 0.0})
    t = np.array([0.2])
    xs = np.array([[2.0], [2.0]])
    ys = np.array([[0.5], [0.0]])
    mover = safety.Movers(np.array([[2.0, 0.0]]), np.zeros((1, 2)), np.array([0.3]),
                          np.zeros(1))
    cost, first, _ = safety.contact_costs(xs, ys, t, mover, 0.3, s)
    assert first[0] == first[1] == 0.2
    w = 1.0 / (1.0 + 0.2 / 1.5)
    assert math.isclose(cost[0], 10.0 * (1.0 + 0.15 / 0.65) * w)
    assert math.isclose(cost[1], 20.0 * w)


def test_an_age_grows_the_clearance_as_if_the_mover_had_walked_that_long() -> None:
    # A mover last seen 2 s ago at 0.5 m/s: growth 0.2 x 0.5 x (2 + t) on top of 0.65 m.
    t = np.array([0.2])
    xs, ys = np.array([[0.8]]), np.array([[0.0]])
    fresh = safety.Movers(np.array([[0.0, 0.0]]), np.zeros((1, 2)), np.array([0.3]),
                          np.array([0.5]))
    old = safety.Movers(fresh.positions, fresh.velocities, fresh.radii, fresh.top_speeds,
                        np.array([2.0]))
    _, first_fresh, _ = safety.contact_costs(xs, ys, t, fresh, 0.3, SETTINGS)
    _, first_old, _ = safety.contact_costs(xs, ys, t, old, 0.3, SETTINGS)
    assert math.isinf(first_fresh[0])  # 0.8 m > 0.65 + 0.2 x 0.5 x 0.2 = 0.67 m
    assert first_old[0] == 0.2  # 0.8 m < 0.65 + 0.2 x 0.5 x 2.2 = 0.87 m


def test_a_crosser_seen_late_is_let_pass_not_cut_in_front_of() -> None:
    # The robot (radius 0.2, top speed 0.2 m/s) stands heading -45 degrees; the path
    # runs east. A walker (radius 0.16) 1.8 m away up and to the right walks down-left at
    # 0.55 m/s: on its line it passes 0.62 m from the robot's centre, 0.21 m more than
    # the 0.41 m of contact, in 3.2 s. Within the growth of its clearance every candidate
    # touches it. Standing (or backing off its line) lets it pass; cutting across ahead
    # of it to the east meets it. Whatever is chosen, driven as rolled out, must keep
    # out of the walker's way if it walks on as seen.
    robot = safety.Robot(x=0.0, y=0.0, heading=math.radians(-45.0), speed=0.07, radius=0.2,
                         max_speed=0.2, max_omega=1.0, heading_gain=1.5, accel=0.5,
                         decel=1.0)
    walker = safety.Movers(np.array([[1.64, 0.69]]), np.array([[-0.44, -0.33]]),
                           np.array([0.16]), np.array([0.55]))
    choice = safety.choose(robot, (math.radians(-2.0), 0.07), walker,
                           np.array([2.19, -0.22]), None, math.radians(-32.0), SETTINGS)
    assert not choice.kept
    t = SETTINGS.step * np.arange(1, 31, dtype=np.float64)
    xs, ys = safety.rollout(robot, np.array([choice.heading]), np.array([choice.speed]), t)
    gap = np.hypot(xs[0] - (1.64 - 0.44 * t), ys[0] - (0.69 - 0.33 * t))
    assert gap.min() > 0.2 + 0.16 + 0.05
