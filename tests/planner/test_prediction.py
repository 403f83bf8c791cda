"""Collision prediction (``prediction.assess``: one obstacle through ``assess_all``, which
the planner calls on all of them at once) on
hand-made geometry: one case per scenario letter (b)-(g), the planner's (a) and (h), and
the cases either side of every threshold (the 12 s horizon, cos <= -0.8 for head-on,
cos >= 0.8 for same-way, moving_speed).

Common set-up, worked by hand below: the robot at the origin going +x at V_R = 0.1 m/s
along a 6 m path; robot radius 0.2 m, obstacle radius 0.2 m, margin 0.1 m, so the
footprints meet below a clearance of 0.5 m; cells of 0.5 m.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from zenav.schemas.messages import ObstacleKind
from zenav.services.planner.decide import Planner
from zenav.services.planner.params import Params
from zenav.services.planner.prediction import (
    Assessment,
    MeetRule,
    Obstacle,
    assess,
    at_the_pcp_together,
)

ROBOT = np.array([0.0, 0.0])
EAST = np.array([1.0, 0.0])
V_R = 0.1
PARAMS = Params(goal=(6.0, 0.0), start=(0.0, 0.0), confirm_time=0.0)


def ob(position: tuple[float, float], velocity: tuple[float, float] = (0.0, 0.0),
       kind: ObstacleKind = "dynamic", cells: tuple[int, int, int, int] = (0, 0, 0, 0),
       ob_id: int = 1) -> Obstacle:
    return Obstacle(id=ob_id, kind=kind, position=position, velocity=velocity, radius=0.2,
                    cells=cells)


def judge(obstacle: Obstacle, horizon: float = 12.0,
          meet_rule: MeetRule = "closest") -> Assessment | None:
    return assess(ROBOT, EAST, V_R, 6.0, obstacle, robot_radius=0.2, margin=0.1, cell=0.5,
                  horizon=horizon, moving_speed=0.03, head_on_cos=-0.8, same_way_cos=0.8,
                  meet_rule=meet_rule)


def heading(cos_phi: float) -> tuple[float, float]:
    """A unit direction with the given cosine to +x, its y part positive."""
    return cos_phi, math.sqrt(1.0 - cos_phi * cos_phi)


def meeting(speed: float, cos_phi: float, t_meet: float) -> tuple[tuple[float, float],
                                                                tuple[float, float]]:
    """(position, velocity) of a mover at ``speed`` in direction cos_phi that reaches the
    robot's position at t_meet exactly: M = (V_R t_meet, 0), p0 = M - v t_meet."""
    ux, uy = heading(cos_phi)
    v = (speed * ux, speed * uy)
    return (V_R * t_meet - v[0] * t_meet, -v[1] * t_meet), v


# --- one case per letter ----------------------------------------------------------------


def test_b_static_on_the_path() -> None:
    """A box in cell (4, 0): the square x 1.75..2.25, y -0.25..0.25. The path is sampled
    every 0.125 m; the robot's disc plus margin (0.3 m) first reaches the square at
    s = 1.5 m (1.75 - 1.5 = 0.25 < 0.3; at 1.375 it is 0.375). Robot time 1.5 / 0.1 = 15 s,
    obstacle time infinite; the PCP is abreast of the centre, (2, 0).
    Response: Morphin (a detour)."""
    a = judge(ob((2.0, 0.0), kind="static", cells=(4, 4, 0, 0)))
    assert a is not None and a.letter == "b" and a.threat
    assert a.pcp == pytest.approx((2.0, 0.0))
    assert a.robot_distance == pytest.approx(1.5)
    assert a.robot_time == pytest.approx(15.0) and math.isinf(a.obstacle_time)


def test_c_crosser_passes_first() -> None:
    """From (3, -1) going +y at 0.5 m/s: the paths cross at PCP (3, 0); the obstacle is
    there at 1 / 0.5 = 2 s, the robot at 3 / 0.1 = 30 s. Relative motion (-0.1, 0.5) from
    (3, -1): closest at t = 0.8 / 0.26 = 3.08 s, 2.75 m apart: no threat.
    Response: keep going."""
    a = judge(ob((3.0, -1.0), (0.0, 0.5)))
    assert a is not None and a.letter == "c" and not a.threat
    assert a.pcp == pytest.approx((3.0, 0.0))
    assert (a.robot_time, a.obstacle_time) == pytest.approx((30.0, 2.0))


def test_d_crosser_comes_after() -> None:
    """From (3, -2) going +y at 0.05 m/s: PCP (3, 0), obstacle there at 40 s, robot at
    30 s. Within 12 s the closest is at t = 12: (3 - 1.2, -2 + 0.6), 2.28 m: no threat.
    Response: keep going."""
    a = judge(ob((3.0, -2.0), (0.0, 0.05)))
    assert a is not None and a.letter == "d" and not a.threat
    assert a.pcp == pytest.approx((3.0, 0.0))
    assert (a.robot_time, a.obstacle_time) == pytest.approx((30.0, 40.0))


def test_e_crosser_would_meet_the_robot() -> None:
    """From (1, -2) going +y at 0.2 m/s: PCP (1, 0), obstacle there at 2 / 0.2 = 10 s,
    robot at 1 / 0.1 = 10 s: they meet (relative motion (-0.1, 0.2) brings (1, -2) to 0 at
    t = 10). Response (crossing_response): speeding up would clear the zone at
    (1 + 0.5) / 0.2 + 2 = 9.5 s, after the obstacle enters it at 10 - 0.5 / 0.2 = 7.5 s;
    slowing to arrive after it leaves (12.5 s) means (1 - 0.5) / 13.5 = 0.037 m/s, below
    0.4 V_R = 0.04: stop."""
    a = judge(ob((1.0, -2.0), (0.0, 0.2)))
    assert a is not None and a.letter == "e" and a.threat
    assert a.pcp == pytest.approx((1.0, 0.0))
    assert (a.robot_time, a.obstacle_time) == pytest.approx((10.0, 10.0))
    assert a.min_gap == pytest.approx(-0.5)
    assert Planner(PARAMS).crossing_response(a, None) == ("stop", 0.0)


def test_f_head_on() -> None:
    """From (3, 0) going -x at 0.3 m/s: cos = -1. Closing at 0.4 m/s from 3 m: they meet at
    t = 7.5 s, the robot 0.75 m along: PCP (0.75, 0), both arrival times 7.5 s.
    Response: Morphin."""
    a = judge(ob((3.0, 0.0), (-0.3, 0.0)))
    assert a is not None and a.letter == "f" and a.threat
    assert a.pcp == pytest.approx((0.75, 0.0))
    assert (a.robot_distance, a.robot_time, a.obstacle_time) == pytest.approx((0.75, 7.5, 7.5))


def test_g_slower_ahead_the_same_way() -> None:
    """From (1, 0) going +x at 0.05 m/s: closing at 0.05 m/s from 1 m, the closest within
    12 s is at 12 s, 0.4 m apart < 0.5: a threat; cos = 1: (g). PCP where the robot is at
    12 s, (1.2, 0). Response (follow_response): free gap 1 - 0.2 - 0.2 = 0.6 m = the gap
    kept, so the robot slows to the obstacle's 0.05 + 0.3 (0.6 - 0.6) = 0.05 m/s."""
    a = judge(ob((1.0, 0.0), (0.05, 0.0)))
    assert a is not None and a.letter == "g" and a.threat
    assert a.pcp == pytest.approx((1.2, 0.0))
    assert (a.robot_time, a.obstacle_time) == pytest.approx((12.0, 12.0))
    assert a.along_speed == pytest.approx(0.05)
    action, speed = Planner(PARAMS).follow_response(a)
    assert action == "slow" and speed == pytest.approx(0.05)


def test_a_and_h_are_the_planners() -> None:
    """(a): nothing in the way, keep going at V_R. (h): the box of (b) and the crosser of
    (e) at once: a detour round the box at the speed the crosser allows (here a stop)."""
    clear = Planner(PARAMS).step((0.0, 0.0, 0.0), [], stamp=1.0)
    assert (clear.scenario, clear.action) == ("a", "keep")
    assert clear.speed == pytest.approx(V_R)
    both = Planner(PARAMS).step((0.0, 0.0, 0.0), [
        ob((2.0, 0.0), kind="static", cells=(4, 4, 0, 0), ob_id=1),
        ob((1.0, -2.0), (0.0, 0.2), ob_id=2)], stamp=1.0)
    assert both.scenario == "h"
    assert {a.obstacle.id: a.letter for a in both.notes if a.threat} == {1: "b", 2: "e"}


# --- the thresholds ------------------------------------------------------------------


def test_the_12_s_horizon() -> None:
    """A crosser the robot meets just after 12 s. Relative speed |(-0.1, 0.2)| = 0.2236 m/s,
    so at t = 12 the two are 0.2236 (t_meet - 12) apart: a threat while that is < 0.5.

    * robot at PCP (1.40, 0) at 14.0 s, obstacle from (1.40, -2.82) at 14.1 s: at 12 s
      (0.2, -0.42) apart, 0.465 m: (e);
    * robot at PCP (1.42, 0) at 14.2 s, obstacle from (1.42, -2.86) at 14.3 s: at 12 s
      (0.22, -0.46), 0.510 m: not a threat, and the robot is first: (d). The paper's (e)
      ("both at the PCP at the same time") would call both (e): 0.1 s apart.
    * the second with a 15 s horizon: closest at t = 14.28 s, 0.009 m: (e).
    """
    inside = judge(ob((1.40, -2.82), (0.0, 0.2)))
    assert inside is not None and inside.letter == "e"
    assert (inside.robot_time, inside.obstacle_time) == pytest.approx((14.0, 14.1))
    outside = judge(ob((1.42, -2.86), (0.0, 0.2)))
    assert outside is not None and outside.letter == "d" and not outside.threat
    assert (outside.robot_time, outside.obstacle_time) == pytest.approx((14.2, 14.3))
    longer = judge(ob((1.42, -2.86), (0.0, 0.2)), horizon=15.0)
    assert longer is not None and longer.letter == "e"


@pytest.mark.parametrize(("cos_phi", "letter"), [(-0.81, "f"), (-0.79, "e")])
def test_head_on_below_cos_minus_0_8(cos_phi: float, letter: str) -> None:
    """A 0.3 m/s mover that reaches the robot at t = 5 s, (0.5, 0), coming in at
    cos = -0.81 (head-on, (f)) or -0.79 (a crosser, (e)); e.g. cos -0.81: v = (-0.243,
    0.1759), from (0.5 + 1.215, -0.8796)."""
    position, velocity = meeting(0.3, cos_phi, 5.0)
    a = judge(ob(position, velocity))
    assert a is not None and a.threat and a.letter == letter


@pytest.mark.parametrize(("cos_phi", "letter"), [(0.81, "g"), (0.79, "e")])
def test_same_way_above_cos_0_8(cos_phi: float, letter: str) -> None:
    """A 0.05 m/s mover ahead that the robot catches at t = 10 s, (1, 0), going at
    cos = 0.81 (the same way, (g)) or 0.79 (a crosser, (e))."""
    position, velocity = meeting(0.05, cos_phi, 10.0)
    a = judge(ob(position, velocity))
    assert a is not None and a.threat and a.letter == letter


def test_moving_speed() -> None:
    """A 'dynamic' obstacle on the path at (2, 0) drifting +y: at 0.029 m/s (below
    moving_speed 0.03) it is taken as standing, (b); at 0.031 m/s it is a crosser already
    at its PCP (2, 0) (obstacle time 0 < robot time 20 s) that moves off the path: within
    12 s the closest is (0.8, 0.372), 0.88 m: (c)."""
    slow = judge(ob((2.0, 0.0), (0.0, 0.029), cells=(4, 4, 0, 0)))
    assert slow is not None and slow.letter == "b"
    moving = judge(ob((2.0, 0.0), (0.0, 0.031), cells=(4, 4, 0, 0)))
    assert moving is not None and moving.letter == "c" and not moving.threat
    assert (moving.robot_time, moving.obstacle_time) == pytest.approx((20.0, 0.0))


def test_a_static_kind_never_moves() -> None:
    """Whatever its velocity, an obstacle the tracker calls static is answered as (b)."""
    a = judge(ob((2.0, 0.0), (-0.5, 0.0), kind="static", cells=(4, 4, 0, 0)))
    assert a is not None and a.letter == "b"


def test_off_the_path_and_behind_are_ignored() -> None:
    """A box 1 m beside the path (cells y 2) and a crosser whose paths crossed behind the
    robot relate to nothing: None."""
    assert judge(ob((2.0, 1.0), kind="static", cells=(4, 4, 2, 2))) is None
    assert judge(ob((-2.0, 1.0), (0.0, 0.5))) is None


# --- the paper's (e): at the PCP at the same time (meet_rule="same_time") ------------------
# With the common set-up the clearance is c = 0.5 m. A crosser going +y at v_O from
# (x0, -q) has its PCP at (x0, 0), s = x0 along the robot's path and q along its own. The
# robot is at the PCP (within c of it) from (s - c) / V_R to (s + c) / V_R, that is
# [10 s - 5, 10 s + 5]; the crosser from (q - c) / v_O to (q + c) / v_O. (e) when the two
# overlap after now; otherwise (c) or (d) by the arrival times, as under "closest".


def paper(obstacle: Obstacle, horizon: float = 12.0) -> Assessment | None:
    return judge(obstacle, horizon, meet_rule="same_time")


def test_same_time_e_as_the_paper_draws_it() -> None:
    """From (1, -2) at 0.2 m/s: the robot at the PCP (1, 0) over [5, 15] s, the crosser
    over [(2 - 0.5) / 0.2, (2 + 0.5) / 0.2] = [7.5, 12.5] s: they overlap, (e); both
    centres arrive at 10 s. The same answer as "closest"."""
    a = paper(ob((1.0, -2.0), (0.0, 0.2)))
    assert a is not None and a.letter == "e" and a.threat
    assert (a.robot_time, a.obstacle_time) == pytest.approx((10.0, 10.0))


def test_same_time_c_and_d_by_hand() -> None:
    """(c): from (3, -1) at 0.5 m/s, the crosser is at the PCP over [1, 3] s, the robot
    over [25, 35] s: no overlap, the crosser first. (d): from (3, -5) at 0.1 m/s, the
    crosser over [45, 55] s, after the robot has left at 35 s."""
    c = paper(ob((3.0, -1.0), (0.0, 0.5)))
    assert c is not None and c.letter == "c" and not c.threat
    d = paper(ob((3.0, -5.0), (0.0, 0.1)))
    assert d is not None and d.letter == "d" and not d.threat
    assert (d.robot_time, d.obstacle_time) == pytest.approx((30.0, 50.0))


def test_same_time_has_no_horizon() -> None:
    """The crosser of the (d) case under "closest": from (3, -2) at 0.05 m/s it is at the
    PCP over [(2 - 0.5) / 0.05, (2 + 0.5) / 0.05] = [30, 50] s, the robot over [25, 35] s:
    they overlap over [30, 35] s, (e), although the closest approach (about 30 s ahead,
    robot at (3.2, 0) and crosser at (3, -0.4) at 32 s: 0.447 m < 0.5) lies beyond the
    12 s horizon, where "closest" calls it (d). Likewise the horizon case (1.42, -2.86) at
    0.2 m/s: robot [9.2, 19.2] s, crosser [11.8, 16.8] s: (e) under the paper's rule."""
    far = ob((3.0, -2.0), (0.0, 0.05))
    closest = judge(far)
    assert closest is not None and closest.letter == "d"
    a = paper(far)
    assert a is not None and a.letter == "e" and a.threat
    assert (a.robot_time, a.obstacle_time) == pytest.approx((30.0, 40.0))
    b = paper(ob((1.42, -2.86), (0.0, 0.2)))
    assert b is not None and b.letter == "e"


@pytest.mark.parametrize(("q", "letter"), [(1.99, "c"), (2.01, "e")])
def test_same_time_the_crosser_leaves_as_the_robot_arrives(q: float, letter: str) -> None:
    """From (3, -q) at 0.1 m/s the crosser leaves the PCP at (q + 0.5) / 0.1 s; the robot
    arrives at (3 - 0.5) / 0.1 = 25 s. q = 1.99: gone at 24.9 s, (c) (there at 19.9 s,
    before the robot's 30 s); q = 2.01: still there at 25 s (until 25.1 s), (e)."""
    a = paper(ob((3.0, -q), (0.0, 0.1)))
    assert a is not None and a.letter == letter and a.threat == (letter == "e")


@pytest.mark.parametrize(("q", "letter"), [(3.99, "e"), (4.01, "d")])
def test_same_time_the_crosser_arrives_as_the_robot_leaves(q: float, letter: str) -> None:
    """From (3, -q) at 0.1 m/s the crosser arrives at (q - 0.5) / 0.1 s; the robot leaves
    the PCP at (3 + 0.5) / 0.1 = 35 s. q = 3.99: arrives at 34.9 s, (e); q = 4.01: at
    35.1 s, after the robot, (d) (centres at 30 s and 40.1 s)."""
    a = paper(ob((3.0, -q), (0.0, 0.1)))
    assert a is not None and a.letter == letter and a.threat == (letter == "e")


def test_same_time_intervals_that_only_touch_do_not_meet() -> None:
    """Robot 3 m and crosser 2 m from the PCP, both at 0.1 m/s, c = 0.5: the robot is
    there over [25, 35] s, the crosser over [15, 25] s; they touch at 25 s only. Crosser
    4 m away: [35, 45] s, touching at 35 s. 2.5 m away: [20, 30] s, they meet."""
    assert not at_the_pcp_together(3.0, 2.0, 0.1, 0.1, 0.5, 6.0)
    assert not at_the_pcp_together(3.0, 4.0, 0.1, 0.1, 0.5, 6.0)
    assert at_the_pcp_together(3.0, 2.5, 0.1, 0.1, 0.5, 6.0)


@pytest.mark.parametrize(("x0", "letter"), [(6.49, "e"), (6.51, None)])
def test_same_time_the_pcp_within_reach_of_the_path(x0: float, letter: str | None) -> None:
    """The path is 6 m long: the robot comes within c = 0.5 m of a PCP up to 6.5 m
    along. A crosser from (x0, -x0) at 0.1 m/s is at the PCP over [10 x0 - 5, 10 x0 + 5]
    s, exactly when the robot would be: x0 = 6.49 is (e) (6.49 - 0.5 = 5.99 < 6);
    x0 = 6.51 is beyond the path's reach and its clearance: nothing to do with it."""
    a = paper(ob((x0, -x0), (0.0, 0.1)))
    assert (a.letter if a is not None else None) == letter


def test_same_time_both_at_the_pcp_now() -> None:
    """From (0.3, -0.2) at 0.2 m/s: the robot is 0.3 m from the PCP (0.3, 0), at it over
    [-2, 8] s; the crosser over [(0.2 - 0.5) / 0.2, (0.2 + 0.5) / 0.2] = [-1.5, 3.5] s:
    both there now, (e). A crosser already 0.6 m past it (from (0.3, 0.6)) is at it over
    [-5.5, -0.5] s, all in the past: nothing to do with the robot."""
    now = paper(ob((0.3, -0.2), (0.0, 0.2)))
    assert now is not None and now.letter == "e"
    assert paper(ob((0.3, 0.6), (0.0, 0.2))) is None


def test_same_time_leaves_f_and_g_to_the_closest_approach() -> None:
    """The head-on (f) and same-way (g) cases above give the same letters under the
    paper's (e) rule: it decides crossers only."""
    f = paper(ob((3.0, 0.0), (-0.3, 0.0)))
    g = paper(ob((1.0, 0.0), (0.05, 0.0)))
    assert f is not None and f.letter == "f" and g is not None and g.letter == "g"


def test_the_paper_profile_answers_the_same_time_crosser() -> None:
    """Through the planner: the (3, -2) crosser at 0.05 m/s is (e) with the paper profile's
    meet_rule and left alone, (d), with zenav's."""
    crosser = [ob((3.0, -2.0), (0.0, 0.05))]
    zenav = Planner(PARAMS).step((0.0, 0.0, 0.0), crosser, stamp=1.0)
    paper_rule = Planner(PARAMS.model_copy(update={"meet_rule": "same_time"})).step(
        (0.0, 0.0, 0.0), crosser, stamp=1.0)
    assert [a.letter for a in zenav.notes] == ["d"] and zenav.scenario == "a"
    assert paper_rule.scenario == "e"
