"""deploy/ros2.yaml: zenav's services as clients of the robot's rmw_zenohd router, the
laser driver and motor bridge on their ros2 backends, and no simulator."""

from __future__ import annotations

from pathlib import Path

from zenav.deploy.model import load_deployment
from zenav.services.config import load_params
from zenav.services.laser_driver.params import Params as LaserParams
from zenav.services.motor_bridge.params import Params as BridgeParams

DEPLOY = Path(__file__).resolve().parents[2] / "deploy"


def test_ros2_deployment_uses_the_robots_router_and_the_ros2_backends():
    deployment = load_deployment(DEPLOY / "ros2.yaml")
    assert deployment.router is None  # rmw_zenohd is the router
    assert deployment.transport.mode == "client"
    assert deployment.transport.connect == ["tcp/127.0.0.1:7447"]
    assert "simulator" not in deployment.services and deployment.scenario is None
    laser = deployment.services["laser_driver"]
    bridge = deployment.services["motor_bridge"]
    lp = load_params(LaserParams, laser.config, laser.set)
    bp = load_params(BridgeParams, bridge.config, bridge.set)
    assert lp.backend == bp.backend == "ros2"
    assert (lp.ros2.topic(lp.ros2.scan_topic), lp.ros2.topic(lp.ros2.odom_topic)) == (
        "/scan", "/odom")
    assert bp.ros2.cmd_vel_type == "geometry_msgs/msg/Twist"
    assert bp.clock == "realtime"  # the wall-clock watchdog stops a robot on a cut link
