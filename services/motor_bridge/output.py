"""Where the motor bridge's base commands go (thin: publishers only).

zenav's own ``device/base_cmd`` always; with the ros2 backend also the ROS 2 robot's
``cmd_vel`` as ``geometry_msgs/msg/Twist`` or ``TwistStamped`` (stamped with the scan
time the command answers, in the body frame).
"""

from __future__ import annotations

from typing import Any

from zenav.schemas.messages import BaseCommand
from zenav.services.node import TypedPublisher
from zenav.services.ros2.convert import twist, twist_stamped
from zenav.services.ros2.node import Ros2Publisher
from zenav.services.ros2.params import Ros2Params


def command_to_ros(command: BaseCommand, params: Ros2Params) -> Any:
    """The ROS 2 velocity message of a base command."""
    if params.twist_stamped:
        return twist_stamped(command.stamp, params.base_frame, command.v, command.omega)
    return twist(command.v, command.omega)


class BaseOutput:
    """Same interface as a typed publisher: ``next_seq``, ``publish``, ``republish``."""

    def __init__(self, native: TypedPublisher[BaseCommand], ros: Ros2Publisher | None,
                 params: Ros2Params) -> None:
        self.native = native
        self.ros = ros
        self.params = params

    def next_seq(self) -> int:
        return self.native.next_seq()

    def publish(self, command: BaseCommand) -> None:
        self.native.publish(command)
        if self.ros is not None:
            self.ros.publish(command_to_ros(command, self.params))

    def republish(self) -> None:
        self.native.republish()
        if self.ros is not None and self.ros.last is not None:
            self.ros.publish(self.ros.last)
