"""CrowdNav's test protocol as scenario files: placement, the redraw rule, the frame."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from zenav.sim.crowdnav import circle_crossing, crowdnav_scenario, square_crossing

CENTRE = (6.0, 6.0)
GAP = 0.3 + 0.3 + 0.2  # two radii and the discomfort distance
ROBOT = ((0.0, -4.0), (0.0, 4.0))


def test_the_robot_and_the_settings_are_crowdnavs_in_our_frame():
    sc = crowdnav_scenario("circle", 3, visible=True, fov_deg=360.0)
    r = sc.robot
    assert sc.world.size == (12.0, 12.0)
    assert r.start == (6.0, 2.0) and r.goal == (6.0, 10.0) and r.heading_deg == 90.0
    assert (r.radius, r.speed, r.effective_max_speed, r.goal_tolerance) == (0.3, 1.0, 1.0, 0.3)
    assert sc.duration == 25.0 and sc.name == "circle-crossing-visible-360-3"
    assert (sc.laser.fov_deg, sc.laser.max_range, sc.laser.rate_hz) == (360.0, 8.0, 10.0)
    assert len(sc.obstacles) == 5
    for ob in sc.obstacles:
        assert ob.is_agent and ob.sees_robot and ob.radius == 0.3 and ob.preferred_speed == 1.0
    assert not crowdnav_scenario("circle", 3).obstacles[0].sees_robot


@pytest.mark.parametrize("case", range(0, 500, 7))
def test_circle_humans_start_near_the_circle_and_head_for_the_opposite_point(case):
    sc = crowdnav_scenario("circle", case)
    for ob in sc.obstacles:
        assert ob.goals is not None
        (sx, sy), (gx, gy) = ob.center, ob.goals[0]
        assert math.isclose(sx + gx, 12.0, abs_tol=1e-5) and math.isclose(sy + gy, 12.0,
                                                                          abs_tol=1e-5)
        assert 4.0 - math.hypot(0.5, 0.5) <= math.dist((sx, sy), CENTRE) <= 4.0 + math.hypot(
            0.5, 0.5)


def test_circle_noise_is_uniform_half_a_metre_in_x_and_y():
    offsets = []
    for case in range(200):
        for px, py, _, _, _ in circle_crossing(np.random.RandomState(1000 + case)):
            offsets.append(math.hypot(px, py) - 4.0)
    assert max(offsets) > 0.4 and min(offsets) < -0.4
    assert max(abs(o) for o in offsets) <= math.hypot(0.5, 0.5)


@pytest.mark.parametrize("layout", ["circle", "square"])
def test_no_start_or_goal_is_within_the_discomfort_gap_of_an_earlier_one(layout):
    draw = circle_crossing if layout == "circle" else square_crossing
    for case in range(500):
        humans = draw(np.random.RandomState(1000 + case))
        placed = [(*ROBOT[0], *ROBOT[1])]
        for px, py, gx, gy, _ in humans:
            for ax, ay, bx, by in placed:
                assert math.dist((px, py), (ax, ay)) >= GAP
                assert math.dist((gx, gy), (bx, by)) >= GAP
                if layout == "circle":
                    assert math.dist((px, py), (bx, by)) >= GAP
            placed.append((px, py, gx, gy))


class CountingState(np.random.RandomState):
    """A RandomState that counts its ``random_sample`` draws."""

    draws = 0

    def random_sample(self, *args: Any, **kwargs: Any) -> Any:
        self.draws += 1
        return super().random_sample(*args, **kwargs)


def test_the_rule_redraws_rather_than_skips():
    """Some draws do land too close: circle_crossing draws again (three numbers a try)
    on some of these seeds, and still places every human (the test above holds anyway)."""
    redrawn = 0
    for case in range(100):
        rng = CountingState(1000 + case)
        humans = circle_crossing(rng)
        assert len(humans) == 5
        assert rng.draws % 3 == 0 and rng.draws >= 15
        redrawn += rng.draws > 15
    assert redrawn > 0


@pytest.mark.parametrize("case", range(0, 500, 11))
def test_square_humans_cross_from_one_half_of_the_square_to_the_other(case):
    sc = crowdnav_scenario("square", case)
    for ob in sc.obstacles:
        assert ob.goals is not None
        (sx, sy), (gx, gy) = ob.center, ob.goals[0]
        assert (sx - 6.0) * (gx - 6.0) <= 0.0
        for v in (sx, sy, gx, gy):
            assert 1.0 <= v <= 11.0


def test_same_case_same_scenario_and_cases_differ():
    assert crowdnav_scenario("square", 4) == crowdnav_scenario("square", 4)
    assert crowdnav_scenario("circle", 4).obstacles != crowdnav_scenario("circle", 5).obstacles


def test_bad_arguments_are_named():
    with pytest.raises(ValueError, match="unknown layout 'ring'"):
        crowdnav_scenario("ring", 0)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"case must be in 0\.\.4294966295 \(got -1\)"):
        crowdnav_scenario("circle", -1)
    crowdnav_scenario("circle", 2**32 - 1 - 1000)  # the last case there is: seed 2^32 - 1
    with pytest.raises(ValueError, match=r"case must be in 0\.\.4294966295 \(got 4294966296\)"):
        crowdnav_scenario("circle", 2**32 - 1000)
