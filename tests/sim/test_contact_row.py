"""The record's last row at a collision is the robot's state at the contact: position,
heading and speed each between the two ends of the tick, in the same proportion, not
the position at the contact beside the heading and speed of the tick's end."""

from __future__ import annotations

import pytest

from zenav.services.geometry import wrap_angle
from zenav.sim.kinematics import step_robot
from zenav.sim.params import Params
from zenav.sim.scenario import parse_scenario
from zenav.sim.simulation import Simulation


def test_the_contact_row_holds_the_state_at_the_contact() -> None:
    scenario = parse_scenario({
        "name": "turn-into-box", "world": {"size": [6.0, 6.0], "cell": 0.5},
        "robot": {"start": [2.0, 3.0], "heading_deg": 0.0, "goal": [5.5, 3.0], "speed": 0.5,
                  "radius": 0.2},
        "obstacles": [{"shape": "box", "center": [2.7, 3.0], "size": [0.4, 2.0]}],
        "duration": 20.0}, "turn-into-box.yaml")
    sim = Simulation(scenario, Params(scenario="turn-into-box.yaml"))
    while True:
        before = sim.state
        sim.step(1.0, 0.8)  # speeding up and turning left into the box's face
        if sim.outcome is not None:
            break
    assert sim.outcome == "collision"
    p = sim.params
    end = step_robot(before, 1.0, 0.8, sim.dt, v_max=scenario.robot.effective_max_speed,
                     accel=p.base_accel, decel=p.base_decel, omega_max=p.max_omega,
                     alpha_accel=p.base_angular_accel, alpha_decel=p.base_angular_accel)
    t0, t_hit = sim.rows[-2][0], sim.rows[-1][0]
    frac = (t_hit - t0) / sim.dt
    assert 0.0 < frac < 1.0  # the contact falls inside the tick
    _, x, y, heading, v = sim.rows[-1]
    assert end.v > before.v and wrap_angle(end.heading - before.heading) > 0.0  # both change
    assert x == pytest.approx(before.x + frac * (end.x - before.x), abs=1e-9)
    assert y == pytest.approx(before.y + frac * (end.y - before.y), abs=1e-9)
    assert heading == pytest.approx(
        wrap_angle(before.heading + frac * wrap_angle(end.heading - before.heading)), abs=1e-9)
    assert v == pytest.approx(before.v + frac * (end.v - before.v), abs=1e-9)
    assert (sim.state.heading, sim.state.v) == (heading, v)
