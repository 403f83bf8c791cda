"""Motor bridge parameters: speed and acceleration limits, staleness, the stop zone, and
where base commands go."""

from __future__ import annotations

from typing import Literal

from pydantic import ConfigDict, Field

from zenav.services.mission import (
    ACCEL,
    MAX_OMEGA,
    MAX_REVERSE_SPEED,
    MAX_SPEED,
    ROBOT_RADIUS,
    SCAN_WAIT,
)
from zenav.services.motor_bridge.stop_zone import StopZoneParams
from zenav.services.ros2.params import Ros2Params


class Params(StopZoneParams):
    """The bridge's limits; the stop zone's geometry (``stop_zone``, ``zone_*``, ``decel``)
    is ``StopZoneParams``, which the planner includes too."""

    model_config = ConfigDict(extra="forbid")

    max_speed: float = Field(MAX_SPEED, gt=0, description="forward speed limit, m/s")
    allow_reverse: bool = Field(False, description="whether negative speeds pass")
    max_reverse_speed: float = Field(
        MAX_REVERSE_SPEED, gt=0, description="reverse speed limit when allow_reverse, m/s "
        "(the paper planner backs slowly, in recovery and to a spot aside: the laser does "
        "not see behind)")
    max_omega: float = Field(MAX_OMEGA, gt=0, description="turn rate limit, rad/s")
    accel: float = Field(ACCEL, gt=0, description="forward acceleration limit, m/s^2")
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
    scan_wait: float = Field(
        SCAN_WAIT, gt=0, description="clock 'sim': wall s a command waits for the scan of "
        "its stamp before its stop zone check uses the newest scan before it (a newer "
        "command ends the wait sooner); 'realtime' never holds a command for its scan")
    watchdog_period: float = Field(0.05, gt=0, description="wall s between watchdog checks")
    robot_radius: float = Field(ROBOT_RADIUS, gt=0, description="disc footprint, m")
    backend: Literal["native", "ros2"] = Field(
        "native", description="native: BaseCommand on device/base_cmd only; ros2: also "
        "Twist (or TwistStamped) to a ROS 2 robot over rmw_zenoh")
    ros2: Ros2Params = Field(default_factory=Ros2Params, description="the ROS 2 robot's "
                             "topics, frames and domain (ros2 backend)")
