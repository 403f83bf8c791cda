"""Driving toward a point (``follow.py``): the turn, the slowing near the target, and
braking for it at a given rate."""

from __future__ import annotations

import math

import pytest

from zenav.services.planner.follow import backing_toward, command_toward


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


def test_the_speed_falls_to_the_distance_covered_in_the_time_given() -> None:
    v, _ = command_toward(0.0, 0.0, 0.0, (0.3, 0.0), 2.0, 2.0, 1.0, within=0.5)
    assert v == pytest.approx(0.6)
    v, _ = command_toward(0.0, 0.0, 0.0, (1.0, 0.0), 1.5, 2.0, 1.0, within=1.0 / 1.5)
    assert v == pytest.approx(1.5)
