"""A goal no way reaches ends in ``unreachable`` (issue 12, "never stuck"): the wall memory
(``Costmap.cut_off``) and the planner's recovery stage, on hand-made walls.

The fault these pin: going round a closed ring of walls at 0.1 m/s takes longer than the
map's decay, so the side seen first is unknown (free) again by the time the last side is
seen; the global path always found a way through it and ``unreachable`` never came."""

from __future__ import annotations

import math

import numpy as np
from scipy.ndimage import distance_transform_edt

from tests.planner.scans import Box, scan_of
from zenav.services.planner.costmap import Costmap
from zenav.services.planner.decide import Decision, Planner
from zenav.services.planner.params import Params

GOAL = (8.0, 3.0)


def ring(cx: float, cy: float, half: float, thickness: float = 0.2,
         gap: float = 0.0) -> list[Box]:
    """A closed square ring of walls round (cx, cy), ``half`` from the centre to the
    walls' inner faces; with ``gap``, an opening that wide in the middle of its west side."""
    t, h = thickness, half
    west = [(cx - h - t, cy - h - t, cx - h, cy + h + t)]
    if gap > 0:
        west = [(cx - h - t, cy - h - t, cx - h, cy - gap / 2),
                (cx - h - t, cy + gap / 2, cx - h, cy + h + t)]
    return [*west, (cx + h, cy - h - t, cx + h + t, cy + h + t),
            (cx - h - t, cy - h - t, cx + h + t, cy - h),
            (cx - h - t, cy + h, cx + h + t, cy + h + t)]


# Round the ring, one side at a time, each looked at for 2 s, 40 s apart: the whole
# round takes longer than the map's 60 s decay.
ROUND = [((5.5, 3.0, 0.0), 0.0), ((8.0, 5.5, -math.pi / 2), 40.0),
         ((10.5, 3.0, math.pi), 80.0), ((8.0, 0.5, math.pi / 2), 120.0)]


def look_round(map_or_planner: Costmap | Planner, walls: list[Box]) -> float:
    """Scan every side of ``walls`` in turn (``ROUND``); the stamp after the last look."""
    t = 0.0
    for pose, start in ROUND:
        for k in range(20):
            t = round(start + 0.1 * k, 6)
            scan = scan_of(pose, boxes=walls)
            if isinstance(map_or_planner, Costmap):
                map_or_planner.update(scan, t)
            else:
                map_or_planner.step(pose, [], t, scan)
    return t


def costmap() -> Costmap:
    p = Params()
    return Costmap((2.0, 3.0), GOAL, resolution=p.map_resolution, decay=p.map_decay,
                   inflation=p.robot_radius + p.safety_margin, confirm=p.map_confirm,
                   padding=p.map_padding, max_size=p.map_max_size)


# -- the wall memory ----------------------------------------------------------------------


def test_a_ring_seen_side_by_side_cuts_the_goal_off_though_its_first_side_has_decayed() -> None:
    m = costmap()
    look_round(m, ring(*GOAL, 1.0))
    start, goal = np.array([8.0, 0.5]), np.array(GOAL)
    # The premise: the decaying map has forgotten the west side (a way "opens" there).
    assert not m.lethal_at(np.array([[6.9, 3.0]]))[0]
    assert m.cut_off(start, goal, 0.2)


def test_a_ring_with_a_gap_wider_than_the_robot_does_not_cut_the_goal_off() -> None:
    m = costmap()
    look_round(m, ring(*GOAL, 1.0, gap=0.8))
    assert not m.cut_off(np.array([8.0, 0.5]), np.array(GOAL), 0.2)


def test_a_ring_not_yet_seen_all_round_does_not_cut_the_goal_off() -> None:
    m = costmap()
    pose = ROUND[0][0]
    for k in range(20):
        m.update(scan_of(pose, boxes=ring(*GOAL, 1.0)), 0.1 * k)
    assert not m.cut_off(np.array(pose[:2]), np.array(GOAL), 0.2)


def test_a_remembered_wall_a_beam_passes_through_is_forgotten() -> None:
    # An obstacle that closed the ring's gap, confirmed, then gone (a mover that stood
    # and left): the beams through the gap clear it from the memory.
    m = costmap()
    plug = (6.85, 2.55, 7.05, 3.45)
    look_round(m, [*ring(*GOAL, 1.0, gap=0.8), plug])
    assert m.cut_off(np.array([5.5, 3.0]), np.array(GOAL), 0.2)
    for k in range(5):
        m.update(scan_of((5.5, 3.0, 0.0), boxes=ring(*GOAL, 1.0, gap=0.8)), 130.0 + 0.1 * k)
    assert not m.cut_off(np.array([5.5, 3.0]), np.array(GOAL), 0.2)


def test_a_goal_inside_a_box_seen_all_round_is_cut_off() -> None:
    m = costmap()
    look_round(m, ring(*GOAL, 0.4, thickness=0.4))  # a solid-looking 1.6 m block: the
    # goal 0.4 m inside its faces, in cells no beam reaches
    assert m.cut_off(np.array([8.0, 0.5]), np.array(GOAL), 0.2)


def test_a_mover_passing_over_the_goal_never_cuts_it_off() -> None:
    # A slow disc comes down the line through the goal toward the robot (the paper's
    # robustness run, Ob4): its front marks the goal's cell for a while.
    m = costmap()
    pose = (5.0, 3.0, 0.0)
    for k in range(300):
        t = 0.1 * k
        disc = (10.0 - 0.1 * t, 3.0, 0.2)
        m.update(scan_of(pose, discs=[disc]), t)
        assert not m.cut_off(np.array(pose[:2]), np.array(GOAL), 0.2), t


def test_a_goal_covered_by_a_mover_s_marks_is_not_cut_off() -> None:
    """The wall memory of bench nav's head-on-31017 (180° laser) at 15 s: a slow disc
    appeared 1 m past the goal and walked over it toward the robot, leaving a band of
    marks 0.3 m by 0.9 m over the goal, which the disc itself, on the line, keeps the
    beams off. No cell near the goal is free, but nothing closes the goal off: it is
    covered. (This used to cut the goal off; the planner gave it up at 50 s and stood
    until the mover walked into it.)"""
    goal, robot = np.array([1.693, 6.073]), np.array([7.07, 5.78])
    p = Params()
    m = Costmap(tuple(robot), tuple(goal), resolution=p.map_resolution, decay=p.map_decay,
                inflation=p.robot_radius + p.safety_margin, confirm=p.map_confirm,
                padding=p.map_padding, max_size=p.map_max_size)
    band = np.array([(x, y) for x in np.arange(1.15, 1.96, 0.1) for y in (5.95, 6.05, 6.15)])
    cells = m.cell_of(band)
    m.walls[cells[:, 0], cells[:, 1]] = True
    reach = math.ceil(0.2 / m.resolution) + 1
    gi, gj = m.cell_of(goal[None, :])[0].tolist()
    free = distance_transform_edt(~m.walls) * m.resolution > 0.2
    assert not free[gi - reach:gi + reach + 1, gj - reach:gj + reach + 1].any()  # covered
    assert not m.cut_off(robot, goal, 0.2)
    # A goal 1 m off the band, its own cells free, is not closed off either (a closed
    # ring does close a goal off: the tests above).
    assert not m.cut_off(robot, goal + np.array([0.0, 1.0]), 0.2)


# -- the planner: recovery ends in unreachable ----------------------------------------------


def drive(p: Planner, pose: tuple[float, float, float], t: float, walls: list[Box],
          limit: float) -> tuple[float, list[Decision], tuple[float, float, float]]:
    """Follow the planner's commands (a unicycle, 0.1 s steps) scanning ``walls``, until
    it declares the goal unreachable or ``limit`` s have passed."""
    decisions: list[Decision] = []
    end = t + limit
    while t < end:
        t = round(t + 0.1, 6)
        d = p.step(pose, [], t, scan_of(pose, boxes=walls))
        decisions.append(d)
        if d.action == "unreachable":
            break
        x, y, th = pose
        pose = (x + d.v * 0.1 * math.cos(th), y + d.v * 0.1 * math.sin(th),
                math.remainder(th + d.omega * 0.1, 2 * math.pi))
    return t, decisions, pose


def bound(p: Params) -> float:
    """The documented bound (README, recovery.py): once the wall memory cuts the goal
    off, ``replan_period`` plus ``recovery_rounds`` rounds of the four steps, each at most
    one cycle (replan), the spin's limit, the back-up's limit and ``wait_time``."""
    spin = p.spin_angle() / (0.5 * p.max_omega) + 5.0
    back_up = 2.0 * p.backup_distance / p.backup_speed + 2.0
    return p.replan_period + p.recovery_rounds * (0.1 + spin + 0.1 + back_up + 0.1
                                                  + p.wait_time + 0.1)


def test_a_goal_in_a_closed_ring_is_declared_unreachable_within_the_bound() -> None:
    walls = ring(*GOAL, 1.0)
    p = Planner(Params.model_validate({"goal": GOAL, "start": (2.0, 3.0)}))
    t = look_round(p, walls)
    assert p.plan is not None and p.plan.found  # the decaying map still shows a way
    t, decisions, pose = drive(p, ROUND[-1][0], t, walls, limit=bound(p.p) + 30.0)
    last = decisions[-1]
    assert last.action == "unreachable", [d.action for d in decisions[-5:]]
    assert t - ROUND[-1][1] <= bound(p.p) + 2.0
    assert last.v == 0.0 and last.omega == 0.0
    assert {"replan", "spin", "wait"} <= {d.action for d in decisions}
    after = p.step(pose, [], t + 5.0, scan_of(pose, boxes=walls))
    assert after.action == "unreachable" and after.v == 0.0 and after.omega == 0.0


def test_a_robot_shut_in_a_closed_room_declares_the_goal_outside_unreachable() -> None:
    room = ring(3.0, 3.0, 1.5)  # the robot at its centre, the goal 5 m away outside
    p = Planner(Params.model_validate({"goal": GOAL, "start": (3.0, 3.0)}))
    _, decisions, _ = drive(p, (3.0, 3.0, 0.0), 0.0, room, limit=200.0)
    assert decisions[-1].action == "unreachable", [d.action for d in decisions[-5:]]
    assert decisions[-1].v == 0.0 and decisions[-1].omega == 0.0


def test_a_ring_with_a_gap_is_not_given_up_on() -> None:
    walls = ring(*GOAL, 1.0, gap=0.9)
    p = Planner(Params.model_validate({"goal": GOAL, "start": (2.0, 3.0)}))
    t = look_round(p, walls)
    t, decisions, _ = drive(p, ROUND[0][0], t, walls, limit=120.0)
    assert "unreachable" not in {d.action for d in decisions}
