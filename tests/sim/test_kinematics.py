"""Unicycle integration and velocity limits against hand-computed values."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from zenav.services.geometry import limit_velocity, wrap_angle
from zenav.sim.kinematics import RobotState, step_robot, unicycle_step


def test_straight_line_along_the_heading() -> None:
    x, y, heading = unicycle_step(1.0, 2.0, math.pi / 4, 1.0, 0.0, 2.0)
    assert (x, y) == pytest.approx((1.0 + math.sqrt(2.0), 2.0 + math.sqrt(2.0)))
    assert heading == pytest.approx(math.pi / 4)


def test_reversing_moves_backwards() -> None:
    x, y, _ = unicycle_step(0.0, 0.0, math.pi / 2, -0.5, 0.0, 2.0)
    assert (x, y) == pytest.approx((0.0, -1.0), abs=1e-12)


def test_quarter_circle_arc_counter_clockwise() -> None:
    # v = 1 m/s, omega = 0.5 rad/s: turning radius 2 m around (0, 2); pi s is a quarter turn.
    x, y, heading = unicycle_step(0.0, 0.0, 0.0, 1.0, 0.5, math.pi)
    assert (x, y) == pytest.approx((2.0, 2.0), abs=1e-12)
    assert heading == pytest.approx(math.pi / 2)


def test_quarter_circle_arc_clockwise() -> None:
    x, y, heading = unicycle_step(0.0, 0.0, 0.0, 1.0, -0.5, math.pi)
    assert (x, y) == pytest.approx((2.0, -2.0), abs=1e-12)
    assert heading == pytest.approx(-math.pi / 2)


def test_turning_on_the_spot_keeps_position_and_wraps_heading() -> None:
    x, y, heading = unicycle_step(3.0, 4.0, 3.0, 0.0, 1.0, 1.0)
    assert (x, y) == (3.0, 4.0)
    assert heading == pytest.approx(4.0 - 2.0 * math.pi)
    assert wrap_angle(-math.pi) == math.pi
    assert wrap_angle(7.0 * math.pi) == pytest.approx(math.pi)
    assert wrap_angle(-0.5) == -0.5


def test_tiny_turn_rate_matches_straight_line() -> None:
    straight = unicycle_step(0.0, 0.0, 0.3, 2.0, 0.0, 0.1)
    almost = unicycle_step(0.0, 0.0, 0.3, 2.0, 1e-9, 0.1)
    # Within the true difference (heading 1e-10 rad, lateral 1e-11 m): no 0/0 blow-up.
    assert almost == pytest.approx(straight, abs=1e-9)


@given(
    v=st.floats(-2.0, 2.0),
    omega=st.floats(-3.0, 3.0),
    heading=st.floats(-math.pi, math.pi),
    dt=st.floats(0.0, 2.0),
)
def test_two_half_steps_equal_one_step(v: float, omega: float, heading: float, dt: float) -> None:
    # Exact integration: splitting the interval changes nothing (unlike Euler).
    whole = unicycle_step(0.5, -0.5, heading, v, omega, dt)
    half = unicycle_step(0.5, -0.5, heading, v, omega, dt / 2)
    twice = unicycle_step(*half, v, omega, dt / 2)
    assert twice[:2] == pytest.approx(whole[:2], abs=1e-9)
    assert math.cos(twice[2] - whole[2]) == pytest.approx(1.0, abs=1e-12)


def test_acceleration_limit_when_speeding_up() -> None:
    # 0.5 m/s^2 for 0.1 s: at most +0.05 m/s.
    assert limit_velocity(0.0, 1.0, 0.5, 2.0, 0.1, 2.0) == pytest.approx(0.05)
    assert limit_velocity(0.0, -1.0, 0.5, 2.0, 0.1, 2.0) == pytest.approx(-0.05)


def test_deceleration_limit_when_slowing_down_or_reversing() -> None:
    assert limit_velocity(1.0, 0.0, 0.5, 2.0, 0.1, 2.0) == pytest.approx(0.8)
    assert limit_velocity(-1.0, 0.0, 0.5, 2.0, 0.1, 2.0) == pytest.approx(-0.8)
    assert limit_velocity(0.1, -1.0, 0.5, 2.0, 0.1, 2.0) == pytest.approx(-0.1)


def test_target_within_limits_is_reached_exactly() -> None:
    assert limit_velocity(0.5, 0.52, 0.5, 2.0, 0.1, 2.0) == 0.52
    assert limit_velocity(0.5, 0.4, 0.5, 2.0, 0.1, 2.0) == 0.4


def test_target_is_clamped_to_max_speed() -> None:
    assert limit_velocity(0.95, 5.0, 10.0, 10.0, 0.1, 1.0) == 1.0
    assert limit_velocity(-0.95, -5.0, 10.0, 10.0, 0.1, 1.0) == -1.0
    # Above the maximum already (e.g. the limit was lowered): slow down at decel rate.
    assert limit_velocity(1.5, 1.5, 0.5, 2.0, 0.1, 1.0) == pytest.approx(1.3)


def test_no_time_means_no_change_and_infinite_limits_jump() -> None:
    assert limit_velocity(0.3, 1.0, math.inf, math.inf, 0.0, 2.0) == 0.3
    assert limit_velocity(0.3, 1.0, math.inf, math.inf, 0.1, 2.0) == 1.0


def test_negative_limits_are_rejected() -> None:
    with pytest.raises(ValueError, match="must be >= 0"):
        limit_velocity(0.0, 1.0, -0.5, 1.0, 0.1, 1.0)
    with pytest.raises(ValueError, match="must be >= 0"):
        limit_velocity(0.0, 1.0, 0.5, 1.0, -0.1, 1.0)


def test_step_robot_limits_then_integrates() -> None:
    state = RobotState(x=0.0, y=0.0, heading=0.0, v=0.2, omega=0.0)
    new = step_robot(
        state,
        1.0,
        1.0,
        0.5,
        v_max=0.4,
        accel=0.2,
        decel=1.0,
        omega_max=0.5,
        alpha_accel=0.4,
        alpha_decel=1.0,
    )
    assert new.v == pytest.approx(0.3)  # 0.2 + 0.2 m/s^2 * 0.5 s
    assert new.omega == pytest.approx(0.2)  # 0.4 rad/s^2 * 0.5 s, below omega_max
    assert new.heading == pytest.approx(0.1)
    assert (new.x, new.y) == pytest.approx(unicycle_step(0.0, 0.0, 0.0, 0.3, 0.2, 0.5)[:2])
    assert state.v == 0.2  # the input state is unchanged
