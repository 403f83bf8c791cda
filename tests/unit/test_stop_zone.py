"""The stop zone's test (``stop_zone.zone_blocked``, its loop compiled as
``_loops.zone_hit``): the rectangle ahead of the robot, edge by edge, and against the
rectangle's definition on random scans."""

from __future__ import annotations

import math

import numpy as np
import pytest

from zenav.services.motor_bridge.stop_zone import StopZoneParams, stop_distance, zone_blocked

RADIUS, SIDE, AHEAD = 0.2, 0.02, 0.5
RANGE_MAX = 8.0


def one_return(x: float, y: float, beams: int = 361) -> tuple[np.ndarray, float, float]:
    """A 360° scan of ``beams`` beams with no return but one at (x, y), robot frame: the
    beam through the point (the scan starts at its angle) at its distance."""
    bearing = math.atan2(y, x)
    ranges = np.full(beams, RANGE_MAX, dtype=np.float32)
    ranges[0] = math.hypot(x, y)
    return ranges, bearing, 2 * math.pi / beams


def blocked(x: float, y: float, v: float = 0.5) -> bool:
    ranges, angle_min, step = one_return(x, y)
    return zone_blocked(ranges, angle_min, step, RANGE_MAX, v, RADIUS, SIDE, AHEAD)


def test_a_return_inside_the_rectangle_blocks_and_one_beyond_each_edge_does_not() -> None:
    front, half = RADIUS + AHEAD, RADIUS + SIDE
    assert blocked(0.4, 0.0)
    assert blocked(front - 1e-3, half - 1e-3)
    assert blocked(front - 1e-3, -(half - 1e-3))
    assert not blocked(front + 1e-3, 0.0)  # beyond the front
    assert not blocked(0.3, half + 1e-3)  # beside it, left and right
    assert not blocked(0.3, -(half + 1e-3))
    assert not blocked(-0.1, 0.0)  # behind the robot
    assert not blocked(0.4, 0.0, v=0.0)  # not moving forward: never blocked


def test_no_return_a_nan_or_one_at_range_max_never_blocks() -> None:
    for value in (RANGE_MAX, math.nan, math.inf):
        ranges, angle_min, step = one_return(0.4, 0.0)
        ranges[0] = value
        assert not zone_blocked(ranges, angle_min, step, RANGE_MAX, 0.5, RADIUS, SIDE, AHEAD)


@pytest.mark.parametrize("seed", range(5))
def test_the_zone_holds_a_return_exactly_when_one_lies_in_the_rectangle(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for _ in range(200):
        beams = int(rng.integers(20, 400))
        angle_min = rng.uniform(-math.pi, 0.0)
        step = rng.uniform(0.2, 1.0) * 2 * math.pi / beams
        ranges = rng.uniform(0.05, 1.5, beams).astype(np.float32)
        ranges[rng.random(beams) < 0.1] = RANGE_MAX
        ranges[rng.random(beams) < 0.05] = np.nan
        ahead = rng.uniform(0.0, 0.6)
        r = ranges.astype(np.float64)
        angles = angle_min + step * np.arange(beams)
        x, y = r * np.cos(angles), r * np.sin(angles)
        with np.errstate(invalid="ignore"):
            want = bool(((r < RANGE_MAX) & (x > 0.0) & (x <= RADIUS + ahead)
                         & (np.abs(y) <= RADIUS + SIDE)).any())
        assert zone_blocked(ranges, angle_min, step, RANGE_MAX, 0.4, RADIUS, SIDE,
                            ahead) == want


def test_the_params_zone_reaches_as_far_as_the_robot_needs_to_stop() -> None:
    p = StopZoneParams()
    v = 0.8
    reach = RADIUS + stop_distance(v, p.zone_reaction, p.decel, p.zone_margin)
    ranges, angle_min, step = one_return(reach - 1e-3, 0.0)
    assert p.blocks(ranges, angle_min, step, RANGE_MAX, v, RADIUS)
    ranges, angle_min, step = one_return(reach + 1e-3, 0.0)
    assert not p.blocks(ranges, angle_min, step, RANGE_MAX, v, RADIUS)
