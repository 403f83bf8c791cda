"""What reaches the base for one velocity command: limits and the stop zone (pure, no I/O)."""

from __future__ import annotations

from typing import Literal

from zenav.schemas.messages import LaserScan
from zenav.services.geometry import limit_velocity
from zenav.services.motor_bridge.params import Params


class Limiter:
    """Speed and acceleration limits between successive commands (pure, no I/O)."""

    def __init__(self, params: Params) -> None:
        self.params = params
        self.v = 0.0
        self.omega = 0.0
        self.stamp: float | None = None

    def apply(self, stamp: float, v: float, omega: float) -> tuple[float, float]:
        p = self.params
        dt = p.command_period if self.stamp is None else max(stamp - self.stamp, 0.0)
        v_low = -min(p.max_reverse_speed, p.max_speed) if p.allow_reverse else 0.0
        v_target = min(max(v, v_low), p.max_speed)
        self.v = limit_velocity(self.v, v_target, p.accel, p.decel, dt, p.max_speed)
        self.omega = limit_velocity(
            self.omega, omega, p.angular_accel, p.angular_accel, dt, p.max_omega
        )
        self.stamp = stamp
        return self.v, self.omega

    def stop(self, stamp: float) -> None:
        self.v = 0.0
        self.omega = 0.0
        self.stamp = stamp


Reason = Literal["command", "stop_zone"]


class CommandFilter:
    """Limits plus the stop zone: what reaches the base for one command (pure, no I/O)."""

    def __init__(self, params: Params) -> None:
        self.params = params
        self.limiter = Limiter(params)

    def blocked(self, scan: LaserScan | None, v: float) -> bool:
        p = self.params
        if scan is None:
            return False
        return p.blocks(scan.ranges, scan.angle_min, scan.angle_increment, scan.range_max, v,
                        p.robot_radius)

    def apply(
        self, stamp: float, v: float, omega: float, scan: LaserScan | None
    ) -> tuple[float, float, Reason]:
        reason: Reason = "command"
        if self.blocked(scan, max(v, self.limiter.v)):
            v, reason = min(v, 0.0), "stop_zone"
        v, omega = self.limiter.apply(stamp, v, omega)
        if reason == "stop_zone":
            v = min(v, 0.0)  # at once: the base's own deceleration limit applies
            self.limiter.v = v
        return v, omega, reason
