"""Motor bridge service: the last stage before the wheels.

It turns velocity commands into base commands for the device backend (the simulator
here), clamped to the speed and acceleration limits, and commands zero velocity when
commands go stale. Staleness is judged on the stamps' clock: the latest odometry stamp
tells the bridge what time it is. In real-time mode a wall-clock watchdog also stops the
robot when nothing at all arrives (a cut link, a dead planner host).
"""

from __future__ import annotations

import asyncio
import logging
import time
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

from zenav.schemas import keys
from zenav.schemas.messages import BaseCommand, LaserScan, Odometry, VelocityCommand
from zenav.services.geometry import limit_velocity
from zenav.services.motor_bridge.stop_zone import stop_distance, zone_blocked
from zenav.services.node import Node, StampGate

log = logging.getLogger(__name__)

SCANS_KEPT = 8


class Params(BaseModel):
    model_config = ConfigDict(extra="forbid")

    max_speed: float = Field(0.2, gt=0, description="forward speed limit, m/s")
    allow_reverse: bool = Field(False, description="whether negative speeds pass")
    max_omega: float = Field(1.5, gt=0, description="turn rate limit, rad/s")
    accel: float = Field(0.5, gt=0, description="forward acceleration limit, m/s^2")
    decel: float = Field(1.0, gt=0, description="forward deceleration limit, m/s^2")
    angular_accel: float = Field(4.0, gt=0, description="turn rate change limit, rad/s^2")
    stale_timeout: float = Field(
        0.5, gt=0, description="s without a command before the robot is stopped"
    )
    command_period: float = Field(
        0.1, gt=0, description="nominal s between commands, used for the first one"
    )
    clock: Literal["sim", "realtime"] = Field(
        "sim", description="'realtime' adds a wall-clock watchdog to the stamp-clock check"
    )
    watchdog_period: float = Field(0.05, gt=0, description="wall s between watchdog checks")
    stop_zone: bool = Field(True, description="refuse forward motion toward a return in the "
                            "zone ahead (reads the raw scan)")
    robot_radius: float = Field(0.2, gt=0, description="disc footprint, m")
    zone_side_margin: float = Field(0.02, ge=0, description="zone half-width beyond the "
                                    "robot radius, m")
    zone_margin: float = Field(0.08, ge=0, description="zone length beyond the robot's "
                               "front at standstill, m")
    zone_reaction: float = Field(0.3, ge=0, description="s of travel added to the zone: one "
                                 "command period and some")


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
        v_low = -p.max_speed if p.allow_reverse else 0.0
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
        if not p.stop_zone or scan is None:
            return False
        ahead = stop_distance(v, p.zone_reaction, p.decel, p.zone_margin)
        return zone_blocked(scan.ranges, scan.angle_min, scan.angle_increment, scan.range_max,
                            v, p.robot_radius, p.zone_side_margin, ahead)

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


class Service:
    def __init__(self, node: Node, params: Params) -> None:
        self.node = node
        self.params = params
        self.filter = CommandFilter(params)
        self.limiter = self.filter.limiter
        self.base = node.publisher(keys.BASE_CMD, BaseCommand, reliable=True, urgent=True)
        self.gate = StampGate(node, keys.CMD_VEL)
        self.now: float | None = None  # latest stamp seen: the stack's clock
        self.last_command_stamp: float | None = None
        self.last_command_wall = time.monotonic()
        self.stopped_for_staleness = False
        self.scans: dict[float, LaserScan] = {}  # the latest few, by stamp
        self.zone_stops = 0
        node.subscribe(keys.SCAN, LaserScan, self.on_scan, depth=2)
        node.subscribe(keys.CMD_VEL, VelocityCommand, self.on_command, depth=2)
        node.subscribe(keys.ODOM, Odometry, self.on_odometry, depth=8)

    def on_scan(self, scan: LaserScan) -> None:
        self.scans[scan.stamp] = scan
        while len(self.scans) > SCANS_KEPT:
            del self.scans[min(self.scans)]

    def scan_for(self, stamp: float) -> LaserScan | None:
        """The scan a command answers (same stamp), else the newest one not after it."""
        if stamp in self.scans:
            return self.scans[stamp]
        earlier = [s for s in self.scans if s <= stamp]
        return self.scans[max(earlier)] if earlier else None

    def on_command(self, command: VelocityCommand) -> None:
        if not self.gate.admit(command.stamp, self.base):
            return
        if self.stopped_for_staleness:
            log.info("commands resumed at t=%.3f", command.stamp)
            self.stopped_for_staleness = False
        self.last_command_stamp = command.stamp
        self.last_command_wall = time.monotonic()
        self.now = command.stamp if self.now is None else max(self.now, command.stamp)
        v, omega, reason = self.filter.apply(command.stamp, command.v, command.omega,
                                             self.scan_for(command.stamp))
        if reason == "stop_zone":
            self.zone_stops += 1
            if self.zone_stops == 1 or self.zone_stops % 50 == 0:
                log.warning("stop zone: something ahead at t=%.2f; forward motion refused "
                            "(%d times so far)", command.stamp, self.zone_stops)
        self.base.publish(BaseCommand(stamp=command.stamp, seq=self.base.next_seq(), v=v,
                                      omega=omega, reason=reason))

    def on_odometry(self, odometry: Odometry) -> None:
        self.now = odometry.stamp if self.now is None else max(self.now, odometry.stamp)
        if self.last_command_stamp is None:
            return
        if self.now - self.last_command_stamp > self.params.stale_timeout:
            self.stop_for_staleness(
                f"no command since t={self.last_command_stamp:.3f} (now t={self.now:.3f})"
            )

    def stop_for_staleness(self, why: str) -> None:
        """Command zero velocity once, until a fresh command arrives."""
        if self.stopped_for_staleness:
            return
        self.stopped_for_staleness = True
        stamp = self.now if self.now is not None else 0.0
        log.warning("stopping the robot: %s", why)
        self.limiter.stop(stamp)
        self.base.publish(
            BaseCommand(stamp=stamp, seq=self.base.next_seq(), v=0.0, omega=0.0, reason="stale")
        )

    async def run(self) -> None:
        """The wall-clock watchdog, in real-time mode only."""
        if self.params.clock != "realtime":
            await asyncio.Event().wait()  # nothing to do; cancelled when the node stops
            return
        while True:
            await asyncio.sleep(self.params.watchdog_period)
            silent = time.monotonic() - self.last_command_wall
            if self.last_command_stamp is not None and silent > self.params.stale_timeout:
                self.stop_for_staleness(f"no command for {silent:.2f} s of wall time")


if __name__ == "__main__":
    from zenav.services.runner import main

    raise SystemExit(main("motor_bridge"))
