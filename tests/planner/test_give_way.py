"""Giving way in a corridor (give_way.py) on hand-made geometry, and inside a planner
cycle: the walls' direction, the spot aside worked by hand, and the hold from start to
release."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
import pytest

from tests.planner.scans import scan_of
from zenav.services.planner import give_way
from zenav.services.planner.decide import Planner
from zenav.services.planner.params import Params
from zenav.services.planner.prediction import Obstacle

Vec = npt.NDArray[np.float64]


def wall_points(angle_deg: float, half_width: float, length: float = 4.0) -> Vec:
    """The cell centres (every 0.1 m) of two walls ``2 half_width`` apart, running at
    ``angle_deg`` through the origin."""
    a = math.radians(angle_deg)
    along = np.array([math.cos(a), math.sin(a)])
    across = np.array([-math.sin(a), math.cos(a)])
    s = np.arange(-length / 2, length / 2, 0.1)
    rows = [s[:, None] * along + side * half_width * across for side in (-1, 1)]
    return np.round(np.vstack(rows), 1)


def test_corridor_axis_finds_the_walls_direction() -> None:
    for angle in (0.0, 30.0, 90.0, 124.0):
        axis = give_way.corridor_axis(wall_points(angle, 0.9), 0.1)
        assert axis is not None
        off = math.degrees(math.acos(min(abs(float(axis @ [math.cos(math.radians(angle)),
                                                           math.sin(math.radians(angle))])),
                                         1.0)))
        assert off <= 2.0 + 1e-9


def test_corridor_axis_refuses_scatter_and_too_few_points() -> None:
    rng = np.random.default_rng(1)
    assert give_way.corridor_axis(rng.uniform(-2.0, 2.0, (200, 2)), 0.1) is None
    assert give_way.corridor_axis(wall_points(0.0, 0.9)[:7], 0.1) is None


def corridor(half_width: float) -> give_way.BlockedAt:
    """A corridor along x, its walls' inflation leaving the centre free within
    ``half_width`` of y = 0."""
    def blocked(points: Vec) -> npt.NDArray[np.bool_]:
        return np.asarray(np.abs(points[:, 1]) > half_width)
    return blocked


def test_hemmed_in_needs_walls_on_both_sides() -> None:
    robot = np.array([0.0, 0.1])
    way = np.array([-1.0, 0.0])
    assert give_way.hemmed_in(robot, way, corridor(0.6), 1.0, 0.05)

    def one_wall(points: Vec) -> npt.NDArray[np.bool_]:
        return np.asarray(points[:, 1] > 0.6)

    assert not give_way.hemmed_in(robot, way, one_wall, 1.0, 0.05)


def test_offsets_are_signed_left_of_the_walk() -> None:
    # A mover at the origin walking -x: its left is -y.
    points = np.array([[0.0, -1.0], [0.0, 1.0], [5.0, 0.3]])
    off = give_way.offsets(points, np.zeros(2), np.array([-1.0, 0.0]))
    assert off == pytest.approx([1.0, -1.0, -0.3])


def always(_a: Vec, _b: Vec) -> bool:
    return True


def test_spot_aside_is_the_nearest_free_point_off_the_line() -> None:
    # The robot at (0, 0.1) in a corridor whose free centre is |y| <= 0.6; a mover at
    # (3, 0) walking -x at 0.2 m/s; clearance 0.45. Above the line (its right: side -1)
    # the spot must have y >= 0.45: on the 0.05 m grid round the robot, (0, 0.45), 0.35 m
    # straight up (reached in 1.75 s at 0.2 m/s, plus 1.5 s to turn, against
    # (3 - 0.45) / 0.2 = 12.75 s for the mover).
    robot = np.array([0.0, 0.1])
    spot = give_way.spot_aside(robot, np.array([3.0, 0.0]), np.array([-1.0, 0.0]), 0.2,
                               0.45, -1, corridor(0.6), always, 1.0, 0.05, 0.2, 1.5)
    assert spot is not None
    assert spot == pytest.approx([0.0, 0.45])
    # Below the line (side +1) the free half is too narrow: y <= -0.45 holds, |y| <= 0.6
    # too, but it lies 0.55 m away: still found, farther.
    below = give_way.spot_aside(robot, np.array([3.0, 0.0]), np.array([-1.0, 0.0]), 0.2,
                                0.45, 1, corridor(0.6), always, 1.0, 0.05, 0.2, 1.5)
    assert below is not None and below[1] <= -0.45 + 1e-9
    assert float(np.hypot(*(below - robot))) > 0.35


def test_spot_aside_none_when_too_late_too_narrow_or_blocked() -> None:
    robot = np.array([0.0, 0.1])
    way = np.array([-1.0, 0.0])
    # The mover 0.6 m off: a spot at x (m from the robot, d m away) is reached in
    # d / 0.2 + 1.5 s, the mover is abreast of it less the clearance in
    # (0.6 - x - 0.45) / 0.2 s: -x - d >= 0.15 is needed, and d >= |x|.
    assert give_way.spot_aside(robot, np.array([0.6, 0.0]), way, 0.2, 0.45, -1,
                               corridor(0.6), always, 1.0, 0.05, 0.2, 1.5) is None
    # The free centre narrower than the clearance.
    assert give_way.spot_aside(robot, np.array([3.0, 0.0]), way, 0.2, 0.45, -1,
                               corridor(0.4), always, 1.0, 0.05, 0.2, 1.5) is None
    # No straight way to any spot.
    assert give_way.spot_aside(robot, np.array([3.0, 0.0]), way, 0.2, 0.45, -1,
                               corridor(0.6), lambda a, b: False, 1.0, 0.05, 0.2,
                               1.5) is None
    # The mover already abreast of the robot.
    assert give_way.spot_aside(robot, np.array([0.2, 0.0]), way, 0.2, 0.45, -1,
                               corridor(0.6), always, 1.0, 0.05, 0.2, 1.5) is None


def test_spot_aside_ahead_keeps_within_45_degrees_of_the_way() -> None:
    # A mover overtaking: at (-3, 0) walking +x at 1.2 m/s, the robot at (0, 0.1) in the
    # same corridor, clearance 0.45. The nearest spot above the line is straight up;
    # ahead, the robot swerves: the spot lies at least as far along the way as across.
    robot = np.array([0.0, 0.1])
    mover, way = np.array([-3.0, 0.0]), np.array([1.0, 0.0])
    square = give_way.spot_aside(robot, mover, way, 1.2, 0.45, 1, corridor(0.6), always,
                                 1.0, 0.05, 1.0, 0.0)
    assert square == pytest.approx([0.0, 0.45])
    ahead = give_way.spot_aside(robot, mover, way, 1.2, 0.45, 1, corridor(0.6), always,
                                1.0, 0.05, 1.0, 0.8, ahead=True)
    assert ahead is not None and ahead[1] >= 0.45 - 1e-9
    assert ahead[0] - robot[0] >= abs(ahead[1] - robot[1]) - 1e-9
    assert ahead == pytest.approx([0.35, 0.45])  # the nearest such point on the grid
    # Too close behind for any spot ahead: none.
    assert give_way.spot_aside(robot, np.array([-1.0, 0.0]), way, 1.2, 0.45, 1,
                               corridor(0.6), always, 1.0, 0.05, 1.0, 0.8, ahead=True) is None


def test_the_lane_runs_against_a_head_on_mover_and_with_an_overtaking_one() -> None:
    def hold(overtaking: bool) -> give_way.Hold:
        return give_way.Hold(spot=(0.0, 0.5), side=1, radius=0.2, mover=3, way=(1.0, 0.0),
                             until=60.0, position=(-3.0, 0.0), velocity=(1.2, 0.0), at=0.0,
                             seen=0.0, moving=0.0, overtaking=overtaking)

    assert hold(False).lane == (-1.0, -0.0)
    assert hold(True).lane == (1.0, 0.0)


def test_passed_once_behind_by_the_clearance() -> None:
    robot = np.array([0.0, 0.5])
    way = np.array([-1.0, 0.0])
    assert not give_way.passed(robot, np.array([0.3, 0.0]), way, 0.45)
    assert not give_way.passed(robot, np.array([-0.4, 0.0]), way, 0.45)
    assert give_way.passed(robot, np.array([-0.5, 0.0]), way, 0.45)


def test_hold_predicts_along_the_corridor_and_keeps_the_lateral() -> None:
    hold = give_way.Hold(spot=(0.0, 0.5), side=-1, radius=0.2, mover=3, way=(-1.0, 0.0),
                         until=60.0, position=(3.0, 0.1), velocity=(-0.2, 0.05), at=0.0,
                         seen=0.0, moving=0.0)
    # Along its way at its speed (0.206 m/s), not along its tracked heading.
    assert hold.predicted(2.0) == pytest.approx([3.0 - 2.0 * math.hypot(0.2, 0.05), 0.1])
    assert hold.along((2.0, 0.4)) == pytest.approx((2.0, 0.1))


# -- inside a planner cycle ----------------------------------------------------------

WALLS = [(0.0, 1.9, 14.0, 2.1), (0.0, 3.9, 14.0, 4.1)]  # a 1.8 m corridor along y = 3


def corridor_planner(**changes: object) -> Planner:
    return Planner(Params.model_validate({
        "goal": (13.0, 3.0), "start": (1.0, 3.0), "cruise_speed": 0.2, "max_speed": 0.4,
        "cell": 0.25, "window_radius": 2.0, **changes}))


def walker(x: float, y: float = 3.0) -> Obstacle:
    return Obstacle(7, "dynamic", (x, y), (-0.15, 0.0), 0.2, (0, 0, 0, 0))


def map_walls(p: Planner, pose: tuple[float, float, float], until: float,
              boxes: list[tuple[float, float, float, float]] = WALLS,
              fov_deg: float = 180.0) -> float:
    """Scans of the empty corridor (``boxes``) every 0.1 s up to ``until`` (the walls
    confirmed)."""
    t = 0.0
    while t < until:
        p.step(pose, [], t, scan_of(pose, boxes=boxes, fov_deg=fov_deg))
        t = round(t + 0.1, 1)
    return t


def test_a_head_on_walker_in_a_corridor_is_given_way_and_let_by() -> None:
    pose = (5.0, 3.1, 0.0)
    p = corridor_planner()
    t = map_walls(p, pose, 2.0)
    # The walker 1.8 m ahead on the corridor's line, coming at 0.15 m/s.
    d = p.step(pose, [walker(6.8)], t, scan_of(pose, boxes=WALLS, discs=[(6.8, 3.0, 0.2)]))
    assert (d.action, d.scenario, d.obstacle) == ("give_way", "f", 7)
    assert p.hold is not None and p.hold.side == -1  # above the line: the robot's side
    spot = p.hold.spot
    assert spot[1] - 3.0 >= 0.2 + 0.2 + 0.05 - 1e-9  # off the walker's line by the clearance
    assert spot[1] <= 3.9 - 0.2 - 0.1 + 0.1  # inside the walls' inflation (to a cell)
    # At the spot it stands and turns to face the walker.
    at_spot = (spot[0], spot[1], math.pi / 2)
    d = p.step(at_spot, [walker(6.0)], t + 0.1, scan_of(at_spot, boxes=WALLS,
                                                         discs=[(6.0, 3.0, 0.2)]))
    assert d.action == "give_way" and d.v == 0.0 and d.omega < 0.0
    # Once the walker is behind the robot by the clearance, the hold ends.
    d = p.step(at_spot, [walker(spot[0] - 0.5)], t + 0.2,
               scan_of(at_spot, boxes=WALLS, discs=[(spot[0] - 0.5, 3.0, 0.2)]))
    assert p.hold is None and d.action != "give_way"


def test_a_hold_whose_spot_the_walker_would_still_walk_into_ends() -> None:
    """Standing at its spot aside, the robot learns that the walker comes along a line
    that touches it, too late for another spot: the hold ends and the local layer
    answers the walker, instead of standing in its way."""
    pose = (5.0, 3.1, 0.0)
    p = corridor_planner()
    t = map_walls(p, pose, 2.0)
    p.step(pose, [walker(6.8)], t, scan_of(pose, boxes=WALLS, discs=[(6.8, 3.0, 0.2)]))
    assert p.hold is not None
    spot = p.hold.spot
    at_spot = (spot[0], spot[1], 0.0)
    close = Obstacle(7, "dynamic", (spot[0] + 0.7, spot[1] - 0.1), (-0.4, 0.0), 0.2,
                     (0, 0, 0, 0))
    d = p.step(at_spot, [close], t + 0.1,
               scan_of(at_spot, boxes=WALLS, discs=[(spot[0] + 0.7, spot[1] - 0.1, 0.2)]))
    assert p.hold is None and d.action != "give_way"


def test_in_the_open_a_head_on_walker_is_not_given_way() -> None:
    pose = (5.0, 3.1, 0.0)
    p = corridor_planner()
    d = p.step(pose, [walker(6.8)], 0.0, scan_of(pose, discs=[(6.8, 3.0, 0.2)]))
    assert p.hold is None and d.scenario == "f" and d.action != "give_way"


def test_giving_way_can_be_turned_off() -> None:
    pose = (5.0, 3.1, 0.0)
    p = corridor_planner(give_way=False)
    t = map_walls(p, pose, 2.0)
    p.step(pose, [walker(6.8)], t, scan_of(pose, boxes=WALLS, discs=[(6.8, 3.0, 0.2)]))
    assert p.hold is None


# -- a mover overtaking in a corridor ----------------------------------------------------


WIDE = [(0.0, 1.4, 14.0, 1.6), (0.0, 4.4, 14.0, 4.6)]  # a 2.8 m corridor along y = 3


def overtaker(x: float, y: float = 3.0, speed: float = 0.6) -> Obstacle:
    return Obstacle(8, "dynamic", (x, y), (speed, 0.0), 0.2, (0, 0, 0, 0))


def map_wide(p: Planner, pose: tuple[float, float, float], until: float) -> float:
    """``map_walls`` for the wide corridor, all round."""
    return map_walls(p, pose, until, WIDE, 360.0)


def test_a_walker_overtaking_in_a_corridor_is_given_way_ahead_and_let_by() -> None:
    # The robot at (5, 3.0) goes +x at up to 0.4 m/s; a walker 1.7 m behind on its line
    # (in the 2 m window) comes at 0.6 m/s: no outrunning it, and collision prediction
    # keeps only movers ahead. Between the walls the robot swerves into a lane off the
    # walker's line.
    # (A 360-degree laser: the 180-degree one would not see the walker.)
    pose = (5.0, 3.0, 0.0)
    p = corridor_planner()
    t = map_wide(p, pose, 2.0)
    d = p.step(pose, [overtaker(3.3)], t,
               scan_of(pose, boxes=WIDE, discs=[(3.3, 3.0, 0.2)], fov_deg=360.0))
    assert (d.action, d.scenario, d.obstacle) == ("give_way", "g", 8)
    assert p.hold is not None and p.hold.overtaking
    spot = p.hold.spot
    clearance = 0.2 + 0.2 + 0.05  # both radii (the robot's for a smaller track) + margin/2
    assert abs(spot[1] - 3.0) >= clearance - 1e-9  # off the walker's line
    assert spot[0] - 5.0 >= abs(spot[1] - 3.0) - 1e-9  # ahead, within 45 degrees
    # It swerves on toward that side at its top speed (no square turn on the spot).
    assert d.v > 0.0 and d.omega * (spot[1] - 3.0) > 0.0 and d.speed == 0.4
    # In the lane it goes on at cruise speed while the walker comes by.
    in_lane = (spot[0], spot[1], 0.0)
    d = p.step(in_lane, [overtaker(spot[0] - 1.0)], t + 0.1,
               scan_of(in_lane, boxes=WIDE, discs=[(spot[0] - 1.0, 3.0, 0.2)], fov_deg=360.0))
    assert (d.action, d.speed) == ("give_way", 0.2) and d.v > 0.0
    # Once the walker is ahead of the robot by the clearance, the hold ends.
    d = p.step(in_lane, [overtaker(spot[0] + 0.5)], t + 0.2,
               scan_of(in_lane, boxes=WIDE, discs=[(spot[0] + 0.5, 3.0, 0.2)], fov_deg=360.0))
    assert p.hold is None and d.action != "give_way"


@pytest.mark.parametrize(("walls", "x", "y", "speed"), [
    (False, 3.3, 3.0, 0.6),  # in the open: the speed and safety stage answers it
    (True, 3.3, 3.0, 0.3),  # slower than the robot's top speed: it can keep ahead
    (True, 3.3, 3.5, 0.6),  # its line passes the robot clear
    (True, 6.0, 3.0, 0.6),  # ahead of the robot already
])
def test_no_hold_for_a_walker_that_is_not_overtaking_in_a_corridor(
        walls: bool, x: float, y: float, speed: float) -> None:
    pose = (5.0, 3.0, 0.0)
    p = corridor_planner()
    boxes = WIDE if walls else []
    t = map_wide(p, pose, 2.0) if walls else 0.0
    d = p.step(pose, [overtaker(x, y, speed)], t,
               scan_of(pose, boxes=boxes, discs=[(x, y, 0.2)], fov_deg=360.0))
    assert p.hold is None and d.action != "give_way"


def test_spot_aside_across_the_line_and_behind_is_timed_at_the_reverse_limit() -> None:
    # The robot at (0, 0.3), on the far side of the line of a mover at (2, 0) walking -x
    # at 0.2 m/s; clearance 0.45: a spot for side +1 has y <= -0.45, across the line.
    # Nearest on the 0.05 m grid, (0, -0.5) (the point at -0.45 falls short of the
    # clearance by a rounding), 0.8 m away: at 0.2 m/s, 0.8 / 0.2 + 1.5 = 5.5 s against
    # (2 - 0.45) / 0.2 = 7.75 s for the mover: in time. Facing away from the line
    # (heading +90 degrees) it lies behind, and the robot backs there at 0.1 m/s:
    # 0.8 / 0.1 + 1.5 = 9.5 s, too late, and every spot farther back is later still.
    robot, mover, way = np.array([0.0, 0.3]), np.array([2.0, 0.0]), np.array([-1.0, 0.0])

    def spot(backing: tuple[float, float] | None) -> Vec | None:
        return give_way.spot_aside(robot, mover, way, 0.2, 0.45, 1, corridor(0.6), always,
                                   1.0, 0.05, 0.2, 1.5, backing=backing)

    assert spot(None) == pytest.approx([0.0, -0.5])
    assert spot((math.pi / 2, 0.1)) is None
    # Facing the line, the robot drives there forward: the same spot.
    assert spot((-math.pi / 2, 0.1)) == pytest.approx([0.0, -0.5])
    # On its own side (side -1: y >= 0.45) it needs no crossing: timed as before even
    # where it backs, as the hold then also drives it.
    own = give_way.spot_aside(robot, mover, way, 0.2, 0.45, -1, corridor(0.6), always,
                              1.0, 0.05, 0.2, 1.5, backing=(-math.pi / 2, 0.1))
    assert own == pytest.approx([0.0, 0.45], abs=1e-9)


def test_backing_is_checked_against_the_map_behind_the_robot() -> None:
    """Backing to a spot aside there is no laser and no stop zone behind the robot: a
    wall the map holds 0.35 m behind its centre stops the backing that would come within
    a cell more than the radius of it; backing away from it, or with room, goes on."""
    end_wall = [*WALLS, (3.9, 2.1, 4.1, 3.9)]  # the corridor closed at x = 4
    p = corridor_planner()
    map_walls(p, (5.0, 3.0, math.pi), 2.0, boxes=end_wall, fov_deg=360.0)
    assert p._backs_into_map((4.45, 3.0, 0.0), -0.4, 0.0)  # rear toward the wall
    assert not p._backs_into_map((4.45, 3.0, math.pi), -0.4, 0.0)  # rear away from it
    assert not p._backs_into_map((5.5, 3.0, 0.0), -0.4, 0.0)  # 1.4 m of room behind
