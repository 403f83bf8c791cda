"""``zenav.bench.escape``: whether a robot hit by a mover had any way out once it could
know of it, on hand-made movers whose answer is worked out by hand."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from zenav.bench.escape import (
    agent_gap,
    can_escape,
    escape_horizon,
    first_in_view,
    no_escape,
    surface_distance,
)
from zenav.bench.nav import goal_lines, summarise
from zenav.sim.scenario import Scenario


def world(mover: dict[str, Any], speed: float = 0.1) -> Scenario:
    """A robot at the origin facing east (top speed twice ``speed``, radius 0.2 m, the
    paper's 180-degree laser at 10 Hz) and one mover, obstacle 1."""
    return Scenario.model_validate({
        "name": "escape", "world": {"size": [20.0, 20.0], "cell": 0.5},
        "robot": {"start": [0.0, 0.0], "goal": [8.0, 0.0], "speed": speed, "radius": 0.2},
        "obstacles": [{"shape": "box", "center": [19.0, 19.0], "size": [0.5, 0.5]},
                      {"shape": "disc", "radius": 0.25, **mover}],
        "duration": 60.0})


def standing(until: float) -> list[list[float]]:
    """The robot standing at the origin facing east, a row every 0.1 s."""
    return [[k / 10, 0.0, 0.0, 0.0, 0.0] for k in range(round(until * 10) + 1)]


def hit(until: float) -> dict[str, Any]:
    return {"scenario": "mixed-1", "planner": "paper", "outcome": "collision",
            "time": until, "path_length": 0.0, "min_clearance": 0.0, "events": [],
            "trajectory": standing(until), "collided_with": 1}


def test_the_mover_s_distance_is_its_shape_s_at_each_time() -> None:
    disc = world({"center": [3.0, 0.0], "velocity": [-1.0, 0.0]}).obstacles[1]
    xs = np.array([[0.0, 0.0]])
    ys = np.array([[0.0, 1.0]])
    # At 1 s the disc is centred at (2, 0); at 2 s at (1, 0).
    got = surface_distance(disc, xs, ys, np.array([1.0, 2.0]))
    assert np.allclose(got, [[2.0 - 0.25, np.hypot(1.0, 1.0) - 0.25]])
    box = world({"center": [3.0, 0.0], "velocity": [-1.0, 0.0]}).obstacles[0]
    point = (18.0, 19.0)
    assert np.isclose(surface_distance(box, np.array([[point[0]]]), np.array([[point[1]]]),
                                       np.array([0.0]))[0, 0],
                      box.signed_distance(point, 0.0))


def test_a_fast_mover_seen_close_leaves_a_slow_robot_no_way_out() -> None:
    # 0.6 m/s straight at a robot whose top speed is 0.2 m/s, its disc 0.55 m off: the
    # contact comes in under a second; a quarter turn alone takes over a second.
    close = world({"center": [1.0, 0.0], "velocity": [-0.6, 0.0]})
    assert not can_escape(close, 1, (0.0, 0.0, 0.0), 0.0, 0.0)
    # Seen 6 m off, the same mover leaves ten seconds to step out of its way.
    far = world({"center": [6.0, 0.0], "velocity": [-0.6, 0.0]})
    assert can_escape(far, 1, (0.0, 0.0, 0.0), 0.0, 0.0)
    # A mover whose line passes 1 m to the side: standing is enough.
    wide = world({"center": [1.0, 1.0], "velocity": [-0.6, 0.0]})
    assert can_escape(wide, 1, (0.0, 0.0, 0.0), 0.0, 0.0)
    # A disc standing 0.5 m ahead of a standing robot: standing keeps clear of it for the
    # whole horizon (30 s); from 0.15 m on, the robot's disc already touches it.
    still = world({"center": [0.5, 0.0], "velocity": [0.0, 0.0]})
    assert escape_horizon(still.obstacles[1], (0.0, 0.0), 0.0) == 30.0
    assert can_escape(still, 1, (0.0, 0.0, 0.0), 0.0, 0.0)
    assert not can_escape(still, 1, (0.15, 0.0, 0.0), 0.0, 0.0)


def test_a_robot_faster_than_the_mover_runs_ahead_of_one_from_behind() -> None:
    # From behind at 0.5 m/s, 1 m back (0.55 m between the discs), on the robot's line:
    # a robot facing its way with a top speed of 0.6 m/s outruns it (at 0.5 m/s^2 the
    # gap shrinks by at most 0.25 m); one of 0.2 m/s is caught within 1.8 s, too soon
    # to turn a right angle and get its disc off the mover's line.
    behind = {"center": [-1.0, 0.0], "velocity": [0.5, 0.0]}
    assert can_escape(world(behind, speed=0.3), 1,
                      (0.0, 0.0, 0.0), 0.0, 0.0)
    assert not can_escape(world(behind, speed=0.1), 1,
                          (0.0, 0.0, 0.0), 0.0, 0.0)


def test_no_escape_judges_from_two_scans_after_the_mover_first_came_into_view() -> None:
    # The mover comes from behind the robot's 180-degree view, on a line 0.3 m to its
    # side, and turns into view only at x = 0 (beside it, 0.9 s in): the contact is then
    # at hand.
    beside = world({"center": [-0.9, 0.3], "velocity": [1.0, 0.0]})
    record = hit(1.0)
    seen = first_in_view(beside, record, 1)
    assert seen is not None and record["trajectory"][seen][0] == 0.9
    assert no_escape(beside, record)  # the run ended before a planner could answer
    # In view from the start 1 m ahead, coming at 0.6 m/s: judged from 0.2 s on, when
    # there is no way out left.
    close = world({"center": [1.0, 0.0], "velocity": [-0.6, 0.0]})
    assert first_in_view(close, hit(1.0), 1) == 0
    assert no_escape(close, hit(1.0))
    # Ahead from the start, 6 m off: in view at once, with time to leave its way.
    ahead = world({"center": [6.0, 0.0], "velocity": [-0.6, 0.0]})
    assert first_in_view(ahead, hit(9.0), 1) == 0
    assert not no_escape(ahead, hit(9.0))
    # Not a collision, a standing obstacle, or a mover never in view: no verdict.
    assert not no_escape(ahead, {**hit(9.0), "outcome": "timeout"})
    assert not no_escape(ahead, {**hit(9.0), "collided_with": 0})
    behind = world({"center": [-6.0, 0.0], "velocity": [-0.6, 0.0]})
    assert first_in_view(behind, hit(9.0), 1) is None
    assert not no_escape(behind, hit(9.0))


def walker(center: list[float], goal: list[float], sees_robot: bool = False) -> Scenario:
    """The robot of ``world`` (top speed 0.2 m/s) and one ORCA walker at 1 m/s, obstacle
    1, alone in the crowd: it walks straight at its goal."""
    return world({"behavior": "orca", "center": center, "radius": 0.3, "goals": [goal],
                  "preferred_speed": 1.0, "sees_robot": sees_robot})


def test_a_walker_blind_to_the_robot_is_judged_on_its_own_path() -> None:
    # Alone, it walks at 1 m/s from (3, 0) toward (-5, 0): centre (3 - t, 0).
    ahead = walker([3.0, 0.0], [-5.0, 0.0])
    gap = agent_gap(ahead, 1)
    got = gap(np.array([[0.0, 0.0]]), np.array([[0.0, 1.0]]), np.array([1.0, 2.5]))
    assert np.allclose(got, [[2.0 - 0.3, np.hypot(0.5, 1.0) - 0.3]], atol=1e-6)
    # Head-on 3 m off: the discs touch 2.5 s in, too soon for a robot of 0.2 m/s to turn
    # a right angle (1.6 s) and take its disc 0.5 m off the walker's line.
    assert not can_escape(ahead, 1, (0.0, 0.0, 0.0), 0.0, 0.0)
    assert no_escape(ahead, {**hit(2.5), "agents": {"1": [[k / 10, 3.0 - k / 10, 0.0]
                                                           for k in range(26)]}})
    # Seen 8 m off, the same walk leaves the time to step aside.
    far = walker([8.0, 0.0], [-5.0, 0.0])
    assert can_escape(far, 1, (0.0, 0.0, 0.0), 0.0, 0.0)
    # A walker that sees the robot walks round it as the robot moves: no verdict.
    seeing = walker([3.0, 0.0], [-5.0, 0.0], sees_robot=True)
    assert not no_escape(seeing, {**hit(2.5), "agents": {"1": [[k / 10, 3.0 - k / 10, 0.0]
                                                              for k in range(26)]}})
    with pytest.raises(ValueError, match="sees the robot"):
        agent_gap(seeing, 1)
    # A blind walker among others that see the robot: they move it as the robot moves
    # them, so it gets no verdict either.
    mixed = Scenario.model_validate({
        **ahead.model_dump(mode="json", exclude_none=True),
        "obstacles": [*ahead.model_dump(mode="json", exclude_none=True)["obstacles"],
                      {"shape": "disc", "behavior": "orca", "center": [0.0, 5.0],
                       "radius": 0.3, "goals": [[0.0, -5.0]], "preferred_speed": 1.0,
                       "sees_robot": True}]})
    assert not mixed.obstacles[1].sees_robot
    assert not no_escape(mixed, {**hit(2.5), "agents": {
        "1": [[k / 10, 3.0 - k / 10, 0.0] for k in range(26)],
        "2": [[k / 10, 0.0, 5.0 - k / 10] for k in range(26)]}})


def test_the_report_counts_no_way_out_among_the_collisions_a_scan_warned_of() -> None:
    beside = world({"center": [-0.9, 0.3], "velocity": [1.0, 0.0]})
    records = [hit(1.0), {**hit(1.0), "scenario": "mixed-2"},
               {**hit(1.0), "scenario": "mixed-3", "outcome": "reached"}]
    (paper,), families = summarise(
        records, ["paper"], unwarned_hit=lambda r: r["scenario"] == "mixed-2",
        no_escape_hit=lambda r: no_escape(beside, r))
    assert paper.hit_unwarned == ["mixed-2"]
    assert paper.hit_no_escape == ["mixed-1"]  # mixed-2 is counted as unwarned alone
    assert ("speed, in open space with the mover's true path known: `zenav.bench.escape`): "
            "1 of 1 (mixed-1).") in goal_lines([paper], families)
