"""Simulator parameters: the scenario, the clock, the simulated base's limits, and the
face it shows the stack (zenav's device keys or a ROS 2 robot)."""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from zenav.services.mission import LIVE_SERVICES, MAX_OMEGA
from zenav.services.ros2.params import Ros2Params
from zenav.sim.agents import CrowdParams


class Params(BaseModel):
    model_config = ConfigDict(extra="forbid")

    scenario: Path | None = Field(None, description="scenario YAML file (required)")
    clock: Literal["lockstep", "realtime"] = "lockstep"
    realtime_factor: float = Field(1.0, gt=0, description="sim s per wall s in realtime mode")
    base_accel: float = Field(1.0, gt=0, description="the simulated base's own acceleration "
                              "limit, m/s^2 (above the motor bridge's accel)")
    base_decel: float = Field(2.0, gt=0, description="the simulated base's own deceleration "
                              "limit, m/s^2 (above the motor bridge's decel: a stop-zone stop "
                              "brakes with it)")
    max_omega: float = Field(MAX_OMEGA, gt=0, description="turn rate limit of the base, rad/s "
                             "(the robot's, as the planner's and the motor bridge's)")
    base_angular_accel: float = Field(8.0, gt=0, description="the simulated base's own turn "
                                      "rate change limit, rad/s^2 (above the bridge's)")
    wait_for: list[str] = Field(
        default_factory=lambda: list(LIVE_SERVICES),
        description="services whose liveliness is awaited before the clock starts",
    )
    startup_timeout: float = Field(60.0, gt=0, description="wall s to wait for the next of "
                                   "them to arrive (starts again at each arrival)")
    retransmit_after: float = Field(0.5, gt=0, description="wall s before a frame is resent")
    answer_timeout: float = Field(30.0, gt=0, description="wall s without an answer: fail")
    result_repeat: float = Field(0.5, gt=0, description="wall s between result repeats")
    realtime_history: float = Field(
        60.0, gt=0, description="realtime: s of trajectory kept for the run result (a live "
        "stack runs for hours; lockstep runs keep every tick)"
    )
    base_timeout: float = Field(
        1.0, gt=0, description="realtime: the simulated base holds its last command at most "
        "this many wall s, then stops (a base's own watchdog, for when the bridge is gone)"
    )
    robot: Literal["native", "ros2"] = Field(
        "native", description="native: zenav's device/* keys and odom; ros2: a ROS 2 robot "
        "over rmw_zenoh (/scan, /odom, /cmd_vel)")
    ros2: Ros2Params = Field(
        default_factory=Ros2Params,
        description="topics, frames and domain of the simulated ROS 2 robot (its node: "
        "zenav_sim_robot unless ros2.node_name says otherwise)")

    # --- the agents (behavior: orca), CrowdNav's ORCA settings by default ------------
    crowd_time_step: float = Field(0.25, gt=0, description="agents: time between ORCA "
                                   "steps, s (CrowdNav: 0.25)")
    crowd_neighbor_dist: float = Field(10.0, gt=0, description="agents: others farther than "
                                       "this are ignored, m (CrowdNav: 10)")
    crowd_max_neighbors: int = Field(10, gt=0, description="agents: most neighbours "
                                     "considered (CrowdNav: 10)")
    crowd_time_horizon: float = Field(5.0, gt=0, description="agents: ORCA's time horizon "
                                      "for other agents, s (CrowdNav: 5)")
    crowd_time_horizon_obst: float = Field(5.0, gt=0, description="agents: ORCA's time "
                                           "horizon for obstacles, s (CrowdNav: 5)")
    crowd_radius_margin: float = Field(0.01, ge=0, description="agents: added to every "
                                       "radius in ORCA, m (CrowdNav: 0.01)")
    crowd_slow_within: float = Field(1.0, gt=0, description="agents: the preferred velocity "
                                     "is the vector to the goal divided by this, capped at "
                                     "the preferred speed, s (CrowdNav: 1)")

    @model_validator(mode="after")
    def _stamped_for_lockstep(self) -> Params:
        if self.robot == "ros2" and self.clock == "lockstep" and not self.ros2.twist_stamped:
            raise ValueError("a lockstep ROS 2 robot needs ros2.twist_stamped=true (a plain "
                             "Twist has no stamp to say which scan it answers); or use "
                             "clock=realtime")
        return self

    def crowd(self) -> CrowdParams:
        """The ORCA settings of the agents (:mod:`zenav.sim.agents`)."""
        return CrowdParams(
            time_step=self.crowd_time_step, neighbor_dist=self.crowd_neighbor_dist,
            max_neighbors=self.crowd_max_neighbors, time_horizon=self.crowd_time_horizon,
            time_horizon_obst=self.crowd_time_horizon_obst,
            radius_margin=self.crowd_radius_margin, slow_within=self.crowd_slow_within)


def check(params: Params) -> None:
    """What the simulator service would refuse at start-up, before it starts: no
    scenario, or one that does not load (ValueError; ScenarioError names file and field)."""
    from zenav.sim.scenario import load_scenario

    if params.scenario is None:
        raise ValueError("the simulator needs a scenario: --set scenario=FILE")
    load_scenario(params.scenario)
