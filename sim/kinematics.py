"""Unicycle (differential-drive) robot kinematics and velocity limits.

Positions in m, headings in rad from +x counter-clockwise, wrapped to (-pi, pi];
linear speed v in m/s, turn rate omega in rad/s, time in s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["RobotState", "limit_velocity", "step_robot", "unicycle_step", "wrap_angle"]


@dataclass
class RobotState:
    """Pose (x, y m; heading rad) and current velocity (v m/s, omega rad/s)."""

    x: float
    y: float
    heading: float
    v: float = 0.0
    omega: float = 0.0


def wrap_angle(angle: float) -> float:
    """The same angle (rad) in (-pi, pi]."""
    wrapped = math.remainder(angle, 2.0 * math.pi)  # in [-pi, pi]
    return wrapped + 2.0 * math.pi if wrapped <= -math.pi else wrapped


def unicycle_step(
    x: float, y: float, heading: float, v: float, omega: float, dt: float
) -> tuple[float, float, float]:
    """Pose after driving at constant ``v`` (m/s) and ``omega`` (rad/s) for ``dt`` (s).

    Exact arc integration: the robot moves along a chord of length
    ``v * dt * sin(h) / h`` (h = omega * dt / 2) in the direction ``heading + h``;
    for omega -> 0 this is the straight line ``v * dt`` along the heading.
    Returns (x m, y m, heading rad wrapped to (-pi, pi]).
    """
    half = 0.5 * omega * dt
    # sin(h)/h, with its Taylor series near 0 to avoid 0/0.
    sinc = math.sin(half) / half if abs(half) > 1e-6 else 1.0 - half * half / 6.0
    chord = v * dt * sinc
    direction = heading + half
    return (
        x + chord * math.cos(direction),
        y + chord * math.sin(direction),
        wrap_angle(heading + omega * dt),
    )


def limit_velocity(
    v_current: float,
    v_target: float,
    accel_limit: float,
    decel_limit: float,
    dt: float,
    v_max: float,
) -> float:
    """The velocity reached after ``dt`` (s) when asking for ``v_target``.

    Works the same for linear (m/s, m/s^2) and angular (rad/s, rad/s^2) velocity.
    The target is clamped to [-v_max, v_max]; then the change is limited to
    ``accel_limit * dt`` when speeding up (|target| >= |current|, same sign) and
    to ``decel_limit * dt`` otherwise (slowing down or reversing), as in Nav2's
    velocity smoother. Limits are magnitudes (>= 0; ``math.inf`` means no limit).
    """
    if accel_limit < 0.0 or decel_limit < 0.0 or dt < 0.0 or v_max < 0.0:
        raise ValueError(
            "accel_limit, decel_limit, dt and v_max must be >= 0 "
            f"(got {accel_limit}, {decel_limit}, {dt}, {v_max})"
        )
    target = min(max(v_target, -v_max), v_max)
    speeding_up = abs(target) >= abs(v_current) and target * v_current >= 0.0
    limit = accel_limit if speeding_up else decel_limit
    max_change = limit * dt if dt > 0.0 else 0.0
    change = min(max(target - v_current, -max_change), max_change)
    return v_current + change


def step_robot(
    state: RobotState,
    v_target: float,
    omega_target: float,
    dt: float,
    *,
    v_max: float,
    accel: float,
    decel: float,
    omega_max: float,
    alpha_accel: float,
    alpha_decel: float,
) -> RobotState:
    """Apply the limits to the commanded (v m/s, omega rad/s), then drive for ``dt`` s.

    The limited velocities are held constant over ``dt``. ``accel`` / ``decel`` in
    m/s^2, ``alpha_accel`` / ``alpha_decel`` in rad/s^2, ``omega_max`` in rad/s.
    Returns a new state; ``state`` is not changed.
    """
    v = limit_velocity(state.v, v_target, accel, decel, dt, v_max)
    omega = limit_velocity(state.omega, omega_target, alpha_accel, alpha_decel, dt, omega_max)
    x, y, heading = unicycle_step(state.x, state.y, state.heading, v, omega, dt)
    return RobotState(x=x, y=y, heading=heading, v=v, omega=omega)
