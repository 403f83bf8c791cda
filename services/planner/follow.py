"""Drive toward a point: the robot's motion between decisions (pure, no I/O)."""

from __future__ import annotations

import math

from zenav.services.geometry import wrap_angle


def command_toward(
    x: float,
    y: float,
    heading: float,
    target: tuple[float, float],
    speed: float,
    heading_gain: float,
    max_omega: float,
    brake: float | None = None,
    within: float = 1.0,
) -> tuple[float, float]:
    """(v, omega) that heads for ``target`` at up to ``speed`` m/s.

    The turn rate is proportional to the heading error; the forward speed falls with
    the cosine of the error, so the robot turns on the spot when the target is behind it.
    Near the target the speed falls so as not to overshoot it: to the speed that covers
    the distance in ``within`` s (one second of travel by default), or, with ``brake``
    (m/s^2), to the speed from which braking at that rate stops the robot on the target,
    sqrt(2 brake distance).
    """
    dx, dy = target[0] - x, target[1] - y
    distance = math.hypot(dx, dy)
    if distance < 1e-9:
        return 0.0, 0.0
    error = wrap_angle(math.atan2(dy, dx) - heading)
    omega = max(-max_omega, min(max_omega, heading_gain * error))
    near = distance / within if brake is None else math.sqrt(2.0 * brake * distance)
    v = min(speed, near) * max(0.0, math.cos(error))
    return v, omega


def backing_toward(
    x: float,
    y: float,
    heading: float,
    target: tuple[float, float],
    speed: float,
    heading_gain: float,
    max_omega: float,
) -> tuple[float, float]:
    """(v, omega) that backs toward ``target`` at up to ``speed`` m/s: the rear turned
    toward it as ``command_toward`` turns the front, v negative."""
    v, omega = command_toward(x, y, heading + math.pi, target, speed, heading_gain, max_omega)
    return -v, omega
