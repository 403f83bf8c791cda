"""Motor bridge service: the last stage before the wheels.

It turns velocity commands into base commands for the device backend (the simulator
here), clamped to the speed and acceleration limits, and commands zero velocity when
commands go stale. Staleness is judged on the stamps' clock: the latest odometry stamp
tells the bridge what time it is. In real-time mode a wall-clock watchdog also stops the
robot when nothing at all arrives (a cut link, a dead planner host).

The stop zone is checked on the scan a command answers (the same stamp). That scan comes
straight from the laser driver while the command comes through four services, so on a
loaded machine the command can come first. On the simulator's clock (``clock: sim``), once
scans come at all, the bridge then holds the command until its scan comes, as the planner
holds a track list (:class:`~zenav.services.node.StampJoin`: at most ``scan_wait`` wall
seconds, or until a newer command comes), so a lockstep run does not depend on the
machine's load. In real-time mode it never holds a command for a late scan: it checks the
newest scan before the command's stamp.

Backends, chosen by ``backend``: ``native`` sends :class:`BaseCommand` on
``device/base_cmd`` (the simulator, or a base's own driver process); ``ros2`` also sends
each command to a ROS 2 robot's ``cmd_vel`` over rmw_zenoh (:mod:`.output`).
"""

from __future__ import annotations

import asyncio
import logging
import time

from zenav.schemas import keys
from zenav.schemas.messages import BaseCommand, LaserScan, Odometry, VelocityCommand
from zenav.services.motor_bridge.command_filter import CommandFilter, Limiter
from zenav.services.motor_bridge.output import BaseOutput
from zenav.services.motor_bridge.params import Params
from zenav.services.node import Node, StampGate, StampJoin, latest_at
from zenav.services.ros2.node import Ros2Node, Ros2Publisher

__all__ = ["CommandFilter", "Limiter", "Params", "Service"]
# Params and CommandFilter are also read from here by zenav/inprocess.py.

log = logging.getLogger(__name__)

SCANS_KEPT = 8


class Service:
    def __init__(self, node: Node, params: Params) -> None:
        self.node = node
        self.params = params
        self.filter = CommandFilter(params)
        self.limiter = self.filter.limiter
        native = node.publisher(keys.BASE_CMD, BaseCommand, reliable=True, urgent=True)
        self.ros: Ros2Node | None = None
        ros_out: Ros2Publisher | None = None
        if params.backend == "ros2":
            r = params.ros2
            self.ros = Ros2Node(node.bus, r.node_name or "zenav_motor_bridge", r.domain_id,
                                r.namespace)
            ros_out = self.ros.publisher(r.topic(r.cmd_vel_topic), r.cmd_vel_type)
        self.base = BaseOutput(native, ros_out, params.ros2)
        self.gate = StampGate(node, keys.CMD_VEL)
        self.now: float | None = None  # latest stamp seen: the stack's clock
        self.last_command_stamp: float | None = None
        self.last_command_wall = time.monotonic()
        self.stopped_for_staleness = False
        # A command and the scan of its stamp, joined (the latest few scans kept).
        self.join = StampJoin[VelocityCommand, LaserScan](self.apply, params.scan_wait,
                                                          SCANS_KEPT)
        self.zone_stops = 0
        node.subscribe(keys.SCAN, LaserScan, self.on_scan, depth=2)
        node.subscribe(keys.CMD_VEL, VelocityCommand, self.on_command, depth=2)
        node.subscribe(keys.ODOM, Odometry, self.on_odometry, depth=8)

    def on_scan(self, scan: LaserScan) -> None:
        self.join.companion(scan)

    def on_command(self, command: VelocityCommand) -> None:
        if not self.gate.admit(command.stamp, self.base):
            return
        if self.params.clock == "sim" and self.params.stop_zone and self.join.companions:
            self.join.arrive(command)  # applied once its scan is in (see the module notes)
        else:
            self.apply(command, None)

    def apply(self, command: VelocityCommand, scan: LaserScan | None) -> None:
        """Filter ``command`` with the stop zone on ``scan`` (the scan of its stamp), else
        on the newest scan before it, and send it to the base."""
        if self.stopped_for_staleness:
            log.info("commands resumed at t=%.3f", command.stamp)
            self.stopped_for_staleness = False
        self.last_command_stamp = command.stamp
        self.last_command_wall = time.monotonic()
        self.now = command.stamp if self.now is None else max(self.now, command.stamp)
        if scan is None:
            at = latest_at(self.join.companions, command.stamp)
            scan = None if at is None else self.join.companions[at]
        v, omega, reason = self.filter.apply(command.stamp, command.v, command.omega, scan)
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

    def close(self) -> None:
        """Leave the ROS 2 graph (the runner calls this after the node stops)."""
        if self.ros is not None:
            self.ros.close()

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
