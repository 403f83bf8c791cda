"""Driving toward a point (``follow.py``): the turn, the slowing near the target, and
braking for it at a given rate; how far a disc goes straight before it comes too near a
point, and whether there is room near a goal."""

from __future__ import annotations

import math

import numpy as np
import pytest

from zenav.services.planner.follow import (
    arc_points,
    backing_toward,
    command_toward,
    reach_along,
    room_near,
)


def test_straight_ahead_far_off_drives_at_the_speed_asked_without_turning() -> None:
    assert command_toward(0.0, 0.0, 0.0, (5.0, 0.0), 0.8, 2.0, 1.0) == (0.8, 0.0)


def test_a_target_behind_turns_on_the_spot_at_the_turn_limit() -> None:
    v, omega = command_toward(0.0, 0.0, 0.0, (-3.0, 0.1), 0.8, 2.0, 1.0)
    assert v == 0.0 and omega == pytest.approx(1.0)


def test_a_target_to_the_side_slows_with_the_cosine_of_the_heading_error() -> None:
    v, omega = command_toward(0.0, 0.0, 0.0, (3.0, 3.0), 0.8, 0.5, 1.0)
    assert v == pytest.approx(0.8 * math.cos(math.pi / 4))
    assert omega == pytest.approx(0.5 * math.pi / 4)


@pytest.mark.parametrize("distance", [0.05, 0.3, 0.6, 0.9])
def test_without_a_braking_rate_the_speed_falls_to_the_distance(distance: float) -> None:
    v, _ = command_toward(0.0, 0.0, 0.0, (distance, 0.0), 1.0, 2.0, 1.0)
    assert v == pytest.approx(distance)


@pytest.mark.parametrize(("distance", "brake"), [(0.05, 1.0), (0.3, 1.0), (0.45, 1.0),
                                                 (0.3, 0.5), (2.0, 0.5)])
def test_with_a_braking_rate_the_speed_is_the_one_that_brakes_to_rest_on_the_target(
        distance: float, brake: float) -> None:
    v, _ = command_toward(0.0, 0.0, 0.0, (distance, 0.0), 1.0, 2.0, 1.0, brake)
    assert v == pytest.approx(min(1.0, math.sqrt(2.0 * brake * distance)))
    # Braking from it at that rate covers exactly the distance left.
    assert v * v / (2.0 * brake) <= distance + 1e-12


def test_on_the_target_there_is_nothing_to_do() -> None:
    assert command_toward(1.0, 1.0, 0.3, (1.0, 1.0), 1.0, 2.0, 1.0, 1.0) == (0.0, 0.0)


def test_backing_turns_the_rear_toward_the_target_and_drives_it_backwards() -> None:
    v, omega = backing_toward(0.0, 0.0, 0.0, (-2.0, 0.0), 0.1, 2.0, 1.0)
    assert (v, omega) == (-0.1, 0.0)


def test_arc_points_back_in_a_straight_line_without_a_turn() -> None:
    points = arc_points(1.0, 2.0, 0.0, -0.4, 0.0, 0.5, 0.1)
    assert points.shape == (5, 2)
    assert np.allclose(points[:, 1], 2.0) and np.allclose(points[-1], (0.8, 2.0))


def test_arc_points_follow_the_circle_of_the_turn() -> None:
    # 0.5 m/s turning 1 rad/s: a circle of 0.5 m about (0, 0.5); a quarter of it in pi/2 s.
    points = arc_points(0.0, 0.0, 0.0, 0.5, 1.0, math.pi / 2, math.pi / 20)
    assert np.allclose(np.hypot(points[:, 0], points[:, 1] - 0.5), 0.5)
    assert np.allclose(points[-1], (0.5, 0.5))


def test_the_speed_falls_to_the_distance_covered_in_the_time_given() -> None:
    v, _ = command_toward(0.0, 0.0, 0.0, (0.3, 0.0), 2.0, 2.0, 1.0, within=0.5)
    assert v == pytest.approx(0.6)
    v, _ = command_toward(0.0, 0.0, 0.0, (1.0, 0.0), 1.5, 2.0, 1.0, within=1.0 / 1.5)
    assert v == pytest.approx(1.5)


def wall(y: float, x0: float = -2.0, x1: float = 2.0, step: float = 0.01) -> np.ndarray:
    """Points every ``step`` along the line at ``y`` from ``x0`` to ``x1``."""
    xs = np.arange(x0, x1 + 1e-9, step)
    return np.column_stack((xs, np.full(xs.shape, y)))


def test_a_disc_goes_all_the_way_when_nothing_is_near_it() -> None:
    assert reach_along((0.0, 0.0), (0.0, 2.0), np.empty((0, 2)), 0.3) == pytest.approx(2.0)
    beside = np.array([[0.31, 1.0], [-0.5, 0.5]])  # farther aside than the clearance
    assert reach_along((0.0, 0.0), (0.0, 2.0), beside, 0.3) == pytest.approx(2.0)
    behind = np.array([[0.0, -0.31]])
    assert reach_along((0.0, 0.0), (0.0, 2.0), behind, 0.3) == pytest.approx(2.0)


def test_a_wall_ahead_stops_the_disc_the_clearance_short_of_it() -> None:
    assert reach_along((0.0, 0.0), (0.0, 3.0), wall(1.5), 0.3) == pytest.approx(1.2)
    # The end comes first when the wall lies beyond it.
    assert reach_along((0.0, 0.0), (0.0, 1.0), wall(1.5), 0.3) == pytest.approx(1.0)


def test_a_point_aside_stops_the_disc_where_its_edge_first_meets_it() -> None:
    # 0.18 m aside with 0.3 m clearance: met 0.24 m before the point along the way.
    reach = reach_along((0.0, 0.0), (2.0, 0.0), np.array([[1.0, 0.18]]), 0.3)
    assert reach == pytest.approx(1.0 - math.sqrt(0.3**2 - 0.18**2))


def test_a_disc_already_too_near_a_point_goes_nowhere() -> None:
    assert reach_along((0.0, 0.0), (0.0, 2.0), np.array([[0.1, -0.1]]), 0.3) == 0.0


def test_room_near_a_goal_by_a_wall_is_on_the_far_side_of_it_or_nowhere() -> None:
    points = wall(0.5)
    # 0.3 m clearance within 0.25 m of the goal: the goal must lie at least 0.05 m off.
    assert room_near((0.0, 0.47), points, 0.3, 0.25) is False
    assert room_near((0.0, 0.44), points, 0.3, 0.25) is True
    assert room_near((0.0, 0.6), points, 0.3, 0.25) is True  # and on the far side
    assert room_near((0.0, -1.0), points, 0.3, 0.25) is True  # the goal itself is clear
    assert room_near((0.0, 0.0), np.empty((0, 2)), 0.3, 0.25) is True


def test_the_room_at_the_tolerance_s_very_edge_counts() -> None:
    # Only the ring at the reach itself, straight down from the goal, is clear.
    goal_y = 0.5 - (0.3 - 0.25) - 0.002  # 0.052 m below the wall
    assert room_near((0.0, goal_y), wall(0.5), 0.3, 0.25) is True
    assert room_near((0.0, goal_y + 0.004), wall(0.5), 0.3, 0.25) is False
