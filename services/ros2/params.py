"""Where zenav meets a ROS 2 robot: one parameter block shared by the services that
speak ROS 2 (laser driver, motor bridge) and the simulator posing as a ROS 2 robot."""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator

from zenav.services.ros2.wire import WireError, check_name_part, qualify


class Ros2Params(BaseModel):
    """Topic names, frames, domain and QoS of the robot's ROS 2 graph."""

    model_config = ConfigDict(extra="forbid")

    domain_id: int = Field(0, ge=0, le=232, description="ROS_DOMAIN_ID of the robot")
    namespace: str = Field("/", description="ROS namespace of zenav's nodes; relative topic "
                           "names below are resolved in it")
    node_name: str | None = Field(None, description="ROS node name; default zenav_<service>")
    scan_topic: str = Field("scan", description="sensor_msgs/msg/LaserScan from the lidar")
    odom_topic: str = Field("odom", description="nav_msgs/msg/Odometry from the base")
    cmd_vel_topic: str = Field("cmd_vel", description="velocity commands to the base")
    twist_stamped: bool = Field(False, description="send geometry_msgs/msg/TwistStamped "
                                "(Nav2 in Jazzy and later) instead of Twist")
    odom_frame: str = Field("odom", description="frame of odometry poses and of zenav's "
                            "markers and path")
    base_frame: str = Field("base_link", description="robot body frame (TwistStamped "
                            "header, odometry child frame)")
    laser_frame: str = Field("laser", description="frame of the scans the simulator "
                             "publishes as a ROS 2 robot")
    scan_qos: Literal["sensor_data", "reliable"] = Field(
        "sensor_data", description="QoS announced for the scan subscription: best effort, "
        "depth 5 (ROS sensor data), or reliable depth 10")

    @field_validator("namespace")
    @classmethod
    def _namespace(cls, value: str) -> str:
        if value != "/":
            try:
                qualify("x", value)
            except WireError as exc:
                raise ValueError(str(exc)) from None
        return value

    @field_validator("node_name")
    @classmethod
    def _node_name(cls, value: str | None) -> str | None:
        if value is not None:
            try:
                check_name_part(value, "node name")
            except WireError as exc:
                raise ValueError(str(exc)) from None
        return value

    @field_validator("scan_topic", "odom_topic", "cmd_vel_topic")
    @classmethod
    def _topic(cls, value: str) -> str:
        try:
            qualify(value)
        except WireError as exc:
            raise ValueError(str(exc)) from None
        return value

    def topic(self, name: str) -> str:
        """The fully qualified name of a topic parameter's value."""
        return qualify(name, self.namespace)

    @property
    def cmd_vel_type(self) -> str:
        from zenav.services.ros2.wire import TWIST, TWIST_STAMPED

        return TWIST_STAMPED if self.twist_stamped else TWIST


ROBOT_FACES = ("native", "ros2")
"""How a (simulated) robot meets the stack: zenav's device keys, or ROS 2 over rmw_zenoh."""


def with_ros2_robot(params: dict[str, dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """Stack parameters (per service) turned to a ROS 2 robot: the simulator poses as one,
    the laser driver and motor bridge use their ros2 backends. Commands are TwistStamped,
    whose stamp lets a lockstep simulator know which scan a command answers."""
    out = {name: dict(values) for name, values in params.items()}
    ros2 = {"twist_stamped": True}
    out.setdefault("simulator", {}).update(robot="ros2",
                                           ros2=dict(ros2, node_name="zenav_sim_robot"))
    out.setdefault("laser_driver", {}).update(backend="ros2", ros2=dict(ros2))
    out.setdefault("motor_bridge", {}).update(backend="ros2", ros2=dict(ros2))
    return out
