"""Plane geometry every service and the simulator share (pure, no I/O).

Angles in rad from +x counter-clockwise unless a name says degrees. This is the one
place angles are wrapped and velocities limited; ``zenav.sim`` imports it from here.
"""

from __future__ import annotations

import math
from typing import overload

import numpy as np
import numpy.typing as npt

__all__ = [
    "disc_distance",
    "disc_mean_range",
    "limit_velocity",
    "wrap_angle",
    "wrap_angles",
    "wrap_degrees",
    "wrap_positive",
]

FloatArray = npt.NDArray[np.float64]


def disc_mean_range(distance: float, radius: float, n: int = 8) -> float:
    """Mean range of the beams that hit a disc of ``radius`` whose centre is ``distance``
    away (``n`` beams evenly spread in angle over the disc): how far from the laser the
    paper's Eq. 5 puts the centre of a disc seen whole. It lies on the visible surface,
    about 0.8 radius in front of the true centre."""
    half = math.asin(min(radius / distance, 1.0))
    total = 0.0
    for i in range(n):
        a = half * (2 * i + 1 - n) / n
        s = distance * math.sin(a)
        total += distance * math.cos(a) - math.sqrt(max(radius * radius - s * s, 0.0))
    return total / n


def disc_distance(mean_range: float, radius: float) -> float:
    """The distance from the laser of the centre of a disc of ``radius`` whose Eq. 5 centre
    lies ``mean_range`` away: :func:`disc_mean_range` inverted (the gap between the two
    changes slowly with the distance, so fixed-point steps settle it: a few, unless
    the disc is nearly touching the laser)."""
    distance = mean_range + 0.25 * math.pi * radius
    for _ in range(50):
        step = max(mean_range + distance - disc_mean_range(distance, radius), radius) - distance
        distance += step
        if abs(step) < 1e-9:
            break
    return distance


def wrap_angle(angle: float) -> float:
    """The same angle (rad) in (-pi, pi]."""
    wrapped = math.remainder(angle, 2.0 * math.pi)  # in [-pi, pi]
    return wrapped + 2.0 * math.pi if wrapped <= -math.pi else wrapped


def wrap_angles(angles: FloatArray) -> FloatArray:
    """:func:`wrap_angle` of every element: the same angles (rad) in (-pi, pi]."""
    wrapped: FloatArray = np.remainder(angles + math.pi, 2.0 * math.pi) - math.pi
    return np.where(wrapped <= -math.pi, wrapped + 2.0 * math.pi, wrapped)


@overload
def wrap_positive(angle: float, turn: float = ...) -> float: ...
@overload
def wrap_positive(angle: FloatArray, turn: float = ...) -> FloatArray: ...
def wrap_positive(angle: float | FloatArray, turn: float = 2.0 * math.pi) -> float | FloatArray:
    """The same angle in [0, ``turn``): rad by default, ``turn=360`` for degrees.

    Works on a float or elementwise on an array.
    """
    if isinstance(angle, np.ndarray):
        wrapped: FloatArray = np.remainder(angle, turn)
        return np.where(wrapped >= turn, 0.0, wrapped)
    scalar = angle % turn
    return 0.0 if scalar >= turn else scalar  # -1e-17 % turn rounds to turn


def wrap_degrees(angle_deg: float) -> float:
    """An angle in degrees wrapped to [0, 360)."""
    return wrap_positive(angle_deg, 360.0)


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
