"""Movers that leave the 180-degree laser's view are still predicted for a while by the
speed and safety stage (``Planner.remember_movers``, ``should_be_seen``)."""

from __future__ import annotations

import math

from tests.planner.scans import scan_of
from zenav.services.planner.decide import Planner, should_be_seen
from zenav.services.planner.params import Params
from zenav.services.planner.prediction import Obstacle


def test_a_disc_is_expected_in_view_only_inside_the_field_range_and_line_of_sight() -> None:
    pose = (0.0, 0.0, 0.0)
    clear = scan_of(pose)
    assert should_be_seen(clear, (2.0, 1.0), 0.2)  # ahead-left, nothing between
    assert not should_be_seen(clear, (-1.0, 0.5), 0.2)  # behind: the laser looks ahead
    assert not should_be_seen(clear, (0.0, 2.0), 0.2)  # beside, half out of the field
    assert not should_be_seen(clear, (7.9, 0.0), 0.2)  # reaching past the 8 m range
    hidden = scan_of(pose, boxes=[(0.9, 0.2, 1.1, 0.8)])  # a box on the line of sight
    assert not should_be_seen(hidden, (2.0, 1.0), 0.2)


def planner(memory: float) -> Planner:
    return Planner(Params.model_validate({
        "goal": (4.0, 0.0), "start": (0.0, 0.0), "cruise_speed": 0.5, "max_speed": 1.0,
        "robot_radius": 0.2, "use_map": False, "mover_memory": memory}))


CROSSER = Obstacle(5, "dynamic", (1.0, 1.3), (0.0, -0.6), 0.2, (2, 2, 2, 2))


def test_a_crosser_lost_from_view_while_the_robot_turns_is_still_avoided() -> None:
    # The robot sees a walker coming down across its way 1 m ahead (it reaches the way
    # in about 2 s). Then the robot faces south: the walker, now behind its left
    # shoulder, leaves the laser's view and its track is lost. Driving east at the
    # cruise speed would meet it; remembered, it is not driven into.
    decisions = []
    for memory in (0.0, 6.0):
        p = planner(memory)
        p.step((0.0, 0.0, 0.0), [CROSSER], 0.0, scan_of((0.0, 0.0, 0.0), discs=[(1.0, 1.3, 0.2)]))
        facing_south = (0.0, 0.0, math.radians(-80.0))
        decisions.append(p.step(facing_south, [], 0.1, scan_of(facing_south)))
        assert [ob.id for ob, _ in p.unseen] == ([5] if memory > 0 else [])
    forgot, remembered = decisions
    assert forgot.action == "keep" and forgot.speed == 0.5
    assert remembered.action != "keep"
    assert remembered.speed < 0.5 or abs(remembered.target[1]) > 0.3


def test_a_remembered_mover_is_dropped_when_the_laser_should_see_it_and_does_not() -> None:
    p = planner(6.0)
    p.step((0.0, 0.0, 0.0), [CROSSER], 0.0, scan_of((0.0, 0.0, 0.0), discs=[(1.0, 1.3, 0.2)]))
    # Facing it, with nothing there: it turned off or stopped somewhere else.
    p.step((0.0, 0.0, math.radians(45.0)), [], 0.1, scan_of((0.0, 0.0, math.radians(45.0))))
    assert p.unseen == []
    assert p.last_seen_movers == {}


def test_a_remembered_mover_is_forgotten_after_mover_memory_seconds() -> None:
    # The crosser walks across 1 m beside the robot: it does not come at the robot.
    p = planner(1.0)
    p.step((0.0, 0.0, 0.0), [CROSSER], 0.0, scan_of((0.0, 0.0, 0.0), discs=[(1.0, 1.3, 0.2)]))
    behind = (0.0, 0.0, math.radians(-120.0))
    p.step(behind, [], 0.5, scan_of(behind))
    assert [round(age, 3) for _, age in p.unseen] == [0.5]
    assert p.unseen[0][0].position == (1.0, 1.3 - 0.6 * 0.5)
    p.step(behind, [], 1.1, scan_of(behind))
    assert p.unseen == []


def test_a_walker_that_follows_the_robot_out_of_view_is_not_forgotten_by_age() -> None:
    # The robot flees a walker head-on down a corridor, its back to it, as fast as the
    # walker comes: the walker stays 1.5 m behind, out of the laser's view, for longer
    # than mover_memory. When the robot stops, it must still know the walker is there.
    # A walker on a line 1 m to the side is forgotten as before.
    for lateral, remembered in ((0.1, [7]), (1.0, [])):
        p = planner(2.0)
        walker = Obstacle(7, "dynamic", (1.5, lateral), (-0.3, 0.0), 0.2, (2, 2, 2, 2))
        p.step((0.0, 0.0, 0.0), [walker], 0.0,
               scan_of((0.0, 0.0, 0.0), discs=[(1.5, lateral, 0.2)]))
        for k in range(1, 41):  # 4 s, fleeing west at 0.3 m/s
            t = 0.1 * k
            pose = (-0.3 * t, 0.0, math.pi)
            p.step(pose, [], t, scan_of(pose))
        assert [ob.id for ob, _ in p.unseen] == remembered
        for ob, age in p.unseen:  # where it is predicted: 0.3 m behind the robot's back
            assert math.isclose(age, 4.0) and math.isclose(ob.position[0], 1.5 - 0.3 * 4.0)


def test_another_walker_near_its_predicted_place_does_not_make_it_seen_again() -> None:
    # Behind the robot: the lost crosser is predicted at (1.0, 0.7) after 1 s. A walker
    # going the other way passes there (a crowd): the crosser is still remembered. A
    # track there walking its way is the crosser seen again.
    behind = (0.0, 0.0, math.radians(-120.0))
    other = Obstacle(8, "dynamic", (1.05, 0.7), (0.6, 0.0), 0.2, (2, 2, 1, 1))
    again = Obstacle(9, "dynamic", (1.05, 0.7), (0.05, -0.55), 0.2, (2, 2, 1, 1))
    for track, remembered in ((other, [5]), (again, [])):
        p = planner(6.0)
        p.step((0.0, 0.0, 0.0), [CROSSER], 0.0,
               scan_of((0.0, 0.0, 0.0), discs=[(1.0, 1.3, 0.2)]))
        p.step(behind, [track], 1.0, scan_of(behind))
        assert [ob.id for ob, _ in p.unseen] == remembered


def test_a_walker_too_slow_to_reach_the_robot_is_forgotten_by_age() -> None:
    # A walker stopped at the end of its walk, out of view, its track's last velocity a
    # few cm/s toward the robot 3.5 m away: it would not reach the robot within the
    # safety horizon, so it is forgotten after mover_memory like any other (crowd case
    # 490 stood 5 s short of its goal for one). At 0.6 m/s it is kept.
    for speed, remembered in ((0.1, []), (0.6, [7])):
        p = planner(2.0)
        walker = Obstacle(7, "dynamic", (3.5, 0.0), (-speed, 0.0), 0.2, (2, 2, 2, 2))
        p.step((0.0, 0.0, 0.0), [walker], 0.0,
               scan_of((0.0, 0.0, 0.0), discs=[(3.5, 0.0, 0.2)]))
        facing_away = (0.0, 0.0, math.pi)
        p.step(facing_away, [], 2.5, scan_of(facing_away))
        assert [ob.id for ob, _ in p.unseen] == remembered
