"""Unicycle (differential-drive) robot kinematics (angle wrap and velocity limits:
:mod:`zenav.services.geometry`).

Positions in m, headings in rad from +x counter-clockwise, wrapped to (-pi, pi];
linear speed v in m/s, turn rate omega in rad/s, time in s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from zenav.services.geometry import limit_velocity, wrap_angle

__all__ = ["RobotState", "step_robot", "unicycle_step"]


@dataclass
class RobotState:
    """Pose (x, y m; heading rad) and current velocity (v m/s, omega rad/s)."""

    x: float
    y: float
    heading: float
    v: float = 0.0
    omega: float = 0.0


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
