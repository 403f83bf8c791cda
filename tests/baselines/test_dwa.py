"""DWA (Fox, Burgard & Thrun 1997): window, admissibility, objective."""

from __future__ import annotations

import math

import numpy as np

from tests.baselines.scans import cycle, drive, world
from zenav.services.baselines.common import Obstacles
from zenav.services.baselines.dwa import DWA, plan
from zenav.services.baselines.params import DWAParams


def test_free_space_speeds_up_within_the_window_toward_the_goal():
    p = DWAParams(goal=(8.0, 5.0), cruise_speed=0.3)
    d = plan(cycle(world(), (2.0, 5.0, 0.0), (8.0, 5.0), velocity=(0.1, 0.0)), p)
    assert math.isclose(d.v, 0.1 + p.accel * p.control_period)
    assert d.omega == 0.0


def test_stays_within_the_dynamic_window():
    p = DWAParams(goal=(2.0, 8.0), cruise_speed=0.3)  # goal on the left: turn
    d = plan(cycle(world(), (2.0, 5.0, 0.0), (2.0, 8.0), velocity=(0.2, 0.0)), p)
    assert abs(d.v - 0.2) <= p.accel * p.control_period + 1e-9
    assert 0 < d.omega <= p.acc_lim_theta * p.control_period + 1e-9


def test_stops_before_a_wall_it_cannot_pass():
    # A wall across the whole way, the goal behind it.
    w = world({"shape": "box", "center": [4.0, 5.0], "size": [0.2, 40.0]})
    planner = DWA(DWAParams(goal=(8.0, 5.0), cruise_speed=0.3))
    pose, v, omega = (2.0, 5.0, 0.0), 0.3, 0.0
    closest = math.inf
    for _ in range(300):
        d = planner.step(cycle(w, pose, (8.0, 5.0), velocity=(v, omega)))
        v, omega = d.v, d.omega
        pose = drive(pose, v, omega)
        closest = min(closest, 3.9 - pose[0])
    assert closest > 0.2  # the robot disc never reached the wall
    assert v * math.cos(pose[2]) < 0.01  # not driving into it


def test_brakes_for_a_mover_that_would_meet_it_within_braking_distance():
    p = DWAParams(goal=(8.0, 5.0), cruise_speed=0.3)
    c = cycle(world(), (2.0, 5.0, 0.0), (8.0, 5.0), velocity=(0.3, 0.0))
    free = plan(c, p)
    mover = Obstacles(positions=np.array([[2.55, 5.0]]), velocities=np.array([[-0.5, 0.0]]),
                      radii=np.array([0.2]))
    head_on = plan(cycle(world(), (2.0, 5.0, 0.0), (8.0, 5.0), velocity=(0.3, 0.0),
                         movers=mover), p)
    assert free.v == 0.3 and free.omega == 0.0
    assert head_on.v < free.v  # brakes: the mover would meet it within its braking distance
