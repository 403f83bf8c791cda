"""The speed and safety stage (safety.py) on hand-made geometry, and inside a planner
cycle: roll-outs, contact times worked by hand, and the choices it makes."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import numpy.typing as npt
import pytest

from zenav.services.planner import safety
from zenav.services.planner.decide import Planner
from zenav.services.planner.params import Params
from zenav.services.planner.prediction import Obstacle

SETTINGS = safety.Settings(horizon=6.0, step=0.2, margin=0.1, growth=0.0, comfort=0.6,
                           tau=1.5, fan_step=math.radians(15.0),
                           speeds=(0.0, 0.25, 0.5, 0.75, 1.0), turn_cost=0.3)


def robot(speed: float = 0.0, heading: float = 0.0) -> safety.Robot:
    return safety.Robot(x=0.0, y=0.0, heading=heading, speed=speed, radius=0.3,
                        max_speed=1.0, max_omega=1.0, heading_gain=1.5, accel=0.5, decel=1.0)


def movers(*rows: tuple[float, float, float, float]) -> safety.Movers:
    """Movers of radius 0.3 from (x, y, vx, vy) rows, each seen at its speed now."""
    a = np.array(rows, dtype=np.float64).reshape(-1, 4)
    return safety.Movers(a[:, :2], a[:, 2:], np.full(len(a), 0.3), np.hypot(a[:, 2], a[:, 3]))


def times(step: float = 0.2, horizon: float = 6.0) -> npt.NDArray[np.float64]:
    return step * np.arange(1, round(horizon / step) + 1, dtype=np.float64)


def test_rollout_straight_speeds_up_within_accel() -> None:
    # From standstill toward heading 0 at 1 m/s: v = 0.1, 0.2, ... (0.5 m/s^2 x 0.2 s),
    # and each step moves v * 0.2 after the speed change.
    xs, ys = safety.rollout(robot(), np.array([0.0]), np.array([1.0]), times())
    v = np.minimum(0.1 * np.arange(1, 31), 1.0)
    assert np.allclose(xs[0], np.cumsum(v * 0.2))
    assert np.allclose(ys[0], 0.0)


def test_rollout_turns_at_the_turn_limit_before_driving() -> None:
    # A heading 90 degrees off: the error stays above 1/1.5 rad for the first steps, so
    # the robot turns at 1 rad/s, and its speed waits for the cosine of the error.
    xs, ys = safety.rollout(robot(), np.array([math.pi / 2]), np.array([1.0]), times())
    assert abs(xs[0, 0]) < 1e-12 and abs(ys[0, 0]) < 1e-12  # cos(90 - 11.5 deg) ~ 0.2...
    assert ys[0, -1] > 3.0 and abs(xs[0, -1]) < 1.0  # ...then on its way up +y


def test_contact_time_of_a_head_on_walker_worked_by_hand() -> None:
    # The robot stands at the origin; a walker at (3.1, 0) comes at 1 m/s. Contact is
    # within 0.3 + 0.3 + 0.1 / 2 = 0.65 m, so when 3.1 - t < 0.65: t > 2.45 s, first
    # sampled at 2.6 s.
    t = times()
    xs, ys = safety.rollout(robot(), np.array([0.0]), np.array([0.0]), t)
    cost, first, who = safety.contact_costs(xs, ys, t, movers((3.1, 0.0, -1.0, 0.0)), 0.3,
                                            SETTINGS)
    assert math.isclose(float(first[0]), 2.6)
    assert int(who[0]) == 0
    # The worst sample, discounted: at 3.0 s the walker's centre is 0.1 m off, 0.55 m
    # into the 0.65 m clearance (3.2 s is as deep, and later).
    assert math.isclose(float(cost[0]), 10.0 * (1.0 + 0.55 / 0.65) / (1.0 + 3.0 / 1.5))


def test_growth_brings_contact_forward() -> None:
    # With 0.2 m of clearance per metre the walker covers: 3.1 - t < 0.65 + 0.2 t,
    # t > 2.0417 s, first sampled at 2.2 s.
    t = times()
    xs, ys = safety.rollout(robot(), np.array([0.0]), np.array([0.0]), t)
    grown = safety.Settings(**{**SETTINGS.__dict__, "growth": 0.2})
    _, first, _ = safety.contact_costs(xs, ys, t, movers((3.1, 0.0, -1.0, 0.0)), 0.3, grown)
    assert math.isclose(float(first[0]), 2.2)


def test_a_pass_outside_the_comfort_band_costs_nothing() -> None:
    # A walker crossing 2 m ahead of a standing robot never comes within 0.65 + 0.6 m.
    t = times()
    xs, ys = safety.rollout(robot(), np.array([0.0]), np.array([0.0]), t)
    cost, first, who = safety.contact_costs(xs, ys, t, movers((2.0, -3.0, 0.0, 1.0)), 0.3,
                                            SETTINGS)
    assert float(cost[0]) == 0.0 and math.isinf(float(first[0])) and int(who[0]) == -1


def test_a_safe_proposal_is_kept() -> None:
    choice = safety.choose(robot(1.0), (0.0, 1.0), movers((0.0, 5.0, 1.0, 0.0)),
                           np.array([6.0, 0.0]), None, None, SETTINGS)
    assert choice.kept and choice.heading == 0.0 and choice.speed == 1.0


def test_a_stopped_robot_steps_aside_from_a_walker_coming_from_behind() -> None:
    # The local layer says wait; a walker that does not see the robot comes from behind
    # at 1 m/s. Waiting is contact in under 3 s (the walker made the change); the choice
    # drives off (ahead, keeping the gap: 3 - t + 0.25 t^2 >= 2 m while speeding up).
    m = movers((-3.0, 0.0, 1.0, 0.0))
    choice = safety.choose(robot(), (0.0, 0.0), m, np.array([6.0, 0.0]), None, None,
                           SETTINGS)
    assert not choice.kept and choice.mover == 0
    assert choice.speed > 0.0 and math.isinf(choice.contact)  # the chosen roll-out is clear
    t = times()
    xs, ys = safety.rollout(robot(), np.array([choice.heading]), np.array([choice.speed]), t)
    _, first, _ = safety.contact_costs(xs, ys, t, m, 0.3, SETTINGS)
    assert math.isinf(float(first[0]))  # ...as its own roll-out shows


def test_a_walker_crossing_just_ahead_is_not_driven_into() -> None:
    # Driving on at 1 m/s meets a walker crossing 1.5 m ahead; the choice touches nobody.
    m = movers((1.5, -1.5, 0.0, 1.0))
    choice = safety.choose(robot(1.0), (0.0, 1.0), m, np.array([6.0, 0.0]), None, None,
                           SETTINGS)
    assert not choice.kept and choice.mover == 0
    assert math.isinf(choice.contact)


def test_the_map_rules_out_headings_into_a_wall() -> None:
    # Everything at x > 0.8 is a wall; a walker comes from behind. The robot goes
    # sideways or back, never forward into the wall.
    def wall(xs: npt.NDArray[np.float64], ys: npt.NDArray[np.float64]
             ) -> npt.NDArray[np.bool_]:
        return np.asarray((xs > 0.8).any(axis=1))

    choice = safety.choose(robot(), (0.0, 0.0), movers((-3.0, 0.0, 1.0, 0.0)),
                           np.array([6.0, 0.0]), wall, None, SETTINGS)
    assert math.cos(choice.heading) < 0.5


def test_the_last_heading_wins_a_tie() -> None:
    # A walker comes head-on along the robot's line: stepping left or right is the same
    # but for the turn cost from the last heading chosen.
    m = movers((2.5, 0.0, -1.0, 0.0))
    left = safety.choose(robot(), (0.0, 0.0), m, np.array([6.0, 0.0]), None, math.pi / 2,
                         SETTINGS)
    right = safety.choose(robot(), (0.0, 0.0), m, np.array([6.0, 0.0]), None, -math.pi / 2,
                          SETTINGS)
    assert math.sin(left.heading) >= 0.0 >= math.sin(right.heading)


def crowd_planner(speed_check: bool) -> Planner:
    return Planner(Params.model_validate({
        "goal": (8.0, 0.0), "start": (0.0, 0.0), "cruise_speed": 1.0, "max_speed": 1.0,
        "robot_radius": 0.3, "use_map": False, "speed_check": speed_check}))


def test_planner_cycle_does_not_wait_for_a_crosser_with_a_walker_behind() -> None:
    # A crosser ahead (it meets the robot's line at x = 1.5 in 1.5 s): the paper's (e)
    # says stop. A walker that does not see the robot comes from behind on its line.
    # Without the stage the robot stops and is walked into; with it, it steps aside.
    crosser = Obstacle(3, "dynamic", (1.5, -1.2), (0.0, 0.8), 0.3, (3, 3, -2, -2))
    walker = Obstacle(7, "dynamic", (-2.0, 0.0), (1.0, 0.0), 0.3, (-4, -4, 0, 0))
    decisions = []
    for check in (False, True):
        p = crowd_planner(check)
        for t in (0.0, 0.1):
            d = p.step((0.0, 0.0, 0.0), [crosser, walker], t)
        decisions.append(d)
    waits, steps_aside = decisions
    assert (waits.action, waits.speed) == ("stop", 0.0) and waits.scenario == "e"
    assert steps_aside.action == "morphin" and steps_aside.speed > 0.0
    assert abs(steps_aside.target[1]) > 0.5  # off the line the walker comes along


def test_a_top_speed_fades_while_the_mover_stands_and_comes_back_at_once() -> None:
    top = {1: 1.0, 2: 1.0, 4: 1.0}
    faded = safety.faded_top_speeds(top, {1: 0.0, 2: 1.2, 3: 0.5, 4: 0.5}, dt=2.0, fade=2.0)
    assert faded[1] == pytest.approx(math.exp(-1.0))  # stood for one fade time
    assert faded[2] == 1.2  # faster than ever: the new top
    assert faded[3] == 0.5  # new: its speed now
    assert faded[4] == 1.0  # held up to half its pace by others: may set off again
    assert safety.faded_top_speeds(top, {1: 0.0}, dt=2.0, fade=0.0) == {1: 1.0}  # 0: never
    again = safety.faded_top_speeds(faded, {1: 0.9}, dt=0.1, fade=2.0)
    assert again[1] == 0.9  # walking again: its speed, not the faded top


def test_a_robot_inside_a_walkers_clearance_leaves_instead_of_standing() -> None:
    # crowd-2601 of `zenav bench nav --seed 2600` at 10.8 s, about the robot: it stands
    # facing south-west (its last heading west), radius 0.2 m, top speed 0.5 m/s, asked
    # to stop; a walker 0.40 m away to its south-west (radius 0.17 m, inside the
    # clearance of 0.42 m) walks north-east into it at 0.12 m/s. Every candidate touches
    # it from the first step, so without the cap the stop costs about what leaving does
    # and the turn cost from the last heading keeps it: the robot was walked into.
    p = Params()
    s = safety.Settings(horizon=p.safety_horizon, step=p.safety_step, margin=p.safety_margin,
                        growth=p.safety_growth, comfort=p.safety_comfort, tau=p.safety_tau,
                        fan_step=math.radians(p.safety_fan_deg), speeds=p.safety_speeds,
                        turn_cost=p.safety_turn_cost)
    standing = safety.Robot(x=0.0, y=0.0, heading=math.radians(-141.0), speed=0.0,
                            radius=0.2, max_speed=0.5, max_omega=p.max_omega,
                            heading_gain=p.heading_gain, accel=p.accel, decel=p.decel)
    walker = safety.Movers(np.array([[-0.28, -0.28]]), np.array([[0.07, 0.10]]),
                           np.array([0.17]), np.array([0.12]))
    on = dataclasses.replace(s, from_inside=True)
    assert np.isfinite(safety.holding((0.0, 0.0), walker, 0.2, on)).all()  # held now
    carrot, west = np.array([-2.0, 0.0]), -3.13
    old = safety.choose(standing, (west, 0.0), walker, carrot, None, west,
                        dataclasses.replace(s, from_inside=False))
    assert old.kept and old.speed == 0.0  # the stop, walked into
    new = safety.choose(standing, (west, 0.0), walker, carrot, None, west, on)
    assert not new.kept and new.speed > 0.0
    # Its roll-out comes less close to the walker than standing does. (A unicycle
    # turning at 1 rad/s cannot get clear in time here: every way out touches the
    # capped clearance within its first step, and they cost within 1 % of one another,
    # so which of them wins is the progress term's call. In the run the robot was
    # walked into all the same.)
    t = times()
    xs, ys = safety.rollout(standing, np.array([new.heading, west]),
                            np.array([new.speed, 0.0]), t)
    gap = np.hypot(xs - (-0.28 + 0.07 * t), ys - (-0.28 + 0.10 * t))
    assert gap[0].min() > gap[1].min() + 0.05


def test_inside_a_clearance_a_contact_costs_more_than_any_pass_outside_it() -> None:
    # unseen-walkers-doorway-152015 of `zenav bench nav --seed 152000`, reduced: a walker
    # whose clearance holds the robot (0.40 m apart, clearance 0.45 m) comes 2 cm closer
    # in the next step if the robot stands; stepping 3 cm away keeps it 1 cm outside the
    # capped clearance, within ``comfort``. Standing must cost more: with a contact cost
    # of 10 x its depth alone (0.5 here, before the time weight) it cost less than the
    # near pass (0.98), and the robot stood and was walked into.
    s = dataclasses.replace(SETTINGS, growth=0.0, from_inside=True)
    walker = safety.Movers(np.array([[0.4, 0.0]]), np.array([[-0.1, 0.0]]),
                           np.array([0.2]), np.array([0.2]))
    t = np.array([0.2])
    inside = safety.holding((0.0, 0.0), walker, 0.2, s)
    assert inside[0] == pytest.approx(0.4)  # held, its clearance capped at 0.4 m
    xs, ys = np.array([[0.0], [-0.03]]), np.array([[0.0], [0.0]])  # stand; step away
    cost, first_t, _ = safety.contact_costs(xs, ys, t, walker, 0.2, s, inside)
    assert first_t[0] == pytest.approx(0.2) and math.isinf(first_t[1])
    weight = 1.0 / (1.0 + 0.2 / s.tau)
    assert cost[1] == pytest.approx((1.0 - 0.01 / s.comfort) * weight)
    assert cost[0] == pytest.approx((1.0 + 10.0 * 0.02 / 0.4) * weight)
    assert cost[0] > cost[1]  # 10 x the depth alone: 0.5 x weight, below the pass


def test_outside_every_clearance_the_cap_changes_nothing() -> None:
    # The robot clear of every walker: the same choice with the setting on and off.
    m = movers((-3.0, 0.0, 1.0, 0.0), (1.5, -1.5, 0.0, 1.0))
    for proposal in ((0.0, 0.0), (0.0, 1.0)):
        off = safety.choose(robot(), proposal, m, np.array([6.0, 0.0]), None, 0.3, SETTINGS)
        on = safety.choose(robot(), proposal, m, np.array([6.0, 0.0]), None, 0.3,
                           dataclasses.replace(SETTINGS, from_inside=True))
        assert off == on


def test_a_roll_out_stops_at_the_goal() -> None:
    """Past the point where it comes within ``arrive_within`` of the goal, a roll-out
    stands there: the planner stops for good at that distance."""
    near_goal = dataclasses.replace(robot(speed=1.0), goal=(1.0, 0.0), arrive_within=0.15)
    xs, ys, ends = safety.drive_out(near_goal, np.array([0.0]), np.array([1.0]), times())
    arrival = int(ends[0]) - 1
    assert 0.85 <= xs[0, arrival] <= 1.0 and xs[0, arrival - 1] < 0.85
    assert np.all(xs[0, arrival:] == xs[0, arrival]) and np.all(ys[0] == 0.0)
    free = safety.rollout(robot(speed=1.0), np.array([0.0]), np.array([1.0]), times())[0]
    assert np.array_equal(xs[0, :ends[0]], free[0, :ends[0]]) and free[0, -1] > 5.0


def test_what_lies_past_the_goal_does_not_hold_the_robot_short_of_it() -> None:
    """A crowd case (circle crossing, visible, case 1627) timed out 0.34 m from the goal:
    a human standing at its own goal 0.6 m beyond the robot's was in the map, every
    roll-out toward the goal ran on through its inflation, and the robot stood. A
    roll-out that stops at the goal keeps the local layer's command."""
    start = dataclasses.replace(robot(heading=math.pi), x=0.34)
    human = np.array([-0.56, -0.25])

    def blocked(xs: npt.NDArray[np.float64], ys: npt.NDArray[np.float64]
                ) -> npt.NDArray[np.bool_]:
        return np.asarray(np.any(np.hypot(xs - human[0], ys - human[1]) < 0.55, axis=1))

    carrot = np.array([-0.66, 0.0])  # the look-ahead point lies past the goal
    nobody = movers()
    ahead = (math.pi, 1.0)
    assert not safety.keeps_clear(start, ahead, nobody, blocked, SETTINGS)
    with_goal = dataclasses.replace(start, goal=(0.0, 0.0), arrive_within=0.15)
    assert safety.keeps_clear(with_goal, ahead, nobody, blocked, SETTINGS)
    choice = safety.choose(with_goal, ahead, nobody, carrot, blocked, math.pi, SETTINGS)
    assert choice.kept and choice.speed == 1.0


def test_a_robot_beside_its_goal_turns_to_it_rather_than_stand() -> None:
    """A crowd case (circle crossing, visible, 180 degrees, case 490) timed out 0.42 m from
    the goal: the robot faced 75 degrees off it, a walker stood past it, and every fast
    roll-out toward the goal swung past it into the map. The way left was worth 0.07 of a
    cost, the turn to the goal 0.39, so standing won every cycle. A roll-out that arrives
    ends the run and pays no turn cost."""
    start = dataclasses.replace(robot(heading=math.pi / 2), goal=(0.4, 0.0), arrive_within=0.15)

    def blocked(xs: npt.NDArray[np.float64], ys: npt.NDArray[np.float64]
                ) -> npt.NDArray[np.bool_]:
        return np.asarray(np.any(np.hypot(xs - 1.2, ys) < 0.65, axis=1))

    toward_goal = (0.0, 1.0)
    assert not safety.keeps_clear(start, toward_goal, movers(), blocked, SETTINGS)
    choice = safety.choose(start, toward_goal, movers(), np.array([0.4, 0.0]), blocked,
                           math.pi / 2, SETTINGS)
    assert choice.speed > 0.0
    xs, ys, _ = safety.drive_out(start, np.array([choice.heading]), np.array([choice.speed]),
                                 times())
    assert math.hypot(xs[0, -1] - 0.4, ys[0, -1]) <= 0.15
